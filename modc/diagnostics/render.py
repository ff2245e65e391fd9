"""Render diagnostics for people (text with a caret excerpt) and for machines (JSON)."""

from __future__ import annotations

import hashlib
import json
import os
import re
import unicodedata
from collections.abc import Iterable, Mapping
from pathlib import Path
from urllib.parse import quote

from .diagnostic import Diagnostic, sort_key


def display_width(text: str) -> int:
    """Terminal columns of text: East Asian wide and fullwidth characters take two, combining
    marks none (so that a caret lines up under CJK names and emoji)."""
    return sum(0 if unicodedata.combining(c) else 2 if unicodedata.east_asian_width(c) in "WF" else 1 for c in text)


# Characters never echoed as they are: controls (ESC and BEL retitle or recolour a terminal),
# format characters (bidi overrides reorder what is shown), surrogates, private use, unassigned
# and U+2028/U+2029; the same set names refuse (modc.names).
_UNSHOWN = {"Cc", "Cf", "Cs", "Co", "Cn", "Zl", "Zp"}


def shown_char(c: str) -> str:
    """One source character as an excerpt shows it: itself, or its escape as a message quotes it
    (repr: '\\x1b', '\\u202e'); the caret spans the whole escape."""
    return repr(c)[1:-1] if unicodedata.category(c) in _UNSHOWN else c


def excerpt(source: str, d: Diagnostic) -> list[str]:
    """The offending source line and a caret line under the span (clipped to that line)."""
    lines = source.split("\n")  # as the parser counts lines: \f, \v or U+2028 do not end one
    if not (1 <= d.span.line <= len(lines)):
        return []
    text = lines[d.span.line - 1].rstrip("\r").expandtabs(1)
    if len(text) > 200:  # a minified or binary "line": show a window around the column
        lo = max(0, d.span.col - 60)
        text, col = text[lo : lo + 120], d.span.col - lo
    else:
        col = d.span.col
    end = d.span.end_col if d.span.end_line == d.span.line else len(text) + 1
    end = min(end, len(text) + 1)
    pieces = [shown_char(c) for c in text]
    lead = display_width("".join(pieces[: col - 1]))
    width = max(1, display_width("".join(pieces[col - 1 : end - 1])))
    gutter = f"{d.span.line:>4} | "
    return [gutter + "".join(pieces), " " * (len(gutter) - 2) + "| " + " " * lead + "^" * width]


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
        props = (
            f"file={_gh_escape(s.file, True)},line={s.line},col={s.col},endLine={s.end_line},endColumn={s.end_col},"
            f"title={_gh_escape('modc ' + d.code, True)}"
        )
        body = d.message + (f" (hint: {d.hint})" if d.hint else "")
        lines.append(f"::{level[d.severity.value]} {props}::{_gh_escape(body)}")
    return "\n".join(lines)


SARIF_ROOT = "SRCROOT"  # the uriBaseId of the repository root (GitHub code scanning's convention)


def sarif_location(file: str, root: Path) -> dict:
    """artifactLocation of a diagnostic's file: a percent-encoded URI reference relative to root
    (uriBaseId SRCROOT) when the file is under root, else an absolute file: URI."""
    path = Path(os.path.abspath(file))
    try:
        rel = path.relative_to(root)
    except ValueError:
        return {"uri": path.as_uri()}  # pathlib quotes os.fsencode(path): any bytes
    # quote() encodes ' ', '#', '%', ':' and non-ASCII: a reference, never a scheme. The name's
    # bytes, not its str: a name that is not UTF-8 (surrogate escapes) is percent-encoded as is.
    return {"uri": quote(os.fsencode(rel.as_posix()), safe="/"), "uriBaseId": SARIF_ROOT}


def _unicode(text: str) -> str:
    """text without lone surrogates (a file name that is not UTF-8, quoted in a message): JSON
    consumers other than Python reject them. Each undecodable byte becomes U+FFFD."""
    return text.encode("utf-8", "surrogateescape").decode("utf-8", "replace")


def _template_text(template: str) -> str:
    """A message or hint template in words: its fields as '…'."""
    return re.sub(r"(?<!\{)\{[^{}]*\}(?!\})", "…", template).replace("{{", "{").replace("}}", "}")


def _fingerprint(d: Diagnostic, uri: str, sources: Mapping[str, str]) -> str:
    """Stable across commits that move the finding: code, file and the offending line's text,
    not its number."""
    lines = sources.get(d.span.file, "").split("\n")
    line = lines[d.span.line - 1].strip() if 1 <= d.span.line <= len(lines) else ""
    key = "\0".join((d.code, uri, _unicode(d.message), _unicode(line)))
    return hashlib.sha256(key.encode("utf-8")).hexdigest()[:32]


def render_sarif(
    diags: Iterable[Diagnostic],
    version: str,
    root: str | os.PathLike | None = None,
    sources: Mapping[str, str] | None = None,
) -> str:
    """SARIF 2.1.0, one run; every registered code is a rule (so rule indices are stable), with
    its meaning as fullDescription and its hint as help. Paths are relative to root (default the
    working directory)."""
    from .codes import REGISTRY

    base = Path(os.path.abspath(root if root is not None else os.curdir))
    level = {"error": "error", "warning": "warning", "note": "note"}
    names = list(REGISTRY)
    rules = []
    for c in REGISTRY.values():
        hint = _template_text(c.hint) if c.hint.strip("{}") != "hint" else ""
        help_text = c.summary[:1].upper() + c.summary[1:] + "." + (f" Fix: {hint}." if hint.strip("…") else "")
        if c.allowable:
            help_text += f" An assembly rule: `allow {c.name}` inside the robot block silences it on purpose."
        rules.append(
            {
                "id": c.name,
                "name": "".join(w.capitalize() for w in c.name.split("-")),
                "shortDescription": {"text": c.summary},
                "fullDescription": {"text": f"{c.summary}: {_template_text(c.message)}"},
                "help": {"text": help_text, "markdown": help_text},
                "defaultConfiguration": {"level": level[c.severity.value]},
            }
        )
    results = []
    for d in sorted(diags, key=sort_key):
        s = d.span
        location = sarif_location(s.file, base)
        results.append(
            {
                "ruleId": d.code,
                "ruleIndex": names.index(d.code),
                "level": level[d.severity.value],
                "message": {"text": _unicode(d.message + (f"\nhint: {d.hint}" if d.hint else ""))},
                "locations": [
                    {
                        "physicalLocation": {
                            "artifactLocation": location,
                            "region": {
                                "startLine": s.line,
                                "startColumn": s.col,
                                "endLine": s.end_line,
                                "endColumn": max(s.end_col, s.col + 1),
                            },
                        }
                    }
                ],
                "partialFingerprints": {"modc/v1": _fingerprint(d, location["uri"], sources or {})},
            }
        )
    doc = {
        "$schema": "https://json.schemastore.org/sarif-2.1.0.json",
        "version": "2.1.0",
        "runs": [
            {
                "tool": {
                    "driver": {
                        "name": "modc",
                        "version": version,
                        "informationUri": "https://pypi.org/project/modc/",
                        "rules": rules,
                    }
                },
                # No uri: the root is wherever the consumer checked the repository out (and the
                # output stays the same on every machine).
                "originalUriBaseIds": {
                    SARIF_ROOT: {"description": {"text": "the repository root (modc lint --sarif-root)"}}
                },
                "columnKind": "unicodeCodePoints",
                "results": results,
            }
        ],
    }
    return json.dumps(doc, indent=2)
