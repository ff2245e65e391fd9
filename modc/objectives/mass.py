"""`rank mass`: the lightest arm first (the library's masses, payload not counted)."""
from .base import Objective

OBJECTIVE = Objective("mass", "least mass first (kg, without the payload)", "mass", lambda d: d.mass,
                      unit=" kg", digits=3, default=True)
