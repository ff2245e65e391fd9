"""Pivot and port twists must be settable on the library's hardware (docs/conventions.md)."""
from __future__ import annotations

import math

from ..diagnostics import codes
from ..formatting import degrees
from ..model import Design, ResolvedRobot
from ..model.library import TwistSet
from .context import Context


def _reason(ts: TwistSet, deg: float) -> str:
    if not ts.wraps and not (ts.min_deg - 1e-9 <= deg <= ts.max_deg + 1e-9):
        return f"the range is {degrees(ts.min_deg)}..{degrees(ts.max_deg)}"
    return f"it is set in steps of {degrees(ts.step_deg)}"


def run(design: Design, ctx: Context) -> Design:
    for r in design.robots:
        if not isinstance(r, ResolvedRobot):  # resolve_library has reported it
            continue
        lib = r.library
        for u in r.units:
            for param, ts in (("pivot", lib.twists.pivot), ("port", lib.twists.port)):
                if param not in u.param_spans:
                    continue
                deg = math.degrees(getattr(u, param))
                if not ts.realisable(deg):
                    ctx.report(codes.TWIST_NOT_REALISABLE.at(
                        u.param_spans[param], what=f"{u.name} {param}", value=degrees(deg),
                        reason=_reason(ts, deg), nearest=degrees(ts.nearest(deg))), r)
    return design
