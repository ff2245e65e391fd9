"""The lint parse's tables as shipped with modc (grammar/modc.lalr.json): modc.syntax.lalr's data
for the grammar, exported from Lark once, when the grammar changes, so that even a first
`modc lint` (a CI runner's empty cache, a fresh install) imports no lark and builds no tables
(~230 ms). Used only when the grammar and the installed lark's version are the ones the file was
made from; otherwise modc's cache serves (modc.syntax.parser._runtime). Remake it with

    python -m modc.syntax.tables

(tests/test_lalr_runtime.py fails while it is stale).
"""
from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

from ..resources import data_dir

NAME = "modc.lalr.json"


def lark_version() -> str | None:
    """The installed lark's version, read from its package without importing it (~35 ms)."""
    import importlib.util
    import re

    spec = importlib.util.find_spec("lark")
    if spec is None or spec.origin is None:
        return None
    try:
        with open(spec.origin, encoding="utf-8") as f:
            m = re.search(r"""^__version__\s*(?::\s*str\s*)?=\s*["']([^"']+)["']""", f.read(), re.M)
    except (OSError, UnicodeDecodeError):
        return None
    return m.group(1) if m else None


def _stamp(text: str) -> dict[str, Any]:
    from .lalr import FORMAT
    from .parser import _OPTIONS

    return {"grammar": hashlib.sha256(text.encode("utf-8")).hexdigest(), "options": repr(sorted(_OPTIONS.items())),
            "format": FORMAT, "lark": lark_version()}


def _to_json(data: dict) -> dict:
    # JSON keys are strings: the parser states' numbers become text here and numbers again in _from_json
    return {**data, "states": {str(k): v for k, v in data["states"].items()},
            "lexer_of": {str(k): v for k, v in data["lexer_of"].items()}}


def _from_json(doc: dict) -> dict:
    return {**doc, "states": {int(k): {t: tuple(a) for t, a in v.items()} for k, v in doc["states"].items()},
            "lexer_of": {int(k): v for k, v in doc["lexer_of"].items()}}


def load(text: str) -> dict | None:
    """The shipped data, when it was made from this grammar text with this lark; else None."""
    try:
        with open(data_dir("grammar") / NAME, encoding="utf-8") as f:
            doc = json.load(f)
        if doc.get("stamp") != _stamp(text) or doc["stamp"]["lark"] is None:
            return None
        return _from_json(doc["data"])
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return None


def make(text: str) -> dict:
    """The file's content for this grammar text, exported from a freshly built Lark."""
    import lark

    from .lalr import export
    from .parser import _OPTIONS

    data = export(lark.Lark(text, **_OPTIONS), "start")
    if data is None:
        raise RuntimeError("the grammar uses a Lark feature modc.syntax.lalr does not run")
    return {"stamp": _stamp(text), "data": _to_json(data)}


def write(path: Path | None = None) -> Path:
    where = data_dir("grammar")
    out = path or where / NAME
    doc = make((where / "modc.lark").read_text(encoding="utf-8"))
    out.write_text(json.dumps(doc, sort_keys=True, separators=(",", ":")) + "\n", encoding="utf-8")
    return out


if __name__ == "__main__":
    print(f"wrote {write()}")
