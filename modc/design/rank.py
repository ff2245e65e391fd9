"""Ranking designs: by the problem's objectives in order (default fewest modules, least mass,
largest torque margin), then by the chain text, so that the order is total and reproducible.

What `rank` may name is modc.objectives' registry (one module per objective), read here at each
call (REGISTRY[name].key: smaller ranks first). Task objectives (TASK) are known only once the
design's tasks are planned and timed (modc.design.tasks)."""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

from ..objectives import REGISTRY, TASK
from .evaluate import Candidate, Verified


class Planned:
    """The task figures of an arm whose cell's tasks and paths are planned (`plans`: a
    modc.plan.task.TaskPlan each): a design, or the block's reference arm."""

    plans: tuple[Any, ...]

    @property
    def cycle_time(self) -> float:
        """s, summed over the cell's tasks and paths (0 before they are planned)."""
        return sum(p.cycle_time for p in self.plans)

    @property
    def energy(self) -> float:
        """J, summed over the cell's tasks and paths."""
        return sum(p.energy for p in self.plans)


@dataclass(frozen=True)
class Design(Planned):
    candidate: Candidate
    verified: Verified
    alternatives: tuple[Design, ...] = ()  # the same arm with other H/L variants, best first
    plans: tuple[Any, ...] = ()  # modc.plan.task.TaskPlan per task and path of the cell, once planned
    coverage: float = 1.0  # share of the cell's region points reached (modc.design.coverage)

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




def key(objectives: tuple[str, ...], d: Design | Screened) -> tuple:
    return tuple(REGISTRY[o].key(d) for o in objectives) + (d.chain(),)


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


def shown(objective: str, d: Any) -> tuple[str, float, str]:
    """(words, value, unit) of one objective of a design, as report.html and the why sentences show it."""
    o = REGISTRY[objective]
    return o.words, o.shown(d), o.unit


def _pair(a: float, b: float, unit: str) -> tuple[str, str]:
    """Two different values written with just enough decimals to differ (99.4 % vs 99.1 %, not 99 % vs 99 %)."""
    digits = 0 if unit in ("", " %") else 3
    for k in range(digits, digits + 7):
        x, y = f"{a:.{k}f}", f"{b:.{k}f}"
        if x != y:
            break
    return x + unit, y + unit


def versus(objectives: tuple[str, ...], d: Any, other: Any) -> tuple[list[str], str | None, tuple[str, str]]:
    """The objectives d ties `other` on, in ranking order, the first one that tells them apart
    (None: every one ties) and the two values of that one as shown."""
    ties: list[str] = []
    for o in objectives:
        if REGISTRY[o].key(d) != REGISTRY[o].key(other):
            _, a, unit = shown(o, d)
            _, b, _ = shown(o, other)
            return ties, o, _pair(a, b, unit)
        ties.append(shown(o, d)[0])
    return ties, None, ("", "")


def _and(words: list[str]) -> str:
    return words[0] if len(words) == 1 else ", ".join(words[:-1]) + " and " + words[-1]


def why(designs: list, objectives: tuple[str, ...]) -> list[str]:
    """Per rank, in words, what decided it against the next rank (the last: against the one
    before), by the same keys `order` sorts on: "ties rank 2 on modules and mass; ahead by
    torque margin 99 % vs 97 %"."""
    out = []
    for i, d in enumerate(designs):
        if len(designs) == 1:
            out.append("the only design found")
            continue
        last = i == len(designs) - 1
        j = i - 1 if last else i + 1
        ties, decided, (a, b) = versus(objectives, d, designs[j])
        said = f"ties rank {j + 1} on {_and(ties)}" if ties else ""
        if decided is None:
            said = f"ties rank {j + 1} on every objective"
            step = f"{'after' if last else 'before'} it by the chain's name ({d.chain()})"
        else:
            side = "behind" if last else "ahead"
            step = (f"{side} by {shown(decided, d)[0]} {a} vs {b}" if ties
                    else f"{'behind' if last else 'ahead of'} rank {j + 1} by {shown(decided, d)[0]} {a} vs {b}")
        out.append(f"{said}; {step}" if said else step)
    return out


def target_share(got: dict, target) -> float:
    """A target's error as a share of its tolerance (0: dead on, 1: at the edge): position against
    the position tolerance, orientation (when it has one) against the orientation tolerance."""
    import math

    share = got["position_error_m"] / max(target.position_tolerance, 1e-12)
    if got.get("orientation_error_deg") is not None:
        share = max(share, math.radians(got["orientation_error_deg"]) / max(target.orientation_tolerance, 1e-12))
    return share


def worst_share(targets: dict[str, dict], cell) -> float:
    """A design's worst target error as a share of its tolerance: targets and region points
    (`tray[1,0,0]`, the region's tolerance) of the cell (a Robot)."""
    shares = [target_share(got, t) for name, got in targets.items() if (t := cell.task_target(name)) is not None]
    return max(shares, default=0.0)
