"""Render diagnostics for people (text with a caret excerpt) and for machines (JSON)."""
from __future__ import annotations

import json
from collections.abc import Iterable, Mapping

from .diagnostic import Diagnostic, sort_key


def excerpt(source: str, d: Diagnostic) -> list[str]:
    """The offending source line and a caret line under the span (clipped to that line)."""
    lines = source.split("\n")  # as the parser counts lines: \f, \v or U+2028 do not end one
    if not (1 <= d.span.line <= len(lines)):
        return []
    text = lines[d.span.line - 1].rstrip("\r").expandtabs(1)
    if len(text) > 200:  # a minified or binary "line": show a window around the column
        lo = max(0, d.span.col - 60)
        text, col = text[lo:lo + 120], d.span.col - lo
    else:
        col = d.span.col
    end = d.span.end_col if d.span.end_line == d.span.line else len(text) + 1
    width = max(1, min(end, len(text) + 1) - col)
    gutter = f"{d.span.line:>4} | "
    return [gutter + text, " " * (len(gutter) - 2) + "| " + " " * (col - 1) + "^" * width]


def format_text(d: Diagnostic, sources: Mapping[str, str] | None = None) -> str:
    head = f"{d.span.file}:{d.span.line}:{d.span.col}: {d.severity.value}[{d.code}]: {d.message}"
    out = [head]
    src = (sources or {}).get(d.span.file)
    if src is not None:
        out += excerpt(src, d)
    if d.hint:
        out.append(f"     = hint: {d.hint}")
    return "\n".join(out)


def render_text(diags: Iterable[Diagnostic], sources: Mapping[str, str] | None = None) -> str:
    return "\n".join(format_text(d, sources) for d in sorted(diags, key=sort_key))


def render_json(diags: Iterable[Diagnostic]) -> str:
    items = [d.to_json() for d in sorted(diags, key=sort_key)]
    return json.dumps({"version": 1, "diagnostics": items}, indent=2, sort_keys=False)


def summary(diags: list[Diagnostic]) -> str:
    e = sum(d.severity.value == "error" for d in diags)
    w = sum(d.severity.value == "warning" for d in diags)
    return f"{e} error{'s' * (e != 1)}, {w} warning{'s' * (w != 1)}"


def _gh_escape(text: str, prop: bool = False) -> str:
    # GitHub workflow-command escaping: data escapes %, CR, LF; properties also ':' and ','
    text = text.replace("%", "%25").replace("\r", "%0D").replace("\n", "%0A")
    if prop:
        text = text.replace(":", "%3A").replace(",", "%2C")
    return text


def render_github(diags: Iterable[Diagnostic]) -> str:
    """GitHub Actions annotations: ::error file=…,line=…,col=…,endLine=…,endColumn=…,title=…::message"""
    level = {"error": "error", "warning": "warning", "note": "notice"}
    lines = []
    for d in sorted(diags, key=sort_key):
        s = d.span
        props = f"file={_gh_escape(s.file, True)},line={s.line},col={s.col},endLine={s.end_line},endColumn={s.end_col},title={_gh_escape('modc ' + d.code, True)}"
        body = d.message + (f" (hint: {d.hint})" if d.hint else "")
        lines.append(f"::{level[d.severity.value]} {props}::{_gh_escape(body)}")
    return "\n".join(lines)


def render_sarif(diags: Iterable[Diagnostic], version: str) -> str:
    """SARIF 2.1.0, one run; every registered code is a rule (so rule indices are stable)."""
    from .codes import REGISTRY

    level = {"error": "error", "warning": "warning", "note": "note"}
    names = list(REGISTRY)
    rules = [{
        "id": c.name,
        "name": "".join(w.capitalize() for w in c.name.split("-")),
        "shortDescription": {"text": c.summary},
        "defaultConfiguration": {"level": level[c.severity.value]},
    } for c in REGISTRY.values()]
    results = []
    for d in sorted(diags, key=sort_key):
        s = d.span
        results.append({
            "ruleId": d.code,
            "ruleIndex": names.index(d.code),
            "level": level[d.severity.value],
            "message": {"text": d.message + (f"\nhint: {d.hint}" if d.hint else "")},
            "locations": [{"physicalLocation": {
                "artifactLocation": {"uri": s.file.replace("\\", "/")},
                "region": {"startLine": s.line, "startColumn": s.col, "endLine": s.end_line, "endColumn": max(s.end_col, s.col + 1)},
            }}],
        })
    doc = {
        "$schema": "https://json.schemastore.org/sarif-2.1.0.json",
        "version": "2.1.0",
        "runs": [{
            "tool": {"driver": {"name": "modc", "version": version, "informationUri": "https://pypi.org/project/modc/", "rules": rules}},
            "columnKind": "unicodeCodePoints",
            "results": results,
        }],
    }
    return json.dumps(doc, indent=2)
