"""Source positions. Every AST node and model element carries one."""
from __future__ import annotations

from ..records import Record


class Span(Record, kw_only=False):
    """A region of one source file; lines and columns are 1-based, end is exclusive."""

    file: str
    line: int
    col: int
    end_line: int
    end_col: int
    start: int = 0  # character offsets, for the LSP and fmt
    end: int = 0

    @staticmethod
    def point(file: str, line: int = 1, col: int = 1, offset: int = 0) -> Span:
        return Span(file, line, col, line, col + 1, offset, offset + 1)

    def to(self, other: Span) -> Span:
        """The span from the start of self to the end of other."""
        return Span(self.file, self.line, self.col, other.end_line, other.end_col, self.start, other.end)


NOWHERE = Span("<unknown>", 1, 1, 1, 2)
