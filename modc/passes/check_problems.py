"""Design blocks (`modc design` problems): the library resolves, the bounds fit it, names are unique.

The cell of a problem is a robot without units, so what robots get from resolve_library,
check_names and check_environment is done here for it; then `modules` names exist in the
library, `links` lengths are printable and `units` stays within the library's largest chain.
"""
from __future__ import annotations

import difflib
from pathlib import Path

from ..diagnostics import codes
from ..model import Design, Problem, ResolvedRobot, Robot, resolved, resolved_problem
from ..model import library as lib
from .context import Context
from .resolve_library import load_for


def _check(p: Problem, library, ctx: Context) -> None:
    names: set[str] = set()
    declared = [(t.name, t.span) for t in p.cell.targets] + [(o.name, o.span) for o in p.cell.obstacles]
    for name, span in sorted(declared, key=lambda x: (x[1].line, x[1].col)):
        if name in names:
            ctx.report(codes.DUPLICATE_NAME.at(span, name=name, block=f"design '{p.name}'"))
        names.add(name)
    for o in p.cell.obstacles:
        if any(v <= 0 for v in o.size):
            ctx.report(codes.NONPOSITIVE_SIZE.at(o.span, what=f"every dimension of {o.shape} '{o.name}'",
                                                 value=", ".join(f"{v:g} m" for v in o.size)))
    if p.cell.payload is not None and p.cell.payload.mass <= 0:
        ctx.report(codes.NONPOSITIVE_SIZE.at(p.cell.payload.span, what="the payload mass",
                                             value=f"{p.cell.payload.mass:g} kg"))
    for name in p.modules or ():
        if library.split(name) is None:
            close = difflib.get_close_matches(name.upper(), library.unit_names(), n=1, cutoff=0.5)
            suggest = f"; did you mean {close[0]}?" if close else ""
            ctx.report(codes.UNKNOWN_MODULE.at(p.bound_spans.get(f"module:{name}", p.name_span), name=name,
                                               known=", ".join(library.unit_names()), suggest=suggest))
    rules = library.rules
    if p.max_units > rules.max_dof:
        ctx.report(codes.DESIGN_BOUND.at(p.bound_spans.get("units", p.name_span),
                                         what=f"chains of {p.max_units} units cannot be assembled from this library",
                                         hint=f"the library allows {rules.min_dof} to {rules.max_dof} units"))
    for length in p.links or ():
        if not (library.link_length_min <= length <= library.link_length_max):
            ctx.report(codes.LINK_LENGTH_RANGE.at(p.bound_spans.get("links", p.name_span), value=f"{length:g} m",
                                                  low=f"{library.link_length_min:g} m",
                                                  high=f"{library.link_length_max:g} m"))
            break


def _reference(ref: Robot, cell: ResolvedRobot, library, ctx: Context) -> ResolvedRobot:
    """`compare with chain …`: its units tagged and checked as a robot block's chain is (the
    library's modules, the assembly rules, the twists), diagnostics at the units as written."""
    from . import check_assembly, check_modules, check_twists

    units = []
    for u in ref.units:
        vk = library.split(u.name)
        units.append(u.model_copy(update={"variant": vk[0], "kind": vk[1]}) if vk else u)
    ref = cell.model_copy(update={"name": ref.name, "units": tuple(units), "span": ref.span,
                                  "name_span": ref.name_span})
    alone = Design(path=ref.span.file, robots=(ref,))
    for check in (check_modules, check_assembly, check_twists):
        check.run(alone, ctx)
    return ref


def run(design: Design, ctx: Context) -> Design:
    problems = []
    for p in design.problems:
        library = load_for(p.cell, ctx)  # the robots' lookup, diagnostics included
        if library is not None:
            _check(p, library, ctx)
            update: dict = {}
            if ctx.library_override:  # the designs written must name the library they were found with
                path = ctx.library_override not in lib.BUILTIN
                update |= {"library_ref": ctx.library_override, "library_dir": str(Path.cwd()) if path else None}
            cell = resolved(p.cell, library, **update)
            p = resolved_problem(p, cell)
            if p.reference is not None:
                p = p.model_copy(update={"reference": _reference(p.reference, cell, library, ctx)})
        problems.append(p)
    return design.model_copy(update={"problems": tuple(problems)})
