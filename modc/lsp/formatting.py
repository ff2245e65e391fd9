"""Formatting: the document in `modc fmt`'s canonical form."""

from __future__ import annotations

from lsprotocol import types

from .document import Analysis


def formatting(an: Analysis) -> list[types.TextEdit]:
    """One edit replacing the whole document with `modc fmt`'s canonical form
    (modc.syntax.format.format_text); none when the formatter is not there, the document is
    YAML, it does not parse, or it is formatted already. A formatter failure (FormatterBug)
    propagates: the server logs it and answers no edits."""
    if an.is_yaml:
        return []
    try:
        from ..syntax.format import format_text
    except ImportError:
        return []
    new, _diagnostics = format_text(an.text, an.path)  # text, or None when it does not parse
    if new is None or new == an.text:
        return []
    return [types.TextEdit(range=an.index.whole(), new_text=new)]
