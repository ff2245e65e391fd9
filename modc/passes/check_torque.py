"""Can the arm carry itself and its payload? Worst static gravity torque per joint against the
actuator's nominal (warning) and peak (error) torque. Runs when ctx.analyses has "torque", with the
search the compiler hands in (ctx.torque_analysis: modc.dynamics.torque.analyse); a pass imports no
physics, so `modc lint` stays light and the layers stay one-way."""
from __future__ import annotations

import math

from ..diagnostics import codes
from ..model import Design
from .context import Context


def _pose(q) -> str:
    return "(" + ", ".join(f"{math.degrees(x):.0f}" for x in q) + ") deg"


def run(design: Design, ctx: Context) -> Design:
    if "torque" not in ctx.analyses or ctx.torque_severity == "off" or ctx.has_errors:
        return design
    analyse = ctx.torque_analysis
    if analyse is None:  # a driver asked for the analysis without handing it in: a bug, not a user error
        raise RuntimeError("the torque analysis was asked for but ctx.torque_analysis is not set")

    robots = []
    for r in design.resolved_robots():  # no errors so far: resolve_library found every library
        result = analyse(r, ctx.payload_override)
        lib = r.library
        eps_ok = all(sum(u.variant == v for u in r.units) <= lib.variants[v].actuator.epsilon for v in lib.variants)
        eps = " (the chain obeys the paper's ε rule, but the physics says no)" if eps_ok else ""
        for i, j in enumerate(result):
            fields = dict(joint=j.name, unit=j.variant, tau=f"{j.tau:.3g} N·m", pose=_pose(j.q),
                          tau_nom=f"{j.tau_nom:g} N·m", tau_max=f"{j.tau_max:g} N·m", eps=eps)
            span = r.units[i].span
            if j.level == "over-peak":
                d = codes.TORQUE_OVER_PEAK.at(span, **fields)
                if ctx.torque_severity == "warning":
                    d = d.__class__(d.code, codes.Severity.WARNING, d.span, d.message, d.hint)
                ctx.report(d, r)
            elif j.level == "over-nominal":
                ctx.report(codes.TORQUE_OVER_NOMINAL.at(span, **fields), r)
        if not eps_ok and all(j.level == "ok" for j in result):
            worst = min(result, key=lambda j: (j.tau_nom - j.tau) / j.tau_nom)
            msg = (f"robot '{r.name}' has more modules of one kind than ε allows, yet every joint stays within its "
                   f"nominal torque (tightest: {worst.name}, {worst.tau:.3g} of {worst.tau_nom:g} N·m)")
            ctx.report(codes.EPSILON_DISAGREES.at(r.name_span, message=msg), r)
        robots.append(r.model_copy(update={"torque": tuple(result)}))
    return design.model_copy(update={"robots": tuple(robots)})
