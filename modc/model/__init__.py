"""The model: the module library (data) and the checked robot model (SI units)."""
from .library import Library, LibraryError
from .robot import Design, JointLimit, Obstacle, Payload, Pose, Robot, Target, Transform, UnitSpec

__all__ = ["Library", "LibraryError", "Design", "JointLimit", "Obstacle", "Payload", "Pose", "Robot", "Target", "Transform", "UnitSpec"]
