"""`modc dh2mod`: a DH CSV -> checked model -> .mod text or JSON, through the normal passes.

A driver like modc.compiler (it runs the pass list), so it sits at the compiler's layer, above
modc.dh (which the convert_dh pass calls) and modc.passes.
"""
from __future__ import annotations

import json
import math
import re
from pathlib import Path

from . import names
from .dh.report import compare
from .dh.table import read_csv
from .diagnostics import Diagnostic, Span, codes
from .diagnostics.span import NOWHERE
from .model import Design, Robot
from .model.write import robot_text
from .passes import Context, run_all


def _name(path: str) -> str:
    """The file's stem as a robot name (modc.names' identifier rule: ASCII, at most MAX_NAME)."""
    stem = re.sub(r"[^A-Za-z0-9_]", "_", Path(path).stem) or "arm"
    return (stem if re.match(r"[A-Za-z_]", stem) else f"arm_{stem}")[: names.MAX_NAME]


def convert_table(text: str, path: str, name: str | None = None, fit_links: bool = False,
                  library: str | None = None, as_json: bool = False) -> tuple[str, list[Diagnostic], bool]:
    rows, diags = read_csv(text, path)
    if any(d.is_error for d in diags):
        return "", diags, False
    where = Span.point(path)
    problem = names.identifier_problem(name or _name(path))
    if problem:  # only --name can break the rule
        bad = codes.INVALID_NAME.at(Span.point("<command line>"), what="robot", name=names.shown(name or ""),
                                    problem=problem, rule=names.IDENTIFIER_RULE)
        return "", [*diags, bad], False
    robot = Robot(name=name or _name(path), dh=tuple(rows), dh_fit_links=fit_links, span=where, name_span=where,
                  library_span=NOWHERE)  # no `library` statement: --library or the default
    ctx = Context(diagnostics=diags, library_override=library)
    design = run_all(Design(path=path, robots=(robot,)), ctx)
    if ctx.has_errors:
        return "", ctx.diagnostics, False
    r = design.resolved_robots()[0]
    table = compare(r)
    if as_json:
        return json.dumps({"sequence": r.sequence, "joints": table}, indent=2) + "\n", ctx.diagnostics, True
    comments = [f"Converted by modc dh2mod from {Path(path).name} (standard DH; paper section 4.2)."]
    comments.append("joint   requested a, alpha, d        realised a, alpha, d")
    for i, row in enumerate(table, start=1):
        q, x = row["requested"], row["realised"]
        comments.append(f"{i:>3}   {q['a']:.4f} m {math.degrees(q['alpha']):8.3f}° {q['d']:.4f} m"
                        f"   {x['a']:.4f} m {math.degrees(x['alpha']):8.3f}° {x['d']:.4f} m")
    return robot_text(r, comments), ctx.diagnostics, True
