"""Reading a module library file, and the rule for what of it a diagnostic may show.

A `library "PATH"` reference may name any file (/etc/passwd, a .env file in an untrusted .mod
that CI lints). Until the file has parsed as a module library (UTF-8 YAML whose top level is a
mapping with LIBRARY_KEYS) nothing of it is shown: errors say what kind of file it is not, and
carry no span or text. Only a library's own problems point into it, with its text for the caret
excerpt.
"""
from __future__ import annotations

from .. import names
from ..diagnostics import Span


class LibraryError(Exception):
    """A library that cannot be used; span points into the library file when the problem has a
    place there (text is that file, for the caret excerpt), else it is None. code is the
    diagnostic code's name; fields fill its message when it is not library-invalid's."""

    def __init__(self, message: str, span: Span | None = None, text: str | None = None,
                 code: str = "library-invalid", fields: dict[str, str] | None = None):
        super().__init__(message)
        self.span, self.text, self.code, self.fields = span, text, code, fields or {}

    def diagnostic(self, span: Span, ref: str):
        """The diagnostic at span (the reference in the .mod file, or self.span in the library)."""
        from ..diagnostics import REGISTRY
        from .library import BUILTIN

        fields = self.fields or {"name": names.shown(ref, 200), "detail": str(self),
                                 "builtins": ", ".join(BUILTIN)}
        return REGISTRY[self.code].at(span, **fields)


def _node_span(file: str, node) -> Span:
    s, e = node.start_mark, node.end_mark
    if e.line != s.line:  # a block: point at its first line only
        return Span(file, s.line + 1, s.column + 1, s.line + 1, s.column + 2, s.index, s.index + 1)
    end_col, end = max(e.column + 1, s.column + 2), max(e.index, s.index + 1)
    return Span(file, s.line + 1, s.column + 1, e.line + 1, end_col, s.index, end)


def where(text: str, file: str, loc: tuple) -> Span:
    """Where a validation error's location (pydantic's loc) is in the library's YAML: the value
    when it is a scalar, else its key; the deepest part of loc the file has."""
    import yaml

    try:
        node = yaml.compose(text, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
    except yaml.YAMLError:
        node = None
    if node is None:
        return Span.point(file)
    key = None
    for part in loc:
        if part == "[key]" and key is not None:
            return _node_span(file, key)
        if isinstance(node, yaml.MappingNode):
            hit = next(((k, v) for k, v in node.value if k.value == str(part)), None)
        elif isinstance(node, yaml.SequenceNode) and isinstance(part, int) and 0 <= part < len(node.value):
            hit = (key, node.value[part])
        else:
            hit = None
        if hit is None:
            break
        key, node = hit
    return _node_span(file, node if isinstance(node, yaml.ScalarNode) or key is None else key)


MAX_LIBRARY_BYTES = 1_000_000  # the shipped libraries are 4 kB; a 6 MB one took 30 s and 550 MB
# What makes a YAML mapping a module library (see the module's docstring).
LIBRARY_KEYS = ("variants", "units")


def _not_a_library(data) -> str | None:
    """Why parsed YAML is not a module library (in words that quote none of it), else None."""
    if not isinstance(data, dict):
        kind = ("empty" if data is None else "a YAML list" if isinstance(data, list)
                else "plain text or a single value")
        return f"it is {kind}, not a YAML mapping"
    missing = [k for k in LIBRARY_KEYS if k not in data]
    return f"it has no `{missing[0]}` key" if missing else None


def _not(why: str) -> LibraryError:
    return LibraryError(f"not a module library: {why}")


def read_library(path: str):
    """(text, data) of a file that parses as a module library; LibraryError without any of its
    content otherwise."""
    import yaml

    from ..files import read_bounded

    try:
        raw, size = read_bounded(path, MAX_LIBRARY_BYTES)
    except OSError as e:
        raise LibraryError(f"it cannot be read: {e.strerror or type(e).__name__}") from None
    if size > MAX_LIBRARY_BYTES:
        raise LibraryError(f"the file is too large ({size:,} bytes; the limit is {MAX_LIBRARY_BYTES:,})")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as e:
        raise _not(f"it is not UTF-8 text (at byte {e.start + 1})") from None
    try:
        data = yaml.load(text, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
    except RecursionError:
        raise _not("its YAML is nested too deeply") from None
    except yaml.YAMLError as e:
        mark = getattr(e, "problem_mark", None) or getattr(e, "context_mark", None)
        where = f" (line {mark.line + 1}, column {mark.column + 1})" if mark else ""
        raise _not(f"it is not YAML{where}") from None
    why = _not_a_library(data)
    if why:
        raise _not(why)
    return text, data
