"""Number formatting shared by text backends: deterministic, no '-0', enough digits for 1e-9 FK."""
from __future__ import annotations

from collections.abc import Iterable


def num(x: float) -> str:
    s = f"{float(x):.12g}"
    return "0" if s in ("-0", "0") else s


def vec(xs: Iterable[float]) -> str:
    return " ".join(num(x) for x in xs)
