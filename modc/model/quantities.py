"""Units of measure: everything becomes SI (m, kg, rad) here, once."""
from __future__ import annotations

import math

ANGLE = {"deg": math.pi / 180.0, "rad": 1.0}
LENGTH = {"m": 1.0, "cm": 0.01, "mm": 0.001}
MASS = {"kg": 1.0, "g": 0.001}
KINDS = {"an angle": ANGLE, "a length": LENGTH, "a mass": MASS}
ALL = {**ANGLE, **LENGTH, **MASS}
# |SI value| above these is no modular arm (1 km, 1 t, 1e6 rad): reject before arithmetic overflows.
LIMIT = {"an angle": 1e6, "a length": 1e3, "a mass": 1e3}
SI = {"an angle": "rad", "a length": "m", "a mass": "kg"}
EXAMPLE = {"an angle": "45deg or 0.785 rad", "a length": "0.22 m or 220 mm", "a mass": "0.5 kg or 500 g"}


def distance(x: float) -> str:
    """A distance in metres as messages show it (m from 0.1 m up, else mm). Never 'inf' or 'nan':
    a distance nothing measured (no pose, no pair to check) is said in words."""
    if not math.isfinite(x):
        return "no measured distance" if math.isnan(x) else "an unbounded distance"
    return f"{x:.3g} m" if abs(x) >= 0.1 else f"{x * 1000:.3g} mm"
