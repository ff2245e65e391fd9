"""The search, end to end: shapes by number of units, the twist search per shape (on any
concurrent.futures executor), variant splits re-weighed, exact checks in ranking order.

Work goes to the executor in chunks of shapes (each a second or so of numpy); results come back
in submission order and every chunk is a pure function of its inputs, so the ranking is the
same for one process, a local pool or a Dask cluster.
"""
from __future__ import annotations

import math
import time
from collections.abc import Callable
from concurrent.futures import Executor
from dataclasses import dataclass, field

import numpy as np

from ..model import Problem
from . import space
from .evaluate import Candidate, Spec, verify
from .rank import Design, key, order
from .screen import reach_bound, static_torques
from .search import ShapeResult, search_chunk

CHUNK = 1  # shapes per unit of work (a shape's search is 0.1-2 s of numpy)
ROUND = 8  # shapes searched between two rounds of exact checks
TRIES = 3  # twist settings verified per chain before giving up on it
VERIFY_FACTOR = 4  # at most this many exact checks per design asked for, per number of units


@dataclass
class Outcome:
    problem: Problem
    designs: list[Design]
    evaluated: int = 0
    seconds: float = 0.0
    shapes: int = 0
    closest: dict[str, float] = field(default_factory=dict)  # per target, m (0: reached by some design)
    screened: int = 0  # chains that passed the screen
    rejections: list[str] = field(default_factory=list)  # why exact checks failed, in order

    def why_none(self) -> str:
        far = {t: d for t, d in self.closest.items() if d > 0}
        if far:
            name = max(far, key=lambda t: far[t])
            if not math.isfinite(far[name]):  # closest starts at inf: never print it
                return f"target '{name}': no design was measured against it"
            return f"target '{name}': no design gets closer than {_length(far[name])}"
        if self.rejections:
            return (f"{len(self.rejections)} chains reach every target, but none passes the checks "
                    f"(first: {self.rejections[0]})")
        return "every target can be reached alone, but no chain reaches all of them without touching the cell"


def _length(x: float) -> str:
    from ..model.quantities import distance

    return distance(x)


def _mass(problem: Problem, shape: space.Shape, variants: tuple[str, ...]) -> float:
    from ..physical.parts import unit_mass

    lib = problem.cell.library
    assert lib is not None
    total = 0.0
    for v, k, x in zip(variants, shape.kinds, shape.links, strict=True):
        total += unit_mass(lib, v, k, (x if x is not None else lib.units[k].x23) if lib.units[k].link else 0.0)
    return total


def _chunks(items: list, size: int) -> list[list]:
    return [items[i:i + size] for i in range(0, len(items), size)]


def _map(executor: Executor | None, spec: Spec, chunks: list, seed: int):
    if executor is None:
        return (search_chunk(spec, c, seed) for c in chunks)
    return executor.map(search_chunk, [spec] * len(chunks), chunks, [seed] * len(chunks))


def _min_mass(problem: Problem, shape: space.Shape, splits) -> float:
    masses = [_mass(problem, shape, v) for v in splits
              if all(space.allowed(problem, x, k) for x, k in zip(v, shape.kinds, strict=True))]
    return min(masses, default=float("inf"))


def design(problem: Problem, *, max_units: int | None = None, top: int = 5, seed: int = 0,
           executor: Executor | None = None, progress: Callable[[int, int, str], None] | None = None) -> Outcome:
    """Ranked designs for a checked problem (its library resolved).

    With the default objectives (fewest modules first), chains are searched by number of units,
    and within one number lightest shape first, ROUND shapes at a time: the search stops as soon
    as `top` designs are checked that no unsearched shape could beat. ROUND does not depend on
    the number of workers, so neither does where the search stops."""
    t0 = time.perf_counter()
    spec = Spec.of(problem)
    lib = problem.cell.library
    assert lib is not None
    out = Outcome(problem, [])
    hi = min(max_units or problem.max_units, lib.rules.max_dof)
    names = [t.name for t in problem.cell.targets]
    closest = {t: np.inf for t in names}
    far = max((float(np.linalg.norm(t.xyz)) - t.position_tolerance for t in problem.cell.targets), default=0.0)
    early = problem.rank[:2] == ("modules", "mass")
    tiers = []
    for n in range(max(problem.min_units, lib.rules.min_dof), hi + 1):
        splits = space.variant_splits(problem, n)
        if not splits:
            continue
        shapes = []
        for s in space.shapes(problem, n):
            lengths = [x or lib.units[k].x23 for k, x in zip(s.kinds, s.links, strict=True)]
            r = reach_bound([lib.units[k] for k in s.kinds], lengths, problem.cell.tool.xyz)
            if r < far:  # a target beyond any pose of this shape: no IK needed
                for t in problem.cell.targets:
                    closest[t.name] = min(closest[t.name], max(float(np.linalg.norm(t.xyz)) - r, 0.0))
                continue
            shapes.append((_min_mass(problem, s, splits), s.label(), s))
        shapes.sort(key=lambda e: e[:2])
        tiers.append((n, splits, shapes))
    tally = _Verifier(problem, top, out)
    best = ""
    for n, splits, shapes in tiers:
        rounds = _chunks(shapes, ROUND) if early else [shapes]
        for k, batch in enumerate(rounds):
            out.shapes += len(batch)
            for chunk in _map(executor, spec, _chunks([s for _, _, s in batch], CHUNK), seed):
                for res in chunk:
                    out.evaluated += res.evaluated
                    for name, c in zip(names, res.closest, strict=True):
                        closest[name] = min(closest[name], c)
                    if res.found and not best:
                        best = f"shape {res.shape.label()} (unchecked)"
                    tally.add(n, splits, res)
                if progress is not None:
                    progress(out.evaluated, out.shapes, best)
            # designs no unsearched shape of this size can undercut are final
            nxt = rounds[k + 1][0][0] if k + 1 < len(rounds) else float("inf")
            tally.settle(n, nxt)
            if tally.accepted:
                best = order(tally.accepted, problem.rank)[0].chain()
                if progress is not None:
                    progress(out.evaluated, out.shapes, best)
            if early and tally.done(n, nxt):
                break
        if not early:
            continue
        tally.settle(n, float("inf"))
        if len(tally.accepted) >= top:
            break
    tally.settle(hi, float("inf"))
    out.closest = {t: (0.0 if c <= tp else float(c)) for (t, c), tp in
                   zip(closest.items(), (t.position_tolerance for t in problem.cell.targets), strict=True)}
    out.designs = order(tally.accepted, problem.rank)[:top]
    out.seconds = time.perf_counter() - t0
    return out


class _Verifier:
    """Exact checks in ranking order of what the screen passed: a chain is checked once every
    chain that could rank before it has been found (settle), until `top` pass."""

    def __init__(self, problem: Problem, top: int, out: Outcome):
        self.problem, self.top, self.out = problem, top, out
        self.pending: list[tuple] = []
        self.accepted: list[Design] = []
        self.keys: list[tuple] = []
        self.checks = 0

    def add(self, n: int, splits, res: ShapeResult) -> None:
        if not res.found:
            return
        p = self.problem
        for variants in splits:
            if not all(space.allowed(p, v, k) for v, k in zip(variants, res.shape.kinds, strict=True)):
                continue
            found = tuple(f for f in res.found if self._holds(res, variants, f))
            if not found:
                continue
            mass = _mass(p, res.shape, variants)
            chain = "-".join(f"{v}{k}" for v, k in zip(variants, res.shape.kinds, strict=True)) + res.shape.label()
            kept = ShapeResult(res.shape, found, res.evaluated, res.closest, res.best_score)
            self.pending.append((key(p.rank, n, mass, None, chain), n, mass, kept, variants))
            self.out.screened += 1

    def _holds(self, res: ShapeResult, variants, f) -> bool:
        """The static torque screen: gravity torques at the poses found for the targets (inside the
        limits, so no more than the worst case) within every actuator's peak."""
        from .evaluate import robot_for

        lib = self.problem.cell.library
        assert lib is not None
        cand = Candidate(res.shape, variants, f.pivots, f.ports, f.solutions)
        robot = robot_for(self.problem, cand, {}, self.problem.name)
        tau = static_torques(robot, [sols[0] for sols in f.solutions])
        peak = np.array([lib.variants[v].actuator.torque_peak for v in variants])
        if np.all(tau <= peak):
            return True
        self.out.rejections.append(f"{'-'.join(u.name for u in cand.units())}: over peak torque at a target pose")
        return False

    def done(self, n: int, next_mass: float) -> bool:
        """top designs found that rank before anything of n units not yet searched."""
        ahead = [k for k in self.keys if k[0] < n or (k[0] == n and k[1] < next_mass)]
        return len(ahead) >= self.top

    def settle(self, n: int, below: float) -> None:
        """Check the pending chains of up to n units lighter than `below`, best first."""
        ready = sorted((e for e in self.pending if e[1] < n or (e[1] == n and e[2] < below)), key=lambda e: e[0])
        self.pending = [e for e in self.pending if not (e[1] < n or (e[1] == n and e[2] < below))]
        for k, _n, _mass, res, variants in ready:
            better = sorted(self.keys)[: self.top]
            if len(better) >= self.top and k[:2] > better[-1][:2]:
                break  # ranks behind top designs already checked (equal keys still compete on margin)
            if self.checks >= VERIFY_FACTOR * self.top * 4:
                break
            for f in res.found[:TRIES]:
                cand = Candidate(res.shape, variants, f.pivots, f.ports, f.solutions)
                self.checks += 1
                v = verify(self.problem, cand)
                if isinstance(v, str):
                    self.out.rejections.append(f"{'-'.join(u.name for u in cand.units())}: {v}")
                    continue
                self.accepted.append(Design(cand, v))
                self.keys.append(k)
                break
