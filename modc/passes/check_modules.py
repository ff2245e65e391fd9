"""Every modular unit of the chain (H1…L4) exists in the library, its parameters apply to it, and
the DoF is in bounds. (Modular units of the paper, not units of measure: those are checked while
lowering the syntax.)
"""
from __future__ import annotations

import difflib

from ..diagnostics import codes
from ..formatting import counted
from ..model import Design, ResolvedRobot
from .context import Context


def _fmt_len(x: float) -> str:
    return f"{x:g} m"


def run(design: Design, ctx: Context) -> Design:
    for r in design.robots:
        if not isinstance(r, ResolvedRobot):  # resolve_library has reported it
            continue
        lib = r.library
        for u in r.units:
            if not u.variant:
                close = difflib.get_close_matches(u.name.upper(), lib.unit_names(), n=1, cutoff=0.5)
                suggest = f"; did you mean {close[0]}?" if close else ""
                ctx.report(
                    codes.UNKNOWN_MODULE.at(u.span, name=u.name, known=", ".join(lib.unit_names()), suggest=suggest), r
                )
                continue
            if not lib.units[u.kind].link:
                for param in ("port", "link"):
                    if param in u.param_spans:
                        ctx.report(codes.PARAMETER_NOT_APPLICABLE.at(
                            u.param_spans[param], param=param, unit=u.name, kind=u.kind, variant=u.variant), r)
            elif u.link is not None and not (lib.link_length_min <= u.link <= lib.link_length_max):
                ctx.report(
                    codes.LINK_LENGTH_RANGE.at(
                        u.param_spans["link"],
                        value=_fmt_len(u.link),
                        low=_fmt_len(lib.link_length_min),
                        high=_fmt_len(lib.link_length_max),
                    ),
                    r,
                )
        n, rules = len(r.units), lib.rules
        if n > rules.max_dof:
            limits = ", ".join(f"{v}: {lib.variants[v].actuator.epsilon}" for v in lib.variants)
            ctx.report(codes.TOO_MANY_UNITS.at(r.units[rules.max_dof].span, n=counted(n, "unit"), max=rules.max_dof,
                                               limits=limits), r)
        elif 0 < n < rules.min_dof:
            ctx.report(codes.TOO_FEW_UNITS.at(r.name_span, n=counted(n, "unit"), min=rules.min_dof), r)
    return design
