"""The one place where modc positions and diagnostics become LSP types (and back).

modc counts like Lark: lines split at '\\n' only, 1-based lines and columns in characters (code
points), end exclusive (modc.diagnostics.Span). LSP counts 0-based lines and, by default, UTF-16
code units in a line (or UTF-8 bytes / code points when the client negotiated them). A lone
'\\r' is not a line break here (it is not one for the .mod lexer either).
"""

from __future__ import annotations

import bisect
import re

from lsprotocol import types

from ..diagnostics import Diagnostic, Severity, Span

UTF16, UTF8, UTF32 = "utf-16", "utf-8", "utf-32"

SEVERITY = {
    Severity.ERROR: types.DiagnosticSeverity.Error,
    Severity.WARNING: types.DiagnosticSeverity.Warning,
    Severity.NOTE: types.DiagnosticSeverity.Information,
}
SOURCE = "modc"


def _units(s: str, encoding: str) -> int:
    """Length of s in the client's position units."""
    if s.isascii() or encoding == UTF32:
        return len(s)
    if encoding == UTF8:
        return len(s.encode("utf-8", "surrogatepass"))
    return len(s.encode("utf-16-le", "surrogatepass")) // 2


def _chars(line: str, n: int, encoding: str) -> int:
    """Number of characters of line covered by n client units (clamped to the line)."""
    if n <= 0:
        return 0
    if line.isascii() or encoding == UTF32:
        return min(n, len(line))
    used = 0
    for i, ch in enumerate(line):
        o = ord(ch)
        if encoding == UTF8:
            w = 1 if o < 0x80 else 2 if o < 0x800 else 3 if o < 0x10000 else 4
        else:
            w = 2 if o >= 0x10000 else 1
        if used + w > n:
            return i
        used += w
    return len(line)


class LineIndex:
    """Line starts of one text, for offset <-> (line, column) conversions in both directions."""

    def __init__(self, text: str, encoding: str = UTF16):
        self.text = text
        self.encoding = encoding if encoding in (UTF8, UTF16, UTF32) else UTF16
        # line ends as LSP counts them and modc reads them: LF, CRLF, and a lone CR
        self.starts = [0] + [m.end() for m in re.finditer(r"\r(?!\n)|\n", text)]

    def line_text(self, line: int) -> str:
        """Line (0-based) without its line break ('' beyond the end)."""
        if line < 0 or line >= len(self.starts):
            return ""
        end = self.starts[line + 1] - 1 if line + 1 < len(self.starts) else len(self.text)
        return self.text[self.starts[line] : end]

    # --- offsets (characters) <-> LSP positions ---------------------------------------------
    def position(self, offset: int) -> types.Position:
        offset = max(0, min(offset, len(self.text)))
        line = bisect.bisect_right(self.starts, offset) - 1
        col = offset - self.starts[line]
        return types.Position(
            line=line, character=_units(self.text[self.starts[line] : offset], self.encoding) if col else 0
        )

    def offset(self, pos: types.Position) -> int:
        """Character offset of an LSP position, clamped into the text (a position past the end
        of a line means its end, past the last line the end of the text)."""
        line = pos.line
        if line < 0:
            return 0
        if line >= len(self.starts):
            return len(self.text)
        return self.starts[line] + _chars(self.line_text(line), pos.character, self.encoding)

    def range(self, start: int, end: int) -> types.Range:
        return types.Range(start=self.position(start), end=self.position(max(start, end)))

    def whole(self) -> types.Range:
        return self.range(0, len(self.text))

    # --- modc spans -> LSP ranges ---------------------------------------------------------------
    def _at(self, line: int, col: int) -> types.Position:
        """1-based modc line/column (characters) -> LSP position, clamped into the text."""
        i = line - 1
        if i < 0:
            return types.Position(line=0, character=0)
        if i >= len(self.starts):
            return self.position(len(self.text))
        text = self.line_text(i)
        c = max(0, min(col - 1, len(text)))
        return types.Position(line=i, character=_units(text[:c], self.encoding))

    def char_offset(self, line: int, col: int) -> int:
        """1-based modc line/column -> character offset, clamped into the text."""
        i = line - 1
        if i < 0:
            return 0
        if i >= len(self.starts):
            return len(self.text)
        return self.starts[i] + max(0, min(col - 1, len(self.line_text(i))))

    def span_offsets(self, span: Span) -> tuple[int, int]:
        """A modc Span as character offsets (from its lines and columns, which every span has)."""
        a = self.char_offset(span.line, span.col)
        return a, max(a, self.char_offset(span.end_line, span.end_col))

    def span(self, span: Span) -> types.Range:
        start = self._at(span.line, span.col)
        end = self._at(span.end_line, span.end_col)
        if (end.line, end.character) < (start.line, start.character):
            end = start
        return types.Range(start=start, end=end)


def top() -> types.Range:
    """The empty range at the top of a file."""
    zero = types.Position(line=0, character=0)
    return types.Range(start=zero, end=zero)


def diagnostic(d: Diagnostic, index: LineIndex, path: str) -> types.Diagnostic:
    """A modc Diagnostic as an LSP one: same code, severity and message; the hint follows the
    message on its own line ("hint: …") and is also in data.hint for code actions.
    A diagnostic that points into another file (or nowhere) is shown at the top of this one."""
    rng = index.span(d.span) if d.span.file == path else top()
    message = d.message if not d.hint else f"{d.message}\nhint: {d.hint}"
    if d.span.file != path and d.span.file not in ("<unknown>", ""):
        message = f"{d.span.file}:{d.span.line}:{d.span.col}: {message}"
    return types.Diagnostic(
        range=rng,
        message=message,
        severity=SEVERITY.get(d.severity, types.DiagnosticSeverity.Error),
        code=d.code,
        source=SOURCE,
        data={"code": d.code, "hint": d.hint},
    )


def internal_error(e: Exception) -> types.Diagnostic:
    """What the editor shows when the compiler itself fails on a text (a bug in modc)."""
    return types.Diagnostic(
        range=top(),
        message=f"modc failed while checking this file (internal error: {type(e).__name__}: {e}); please report it",
        severity=types.DiagnosticSeverity.Error,
        source=SOURCE,
    )


def diagnostics(diags: list[Diagnostic], text: str, path: str, encoding: str = UTF16) -> list[types.Diagnostic]:
    index = LineIndex(text, encoding)
    return [diagnostic(d, index, path) for d in diags]


def location(uri: str, rng: types.Range) -> types.Location:
    return types.Location(uri=uri, range=rng)


def uri_to_path(uri: str) -> str:
    """file:///a/b%20c.mod -> /a/b c.mod; any other scheme stays as written (still gives the
    suffix that tells .mod from YAML)."""
    from urllib.parse import unquote, urlparse

    try:
        p = urlparse(uri)
    except ValueError:
        return uri
    if p.scheme != "file":
        return uri
    path = unquote(p.path)
    if re.match(r"^/[A-Za-z]:", path):  # file:///C:/x on Windows
        path = path[1:]
    return path


def path_to_uri(path: str) -> str:
    from pathlib import Path

    return Path(path).resolve().as_uri()
