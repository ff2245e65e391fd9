"""What every pass receives besides the model: where to report, and run-wide options."""
from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from ..diagnostics import REGISTRY, Diagnostic
from ..model import Robot
from ..records import Record, field


class Context(Record, kw_only=False, frozen=False):
    diagnostics: list[Diagnostic] = field(default_factory=list)
    library_override: str | None = None  # `--library` on the command line
    # Analyses that need the dynamics model run in compile and check, not in lint (kept fast).
    analyses: frozenset[str] = frozenset()
    torque_severity: str = "error"  # error | warning | off: how an over-peak joint is reported
    payload_override: float | None = None  # `check --payload MASS`, kg at tool0
    # The worst-case torque search (modc.dynamics.torque.analyse), handed in by the compiler when
    # analyses has "torque": a pass never imports the physics (pyproject's import contracts).
    torque_analysis: Callable[[Robot, float | None], Sequence[Any]] | None = None
    sources: dict[str, str] = field(default_factory=dict)  # other files diagnostics point into (libraries)

    def report(self, d: Diagnostic, robot: Robot | None = None) -> None:
        # `allow CODE` in a robot block silences that robot's allowable rule diagnostics.
        if robot is not None and d.code in robot.allow and REGISTRY[d.code].allowable:
            return
        self.diagnostics.append(d)

    @property
    def has_errors(self) -> bool:
        return any(d.is_error for d in self.diagnostics)
