"""Lowering of a design block's search statements: `units`, `modules`, `links`, `rank`.

Checks here need no library (integers, order, steps, known objectives); what does (unit names,
printable link lengths, the library's largest chain) is the check_problems pass.
"""
from __future__ import annotations

import math

from ..diagnostics import codes
from ..objectives import REGISTRY
from ..syntax import ast

MAX_LINK_LENGTHS = 12  # per link unit: beyond this the search space is not worth enumerating


def _count(low, q: ast.Quantity, what: str) -> int | None:
    if not math.isfinite(q.value):
        low.error(codes.NOT_FINITE.at(q.span, what=what))
        return None
    if q.value != int(q.value) or q.value < 1:
        low.error(codes.DESIGN_BOUND.at(q.span, what=f"{what} must be a whole number of units, got {q.value:g}",
                                        hint="write e.g. `units 1 to 3`"))
        return None
    return int(q.value)


def _units(low, st: ast.Units, out: dict) -> None:
    lo = _count(low, st.low, "the smallest chain")
    hi = _count(low, st.high, "the largest chain") if st.high is not None else lo
    if lo is None or hi is None:
        return
    if lo > hi:
        low.error(codes.DESIGN_BOUND.at(st.span, what=f"`units {lo} to {hi}` is an empty range",
                                        hint=f"write the smaller number first: `units {hi} to {lo}`"))
        return
    out["min_units"], out["max_units"] = lo, hi
    out["bound_spans"]["units"] = st.span


def _links(low, st: ast.Links, out: dict) -> None:
    lo = low.quantity(st.low, "a length", "shortest link")
    hi = low.quantity(st.high, "a length", "longest link") if st.high is not None else lo
    step = low.quantity(st.step, "a length", "link step") if st.step is not None else None
    if lo is None or hi is None or (st.step is not None and step is None):
        return
    if lo > hi:
        low.error(codes.DESIGN_BOUND.at(st.span, what="the shortest link is longer than the longest",
                                        hint="write `links SHORTEST to LONGEST`"))
        return
    if step is None:
        step = hi - lo if hi > lo else 1.0
    if step <= 0:
        where = st.step.span if st.step is not None else st.span
        low.error(codes.DESIGN_BOUND.at(where, what="the link step must be positive",
                                        hint="e.g. `links 150 mm to 300 mm step 50 mm`"))
        return
    steps = (hi - lo) / step  # inf for a subnormal step (1e-320 m): compare before int()
    if not steps + 1e-9 < MAX_LINK_LENGTHS:
        many = f"{int(steps + 1e-9) + 1:,}" if steps < 1e12 else "over a trillion"
        low.error(codes.DESIGN_BOUND.at(st.span, what=f"{many} link lengths per link unit are too many to search",
                                        hint=f"use a coarser step: at most {MAX_LINK_LENGTHS} lengths"))
        return
    n = int(math.floor(steps + 1e-9)) + 1
    out["links"] = tuple(round(lo + k * step, 9) for k in range(n))
    out["bound_spans"]["links"] = st.span


def lower_bounds(low, statements: list, block: str) -> dict:
    out: dict = {"bound_spans": {}}
    seen: set[type] = set()
    for st in statements:
        if type(st) in seen:
            what = type(st).__name__.lower()
            low.error(codes.DUPLICATE_STATEMENT.at(st.span, what=what, block=block))
            continue
        seen.add(type(st))
        match st:
            case ast.Units():
                _units(low, st, out)
            case ast.Modules():
                out["modules"] = tuple(dict.fromkeys(n.text for n in st.names))
                out["bound_spans"].update({f"module:{n.text}": n.span for n in st.names})
            case ast.Links():
                _links(low, st, out)
            case ast.Rank():
                keys = []
                for k in st.keys:
                    if k.text not in REGISTRY:
                        known = ", ".join(REGISTRY)
                        low.error(codes.UNKNOWN_OBJECTIVE.at(k.span, name=k.text, known=known))
                    elif k.text in keys:  # an order is ambiguous with one objective in two places
                        low.error(codes.DUPLICATE_OBJECTIVE.at(k.span, name=k.text, block=block))
                    else:
                        keys.append(k.text)
                        out["bound_spans"][f"rank:{k.text}"] = k.span
                # objectives not named keep their default order after the named ones
                out["rank"] = tuple(keys) + tuple(k for k, o in REGISTRY.items() if o.default and k not in keys)
    return out
