"""The model: the module library (data) and the checked robot model (SI units)."""
from .library import Library, LibraryError
from .robot import (
    Design,
    DHRow,
    JointLimit,
    Obstacle,
    Payload,
    Pose,
    Problem,
    ResolvedRobot,
    Robot,
    Target,
    Transform,
    UnitSpec,
    resolved,
)

__all__ = [
    "Library",
    "LibraryError",
    "DHRow",
    "Design",
    "JointLimit",
    "Obstacle",
    "Payload",
    "Pose",
    "Problem",
    "ResolvedRobot",
    "Robot",
    "Target",
    "Transform",
    "UnitSpec",
    "resolved",
]
