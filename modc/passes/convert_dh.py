"""Robots given as a DH table get their chain here (modc/dh/convert.py has the policy)."""
from __future__ import annotations

import math

from ..diagnostics import codes
from ..formatting import counted
from ..model import Design, ResolvedRobot
from .context import Context


def run(design: Design, ctx: Context) -> Design:
    robots = []
    for r in design.robots:
        if r.dh is None or not isinstance(r, ResolvedRobot) or not r.dh:
            robots.append(r)
            continue
        from ..dh.convert import convert
        from ..dh.report import compare

        lib = r.library
        max_dof = lib.rules.max_dof
        if len(r.dh) > max_dof:  # converting (and rounding) thousands of rows would only bury this
            limits = ", ".join(f"{v}: {lib.variants[v].actuator.epsilon}" for v in lib.variants)
            ctx.report(codes.TOO_MANY_UNITS.at(r.dh[max_dof].span, n=counted(len(r.dh), "unit"), max=max_dof,
                                               limits=limits), r)
            robots.append(r)
            continue

        conv = convert(r, lib)
        for d in conv.diagnostics:
            ctx.report(d, r)
        tool = r.tool
        if conv.tool.rpy != (0.0, 0.0, 0.0):
            tool = tool.model_copy(update={"rpy": conv.tool.rpy})
        r = r.model_copy(update={"units": conv.units, "tool": tool})
        if len(r.units) <= lib.rules.max_dof and all(
            u.link is None or lib.link_length_min <= u.link <= lib.link_length_max for u in r.units
        ):
            rows = compare(r)
            da = max(abs(x["realised"]["a"] - x["requested"]["a"]) for x in rows)
            dal = max(abs(x["realised"]["alpha"] - x["requested"]["alpha"]) for x in rows)
            dd = max(abs(x["realised"]["d"] - x["requested"]["d"]) for x in rows)
            hint = "`modc dh FILE` lists every row"
            if da > 1e-3 and not r.dh_fit_links:
                hint = "write `dh fit-links { … }` to print links that realise a exactly; " + hint
            ctx.report(
                codes.DH_APPROXIMATION.at(
                    r.name_span,
                    robot=r.name,
                    da=f"{da * 1000:.1f} mm",
                    dalpha=f"{math.degrees(dal):.2f}deg",
                    dd=f"{dd * 1000:.1f} mm",
                    hint=hint,
                ),
                r,
            )
        robots.append(r)
    return design.model_copy(update={"robots": tuple(robots)})
