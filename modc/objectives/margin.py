"""`rank margin`: the largest torque margin first - the smallest share of peak torque left over
the joints at the design's target poses with the payload (the compiler's torque analysis)."""
from .base import Objective

OBJECTIVE = Objective("margin", "largest static torque margin first (share of peak torque left)",
                      "torque margin", lambda d: d.margin, unit=" %", scale=100.0, digits=1,
                      larger_first=True, default=True)
