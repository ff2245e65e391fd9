"""The model: the module library (data) and the checked robot model (SI units)."""
from .library import Library, LibraryError
from .robot import Design, DHRow, JointLimit, Obstacle, Payload, Pose, Problem, Robot, Target, Transform, UnitSpec

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
    "Robot",
    "Target",
    "Transform",
    "UnitSpec",
]
