"""The one Diagnostic type: fed to the terminal, `lint --format json`, reports and the LSP."""
from __future__ import annotations

from dataclasses import asdict, dataclass

from .codes import Severity
from .span import Span


@dataclass(frozen=True)
class Diagnostic:
    code: str
    severity: Severity
    span: Span
    message: str
    hint: str = ""

    @property
    def is_error(self) -> bool:
        return self.severity is Severity.ERROR

    def to_json(self) -> dict:
        s = asdict(self.span)
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
