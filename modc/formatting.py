"""How modc writes numbers and angles as text: one home for every layer (no imports but math).

    num, vec      numbers in output files: deterministic, no '-0', 12 significant digits
                  (enough for 1e-9 FK); backends/format.py re-exports them
    degrees       an angle already in degrees as .mod source: 6 significant digits, "45deg"
    angle         an angle in radians written the same way (diagnostics quote the user's units)
    angle_text    an angle in radians for a human report: one decimal, "45.0°"
    fixed         a number exact to `digits` decimals, trailing zeros dropped: .mod source that
                  reads back to the value (model/write.py: degrees to 1e-9, millimetres to 1e-6)
    json_number   a number in the trajectory JSON: rounded to 1e-12, Python's shortest repr
    counted       a count and its noun for a message: "1 joint", "3 joints", "1,024 settings"
"""
from __future__ import annotations

import math
from collections.abc import Iterable


def num(x: float) -> str:
    s = f"{float(x):.12g}"
    return "0" if s in ("-0", "0") else s


def vec(xs: Iterable[float]) -> str:
    return " ".join(num(x) for x in xs)


def fixed(x: float, digits: int = 9) -> str:
    s = f"{round(x, digits):.{digits}f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def json_number(x: float) -> str:
    v = round(float(x), 12)
    return "0.0" if v == 0 else repr(v)


def degrees(deg: float) -> str:
    return f"{deg:.6g}deg"


def angle(rad: float) -> str:
    return degrees(math.degrees(rad))


def angle_text(rad: float) -> str:
    return f"{math.degrees(rad):.1f}°"


__all__ = ["angle", "angle_text", "degrees", "fixed", "json_number", "num", "vec"]


def counted(n: int, noun: str, plural: str | None = None) -> str:
    """n with its noun, singular when n is 1 (plural: the noun's plural when not noun + 's')."""
    return f"{n:,} {noun if n == 1 else plural or noun + 's'}"
