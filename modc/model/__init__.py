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
    ResolvedProblem,
    ResolvedRobot,
    Robot,
    Target,
    Transform,
    UnitSpec,
    resolved,
    resolved_problem,
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
    "ResolvedProblem",
    "ResolvedRobot",
    "Robot",
    "Target",
    "Transform",
    "UnitSpec",
    "resolved",
    "resolved_problem",
]
