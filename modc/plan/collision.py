"""The planner's collision model under its old name: its home is modc.physical.checker (below
the planner, so the viewer and the design search use it without importing the planner)."""
from ..physical.checker import (  # noqa: F401  (re-exported)
    DEFAULT_MARGIN,
    STATIC_TOLERANCE,
    CollisionChecker,
    Contact,
    bisection_order,
    obstacle_geometry,
)

__all__ = ["DEFAULT_MARGIN", "STATIC_TOLERANCE", "CollisionChecker", "Contact", "bisection_order", "obstacle_geometry"]
