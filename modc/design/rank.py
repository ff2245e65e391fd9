"""Ranking designs: by the problem's objectives in order (default fewest modules, least mass,
largest torque margin), then by the chain text, so that the order is total and reproducible.

OBJECTIVES is the one registry of what `rank` may name in a design block: a new objective is an
entry here (a function of a design to a value, smaller ranks first) and its keyword in
modc.model.robot (RANK_KEYS / TASK_RANK_KEYS). Task objectives (TASK) are known only once the
design's tasks are planned and timed (modc.design.tasks)."""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

from .evaluate import Candidate, Verified


@dataclass(frozen=True)
class Design:
    candidate: Candidate
    verified: Verified
    alternatives: tuple[Design, ...] = ()  # the same arm with other H/L variants, best first
    plans: tuple[Any, ...] = ()  # modc.plan.task.TaskPlan per task and path of the cell, once planned
    coverage: float = 1.0  # share of the cell's region points reached (modc.design.coverage)

    @property
    def cycle_time(self) -> float:
        """s, summed over the cell's tasks and paths (0 before they are planned)."""
        return sum(p.cycle_time for p in self.plans)

    @property
    def energy(self) -> float:
        """J, summed over the cell's tasks and paths."""
        return sum(p.energy for p in self.plans)

    @property
    def modules(self) -> int:
        return len(self.candidate.variants)

    @property
    def mass(self) -> float:
        return self.verified.mass

    @property
    def margin(self) -> float:
        return self.verified.margin

    def chain(self) -> str:
        from ..model.write import unit_text

        r = self.verified.robot
        return " - ".join(unit_text(r, i) for i in range(r.dof))


@dataclass(frozen=True)
class Screened:
    """What the static search knows of a chain before its exact check: a margin of None ranks
    level with every other (it is computed by the check)."""

    modules: int
    mass: float
    margin: float | None
    text: str

    def chain(self) -> str:
        return self.text


OBJECTIVES: dict[str, Callable[[Any], float]] = {
    "modules": lambda d: d.modules,
    "mass": lambda d: round(d.mass, 9),
    "margin": lambda d: 0.0 if d.margin is None else -round(d.margin, 9),
    "cycle_time": lambda d: round(d.cycle_time, 9),
    "energy": lambda d: round(d.energy, 9),
    "coverage": lambda d: -round(getattr(d, "coverage", 1.0), 9),  # larger first; the static search: all
}
TASK = frozenset({"cycle_time", "energy", "coverage"})  # known only once the design's tasks are planned


def key(objectives: tuple[str, ...], d: Design | Screened) -> tuple:
    return tuple(OBJECTIVES[o](d) for o in objectives) + (d.chain(),)


def static(objectives: tuple[str, ...]) -> tuple[str, ...]:
    """The objectives the static search can rank by (the task objectives left out)."""
    return tuple(o for o in objectives if o not in TASK)


def order(designs: list[Design], objectives: tuple[str, ...]) -> list[Design]:
    return sorted(designs, key=lambda d: key(objectives, d))


def identity(d: Design) -> tuple:
    """The arm's kinematics: its shape and twists (H and L units of one type share their geometry)."""
    c = d.candidate
    return (c.shape.kinds, c.shape.links, tuple(round(x, 9) for x in c.pivots), tuple(round(x, 9) for x in c.ports))


def distinct(designs: list[Design], objectives: tuple[str, ...]) -> list[Design]:
    """Ranked designs, one entry per kinematic arm: its variant swaps become its alternatives."""
    groups: dict[tuple, list[Design]] = {}
    for d in order(designs, objectives):
        groups.setdefault(identity(d), []).append(d)
    return [replace(g[0], alternatives=tuple(g[1:])) for g in groups.values()]


def pareto(points: list[tuple[float, float]]) -> list[bool]:
    """Non-dominated points when both coordinates are minimised."""
    out = []
    for i, (a, b) in enumerate(points):
        out.append(not any((c <= a and d <= b) and (c < a or d < b) for j, (c, d) in enumerate(points) if j != i))
    return out
