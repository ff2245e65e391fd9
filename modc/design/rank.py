"""Ranking designs: by the problem's objectives in order (default fewest modules, least mass,
largest torque margin), then by the chain text, so that the order is total and reproducible."""
from __future__ import annotations

from dataclasses import dataclass, replace

from .evaluate import Candidate, Verified


@dataclass(frozen=True)
class Design:
    candidate: Candidate
    verified: Verified
    alternatives: tuple[Design, ...] = ()  # the same arm with other H/L variants, best first

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


def key(objectives: tuple[str, ...], modules: int, mass: float, margin: float | None, chain: str) -> tuple:
    values = {"modules": modules, "mass": round(mass, 9), "margin": 0.0 if margin is None else -round(margin, 9)}
    return tuple(values[o] for o in objectives) + (chain,)


def order(designs: list[Design], objectives: tuple[str, ...]) -> list[Design]:
    return sorted(designs, key=lambda d: key(objectives, d.modules, d.mass, d.margin, d.chain()))


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
