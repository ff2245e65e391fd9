"""Load each robot's module library and tag every unit with its variant and type."""
from __future__ import annotations

from pathlib import Path

from ..model import Design, Robot, resolved
from ..model import library as lib
from .context import Context


def load_for(r: Robot, ctx: Context) -> lib.Library | None:
    """The library of a robot (or of a design block's cell): --library, else its `library`
    statement (a path relative to its file), else the default; None once the error is reported."""
    ref = ctx.library_override or r.library_ref
    where = Path(r.library_dir) if r.library_dir and not ctx.library_override else None
    try:
        return lib.load(ref, where)
    except lib.LibraryError as e:
        span = r.library_span if r.library_ref == ref and r.library_span.file != "<unknown>" else r.name_span
        if e.span is not None and e.text is not None:
            # a problem inside a file that has parsed as a library: point at it there (with
            # the caret excerpt); a file that is not a library is never quoted
            span = e.span
            ctx.sources[span.file] = e.text
        ctx.report(e.diagnostic(span, ref))
        return None


def run(design: Design, ctx: Context) -> Design:
    robots: list[Robot] = []
    for r in design.robots:
        library = load_for(r, ctx)
        if library is None:
            robots.append(r)
            continue
        units = []
        for u in r.units:
            vk = library.split(u.name)
            units.append(u.model_copy(update={"variant": vk[0], "kind": vk[1]}) if vk else u)
        robots.append(resolved(r, library, units=tuple(units)))
    return design.model_copy(update={"robots": tuple(robots)})
