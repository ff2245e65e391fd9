"""How modc writes numbers and angles as text: one home for every layer (no imports but math).

    num, vec      numbers in output files: deterministic, no '-0', 12 significant digits
                  (enough for 1e-9 FK); backends/format.py re-exports them
    degrees       an angle already in degrees as .mod source: 6 significant digits, "45deg"
    angle         an angle in radians written the same way (diagnostics quote the user's units)
    angle_text    an angle in radians for a human report: one decimal, "45.0°"
"""
from __future__ import annotations

import math
from collections.abc import Iterable


def num(x: float) -> str:
    s = f"{float(x):.12g}"
    return "0" if s in ("-0", "0") else s


def vec(xs: Iterable[float]) -> str:
    return " ".join(num(x) for x in xs)


def degrees(deg: float) -> str:
    return f"{deg:.6g}deg"


def angle(rad: float) -> str:
    return degrees(math.degrees(rad))


def angle_text(rad: float) -> str:
    return f"{math.degrees(rad):.1f}°"


__all__ = ["angle", "angle_text", "degrees", "num", "vec"]
