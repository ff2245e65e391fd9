"""What every pass receives besides the model: where to report, and run-wide options."""
from __future__ import annotations

from dataclasses import dataclass, field

from ..diagnostics import REGISTRY, Diagnostic
from ..model import Robot


@dataclass
class Context:
    diagnostics: list[Diagnostic] = field(default_factory=list)
    library_override: str | None = None  # `--library` on the command line
    # Analyses that need the dynamics model run in compile and check, not in lint (kept fast).
    analyses: frozenset[str] = frozenset()
    torque_severity: str = "error"  # error | warning | off: how an over-peak joint is reported
    payload_override: float | None = None  # `check --payload MASS`, kg at tool0
    sources: dict[str, str] = field(default_factory=dict)  # other files diagnostics point into (libraries)

    def report(self, d: Diagnostic, robot: Robot | None = None) -> None:
        # `allow CODE` in a robot block silences that robot's allowable rule diagnostics.
        if robot is not None and d.code in robot.allow and REGISTRY[d.code].allowable:
            return
        self.diagnostics.append(d)

    @property
    def has_errors(self) -> bool:
        return any(d.is_error for d in self.diagnostics)
