"""`rank cycle_time`: the fastest task first - the cell's tasks and paths summed, each segment
time-optimal from rest to rest under the joints' speed and peak-torque limits (modc.plan.timing)."""
from .base import Objective

OBJECTIVE = Objective("cycle_time", "shortest cycle time of the cell's tasks first (s, planned and timed)",
                      "cycle time", lambda d: d.cycle_time, unit=" s", digits=3, task=True, needs_task=True,
                      planned_column=True)
