"""What `modc plan` reports when it cannot plan: one diagnostic (code, span, message, hint).

The codes are meant to live in modc.diagnostics.codes (the one registry); until they are
registered there, the templates below are used as they are. Once registered, the registry's
templates win (same fields).
"""
from __future__ import annotations

from ..diagnostics import Diagnostic, Span
from ..diagnostics.codes import REGISTRY, Severity

EXIT_FAILED = 1  # planning failed, or the file has errors
EXIT_USAGE = 2  # unreadable file, unknown target / pose / robot

# name -> (summary, message template, hint template)
CODES: dict[str, tuple[str, str, str]] = {
    "target-unknown": (
        "`plan --to` naming a target the robot does not declare",
        "robot {robot} has no target '{target}'",
        "{known}"),
    "pose-unknown": (
        "`plan --start` naming a pose the robot does not declare",
        "robot {robot} has no pose '{pose}'",
        "{known}"),
    "robot-unknown": (
        "`--robot` naming no robot of the file, or a target several robots have",
        "{detail}",
        "{known}"),
    "start-in-collision": (
        "the pose a plan starts from is in collision",
        "the start pose '{pose}' collides: {contacts}",
        "{hint}"),
    "target-unreachable": (
        "a target tool0 cannot reach within the joint limits",
        "target '{target}' is out of reach: tool0 gets no closer than {distance} m",
        "{hint}"),
    "target-in-collision": (
        "a target the arm reaches only in collision",
        "target '{target}' is reachable only in collision: {contacts}",
        "{hint}"),
    "no-path": (
        "no collision-free motion to a target was found",
        "no collision-free path from '{pose}' to target '{target}' found ({detail})",
        "{hint}"),
}

EXIT_CODES = {"target-unknown": EXIT_USAGE, "pose-unknown": EXIT_USAGE, "robot-unknown": EXIT_USAGE}


def diagnostic(name: str, span: Span, **fields) -> Diagnostic:
    code = REGISTRY.get(name)
    if code is not None:
        return code.at(span, **fields)
    _summary, message, hint = CODES[name]
    return Diagnostic(code=name, severity=Severity.ERROR, span=span, message=message.format(**fields),
                      hint=hint.format(**fields) if hint else "")


class PlanError(Exception):
    """Planning did not produce a trajectory. diagnostics: what to print (with sources for the
    caret excerpts); exit_code: 1 planning failure or errors in the file, 2 usage or I/O."""

    def __init__(self, diagnostics: list[Diagnostic], sources: dict[str, str] | None = None, exit_code: int = EXIT_FAILED):
        self.diagnostics = list(diagnostics)
        self.sources = dict(sources or {})
        self.exit_code = exit_code
        first = next((d for d in self.diagnostics if d.is_error), self.diagnostics[0] if self.diagnostics else None)
        self.code = first.code if first else "error"
        self.message = first.message if first else "planning failed"
        self.hint = first.hint if first else ""
        super().__init__(self.message)

    @classmethod
    def of(cls, name: str, span: Span, sources: dict[str, str] | None = None, **fields) -> "PlanError":
        return cls([diagnostic(name, span, **fields)], sources, EXIT_CODES.get(name, EXIT_FAILED))


__all__ = ["CODES", "EXIT_FAILED", "EXIT_USAGE", "PlanError", "diagnostic"]
