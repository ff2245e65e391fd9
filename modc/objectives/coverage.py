"""`rank coverage`: the largest share of the cell's region points reached first; with it the
points are optional (modc.design.coverage), without it every point is required."""
from .base import Objective

OBJECTIVE = Objective("coverage", "largest share of the regions' points reached first (makes them optional)",
                      "coverage", lambda d: getattr(d, "coverage", 1.0), unit=" %", scale=100.0, digits=1,
                      larger_first=True, task=True)
