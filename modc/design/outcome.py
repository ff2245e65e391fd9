"""What a search returns (Outcome) and what its progress display shows (Status)."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from ..model import ResolvedProblem
from .diagnose import why_none
from .rank import Design


@dataclass
class Status:
    """What the progress display shows."""

    shapes_done: int
    shapes_total: int
    screened: int  # settings screened or excluded so far
    feasible: int  # chains the screens passed
    best: str
    eta: float | None  # seconds, None while unknown (or when stopped)
    doing: str = ""  # after the search: the design being planned and timed


@dataclass
class Outcome:
    problem: ResolvedProblem
    designs: list[Design]
    evaluated: int = 0
    seconds: float = 0.0
    shapes: int = 0
    closest: dict[str, float] = field(default_factory=dict)  # per target, m (0: reached by some design)
    screened: int = 0  # chains that passed the screen
    rejections: list[str] = field(default_factory=list)  # why exact checks failed, in order
    excluded: int = 0  # settings ruled out by a sound bound
    dominated: int = 0  # of those, settings a dominance bound ruled out of the ranking (search.ShapeResult)
    complete: bool = True  # every setting of every shape in the bounds screened or excluded
    stopped: str | None = None  # "time budget" or "interrupted"
    unfinished: list[str] = field(default_factory=list)  # shapes whose search did not run to the end
    failed_on: dict[str, int] = field(default_factory=dict)  # per task or path: chains not plannable on it
    not_planned: list[str] = field(default_factory=list)  # designs found, not planned: the search stopped first
    searched: bool = True  # False: a design block not searched, an earlier block used up the budget
    coarse: list[str] = field(default_factory=list)  # shapes searched on a coarse grid
    targets: dict[str, dict] = field(default_factory=dict)  # per target: hit, clear, closest, excluded_by
    reference: Any = None  # modc.design.reference.Reference: the block's `compare with` arm, evaluated
    bases_searched: int | None = None  # `base within`: base poses searched (None: the base as written)
    bases_pruned: int = 0  # base poses ruled out by the reach bound
    bases_total: int = 0  # base poses of the grid
    bases_touching: int = 0  # base poses where base_link sinks into the cell
    bases_kept: list | None = None  # the base poses searched, nearest first (None: the base as written)
    # `rank coverage`: regions no point of which any arm in the bounds reaches -> m beyond the longest reach
    regions_beyond: dict[str, float] = field(default_factory=dict)

    def why_none(self) -> str:
        return why_none(self)


__all__ = ["Outcome", "Status"]
