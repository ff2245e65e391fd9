"""Obstacles have positive sizes and the payload a positive mass."""
from __future__ import annotations

from ..diagnostics import codes
from ..model import Design
from .context import Context


def run(design: Design, ctx: Context) -> Design:
    for r in design.robots:
        for o in r.obstacles:
            for v in o.size:
                if v <= 0:
                    ctx.report(
                        codes.NONPOSITIVE_SIZE.at(
                            o.span, what=f"every dimension of {o.shape} '{o.name}'", value=f"{v:g} m"
                        ),
                        r,
                    )
                    break
        if r.payload is not None and r.payload.mass <= 0:
            ctx.report(
                codes.NONPOSITIVE_SIZE.at(r.payload.span, what="the payload mass", value=f"{r.payload.mass:g} kg"), r
            )
    return design
