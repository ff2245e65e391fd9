"""The paper's assembly rules (section 3): H first, L last, no L -> H, at most ε of each kind."""
from __future__ import annotations

import itertools
from collections import Counter

from ..diagnostics import codes
from ..model import Design, ResolvedRobot
from .context import Context


def run(design: Design, ctx: Context) -> Design:
    for r in design.robots:
        if not isinstance(r, ResolvedRobot):  # resolve_library has reported it
            continue
        lib = r.library
        units = [u for u in r.units if u.variant]
        if not units or len(units) != len(r.units) or len(units) > lib.rules.max_dof:
            continue  # unknown units or an oversized chain were reported already; rules would only echo them
        rules = lib.rules
        first, last = units[0], units[-1]
        if first.variant != rules.first_variant:
            ctx.report(codes.FIRST_VARIANT.at(first.span, unit=first.name, want=rules.first_variant), r)
        if last.variant != rules.last_variant:
            ctx.report(codes.LAST_VARIANT.at(last.span, unit=last.name, want=rules.last_variant), r)
        for before, after in itertools.pairwise(units):
            allowed = rules.may_follow.get(before.variant, [])
            if after.variant not in allowed:
                text = "; ".join(f"{v} -> {', '.join(s)}" for v, s in rules.may_follow.items())
                ctx.report(
                    codes.ILLEGAL_SUCCESSION.at(after.span, before=before.name, after=after.name, allowed=text), r
                )
        counts = Counter(u.variant for u in units)
        for variant, count in sorted(counts.items()):
            eps = lib.variants[variant].actuator.epsilon
            if count > eps:
                extra = [u for u in units if u.variant == variant][eps]
                ctx.report(codes.EPSILON_EXCEEDED.at(extra.span, count=count, variant=variant, eps=eps), r)
    return design
