"""What `modc plan` reports when it cannot plan: PlanError, one or more diagnostics of the
registry (modc.diagnostics.codes: target-unknown, pose-unknown, robot-unknown, start-in-collision,
target-unreachable, target-in-collision, no-path) and the exit code."""
from __future__ import annotations

from ..diagnostics import Code, Diagnostic, Span, codes

EXIT_FAILED = 1  # planning failed, or the file has errors
EXIT_USAGE = 2  # unreadable file, unknown target / pose / robot

USAGE_CODES = frozenset({codes.TARGET_UNKNOWN.name, codes.POSE_UNKNOWN.name, codes.ROBOT_UNKNOWN.name})


class PlanError(Exception):
    """Planning did not produce a trajectory. diagnostics: what to print (with sources for the
    caret excerpts); exit_code: 1 planning failure or errors in the file, 2 usage or I/O."""

    def __init__(
        self, diagnostics: list[Diagnostic], sources: dict[str, str] | None = None, exit_code: int = EXIT_FAILED
    ):
        self.diagnostics = list(diagnostics)
        self.sources = dict(sources or {})
        self.exit_code = exit_code
        first = next((d for d in self.diagnostics if d.is_error), self.diagnostics[0] if self.diagnostics else None)
        self.code = first.code if first else "error"
        self.message = first.message if first else "planning failed"
        self.hint = first.hint if first else ""
        super().__init__(self.message)

    @classmethod
    def of(cls, code: Code, span: Span, sources: dict[str, str] | None = None, **fields) -> PlanError:
        return cls([code.at(span, **fields)], sources, EXIT_USAGE if code.name in USAGE_CODES else EXIT_FAILED)


__all__ = ["EXIT_FAILED", "EXIT_USAGE", "PlanError"]
