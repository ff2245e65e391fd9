"""`rank modules`: fewest modules first (each module is a joint, a motor and its cost)."""
from .base import Objective

OBJECTIVE = Objective("modules", "fewest modules first", "modules", lambda d: d.modules, default=True)
