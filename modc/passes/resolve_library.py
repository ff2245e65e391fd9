"""Load each robot's module library and tag every unit with its variant and type."""
from __future__ import annotations

from pathlib import Path

from .. import names
from ..diagnostics import codes
from ..model import Design
from ..model import library as lib
from .context import Context


def run(design: Design, ctx: Context) -> Design:
    robots = []
    for r in design.robots:
        ref = ctx.library_override or r.library_ref
        where = Path(r.library_dir) if r.library_dir and not ctx.library_override else None
        try:
            library = lib.load(ref, where)
        except lib.LibraryError as e:
            code = codes.LIBRARY_NOT_FOUND if "not found" in str(e) else codes.LIBRARY_INVALID
            span = r.library_span if r.library_ref == ref and r.library_span.file != "<unknown>" else r.name_span
            if e.span is not None:  # a problem inside the library file: point at it there
                span = e.span
                ctx.sources[span.file] = e.text or ""
            ctx.report(code.at(span, name=names.shown(ref, 200), detail=str(e), builtins=", ".join(lib.BUILTIN)))
            robots.append(r)
            continue
        units = []
        for u in r.units:
            vk = library.split(u.name)
            units.append(u.model_copy(update={"variant": vk[0], "kind": vk[1]}) if vk else u)
        robots.append(r.model_copy(update={"library": library, "units": tuple(units)}))
    return design.model_copy(update={"robots": tuple(robots)})
