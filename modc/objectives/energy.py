"""`rank energy`: the least mechanical energy over the cell's tasks first, ∫|τ·q̇| dt along the
planned, timed motion."""
from .base import Objective

OBJECTIVE = Objective("energy", "least mechanical energy over the cell's tasks first (J)", "energy",
                      lambda d: d.energy, unit=" J", digits=2, task=True, needs_task=True, planned_column=True)
