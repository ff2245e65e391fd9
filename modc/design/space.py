"""The design space of a problem, and its exact reductions.

Paper rules (section 3): a chain is H^k L^(n-k) - the first unit H, the last L, L never followed by
H - with k <= eps(H) and n - k <= eps(L); each position is one of the unit types 1-4.

Reductions that lose nothing:
- H and L units of one type share their geometry (docs/conventions.md: x01, z01, z12, x23 belong to the
  type), so kinematics - reach, IK, the obstacle screen - depend on the types only. The search
  runs once per *shape* (types and link lengths) and the variant splits H^k L^(n-k) are only
  re-weighed (mass, torque) afterwards.
- The last unit's port twist rotates the tool about the link's x axis: with a tool offset on that
  axis (or none) and no target orientation it cannot move tool0, so it stays 0.
- Units 1 and 2 have no port twist and no link length.
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

from ..model import ResolvedProblem


@dataclass(frozen=True)
class Shape:
    """Unit types per position and their link lengths (m; None: the library's default)."""

    kinds: tuple[int, ...]
    links: tuple[float | None, ...]

    @property
    def n(self) -> int:
        return len(self.kinds)

    def label(self) -> str:
        return "-".join(str(k) for k in self.kinds) + "".join(f"@{x * 1000:g}" for x in self.links if x is not None)


def twist_values(ts) -> np.ndarray:
    """Every realisable value of a TwistSet, rad, ascending (a wrapping set without the duplicate end)."""
    count = int(math.floor((ts.max_deg - ts.min_deg) / ts.step_deg + 1e-9)) + 1
    deg = [ts.min_deg + k * ts.step_deg for k in range(count)]
    if ts.wraps:
        wrapped = {((d + 180.0) % 360.0) - 180.0 if d != 180.0 else 180.0 for d in deg}
        deg = sorted(wrapped - ({-180.0} if 180.0 in wrapped else set()))
    return np.radians(np.array(deg, float))


def variant_splits(problem: ResolvedProblem, n: int) -> list[tuple[str, ...]]:
    """Variant sequences the rules allow for n units: first variant, then the may-follow order, eps each."""
    lib = problem.cell.library
    rules = lib.rules
    out = []
    for seq in itertools.product(sorted(lib.variants), repeat=n):
        if seq[0] != rules.first_variant or seq[-1] != rules.last_variant:
            continue
        if any(b not in rules.may_follow.get(a, []) for a, b in zip(seq, seq[1:], strict=False)):
            continue
        if any(seq.count(v) > lib.variants[v].actuator.epsilon for v in lib.variants):
            continue
        out.append(seq)
    return out


def allowed(problem: ResolvedProblem, variant: str, kind: int) -> bool:
    return problem.modules is None or f"{variant}{kind}" in problem.modules


def shapes(problem: ResolvedProblem, n: int) -> list[Shape]:
    """Every shape of n units some allowed variant split can build, link lengths expanded."""
    lib = problem.cell.library
    splits = variant_splits(problem, n)
    kinds_all = sorted(lib.units)
    out = []
    for kinds in itertools.product(kinds_all, repeat=n):
        if not any(all(allowed(problem, v, k) for v, k in zip(split, kinds, strict=True)) for split in splits):
            continue
        choices = [(None,) if not lib.units[k].link or problem.links is None else problem.links for k in kinds]
        for links in itertools.product(*choices):
            out.append(Shape(kinds, tuple(links)))
    return out


def port_free(problem: ResolvedProblem, shape: Shape, lib) -> list[bool]:
    """Per position: does its port twist matter (a link unit, and not the last one's irrelevant twist)?"""
    tool = problem.cell.tool
    tool_on_axis = tool.xyz[1] == 0.0 and tool.xyz[2] == 0.0
    oriented = any(t.rpy is not None for t in problem.cell.targets)
    out = []
    for i, k in enumerate(shape.kinds):
        last = i == shape.n - 1
        out.append(lib.units[k].link and not (last and tool_on_axis and not oriented))
    return out
