"""The one Diagnostic type: fed to the terminal, `lint --format json`, reports and the LSP."""
from __future__ import annotations

from ..records import Record, as_fields
from .codes import Severity
from .span import Span


class Diagnostic(Record, kw_only=False):
    code: str
    severity: Severity
    span: Span
    message: str
    hint: str = ""

    @property
    def is_error(self) -> bool:
        return self.severity is Severity.ERROR

    def to_json(self) -> dict:
        s = as_fields(self.span)
        return {
            "code": self.code,
            "severity": self.severity.value,
            "file": s.pop("file"),
            **s,
            "message": self.message,
            "hint": self.hint,
        }


def sort_key(d: Diagnostic):
    return (d.span.file, d.span.line, d.span.col, d.code, d.message)
