"""The search, end to end: shapes by number of units, the twist search per shape (on any
concurrent.futures executor), variant splits re-weighed, exact checks in ranking order.

Work goes to the executor in chunks of shapes (each a second or so of numpy); results come back
in submission order and every chunk is a pure function of its inputs, so the ranking is the
same for one process, a local pool or a Dask cluster.
"""
from __future__ import annotations

import time
from collections.abc import Callable
from concurrent.futures import Executor
from dataclasses import dataclass, field

import numpy as np

from ..model import Problem
from . import space
from .evaluate import Candidate, Spec, verify
from .rank import Design, key, order
from .screen import reach_bound
from .search import ShapeResult, search_chunk

CHUNK = 2  # shapes per unit of work
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
            return f"target '{name}': no design gets closer than {_length(far[name])}"
        if self.screened and self.rejections:
            return f"{self.screened} chains reach every target, but none passes the exact checks (first: {self.rejections[0]})"
        return "every target can be reached, but no chain reaches all of them without touching the cell"


def _length(x: float) -> str:
    return f"{x:.3g} m" if x >= 0.1 else f"{x * 1000:.3g} mm"


def _mass(problem: Problem, shape: space.Shape, variants: tuple[str, ...]) -> float:
    from ..physical.parts import unit_mass

    lib = problem.cell.library
    return sum(unit_mass(lib, v, k, (x if x is not None else lib.units[k].x23) if lib.units[k].link else 0.0)
               for v, k, x in zip(variants, shape.kinds, shape.links))


def _chunks(items: list, size: int) -> list[list]:
    return [items[i:i + size] for i in range(0, len(items), size)]


def _map(executor: Executor | None, spec: Spec, chunks: list, seed: int):
    if executor is None:
        return (search_chunk(spec, c, seed) for c in chunks)
    return executor.map(search_chunk, [spec] * len(chunks), chunks, [seed] * len(chunks))


def design(problem: Problem, *, max_units: int | None = None, top: int = 5, seed: int = 0,
           executor: Executor | None = None, progress: Callable[[int, int, str], None] | None = None) -> Outcome:
    """Ranked designs for a checked problem (its library resolved)."""
    t0 = time.perf_counter()
    spec = Spec.of(problem)
    lib = problem.cell.library
    assert lib is not None
    out = Outcome(problem, [])
    hi = min(max_units or problem.max_units, lib.rules.max_dof)
    names = [t.name for t in problem.cell.targets]
    closest = {t: np.inf for t in names}
    far = max((float(np.linalg.norm(t.xyz)) - t.position_tolerance for t in problem.cell.targets), default=0.0)
    accepted: list[Design] = []
    best = ""
    for n in range(max(problem.min_units, lib.rules.min_dof), hi + 1):
        splits = space.variant_splits(problem, n)
        if not splits:
            continue
        shapes = []
        for s in space.shapes(problem, n):
            r = reach_bound([lib.units[k] for k in s.kinds], [x or lib.units[k].x23 for k, x in zip(s.kinds, s.links)],
                            problem.cell.tool.xyz)
            if r < far:  # a target beyond any pose of this shape: no IK needed
                for t in problem.cell.targets:
                    gap = float(np.linalg.norm(t.xyz)) - r
                    closest[t.name] = min(closest[t.name], max(gap, 0.0))
                continue
            shapes.append(s)
        out.shapes += len(shapes)
        results: list[ShapeResult] = []
        for chunk in _map(executor, spec, _chunks(shapes, CHUNK), seed):
            for res in chunk:
                results.append(res)
                out.evaluated += res.evaluated
                for t, c in zip(names, res.closest):
                    closest[t] = min(closest[t], c)
                if res.found and not best:
                    best = res.shape.label()
            if progress is not None:
                progress(out.evaluated, len(results), best)
        accepted += _verify_tier(problem, n, splits, results, top, out)
        if problem.rank[0] == "modules" and len(accepted) >= top:
            break
    out.closest = {t: (0.0 if c <= tp else float(c)) for (t, c), tp in
                   zip(closest.items(), (t.position_tolerance for t in problem.cell.targets))}
    out.designs = order(accepted, problem.rank)[:top]
    out.seconds = time.perf_counter() - t0
    return out


def _verify_tier(problem: Problem, n: int, splits, results: list[ShapeResult], top: int, out: Outcome) -> list[Design]:
    """Exact checks of one tier's screened chains, cheapest first by the objectives known before
    checking (modules, mass), until `top` pass and the next chain would rank behind them."""
    queue = []
    for res in results:
        if not res.found:
            continue
        for variants in splits:
            if not all(space.allowed(problem, v, k) for v, k in zip(variants, res.shape.kinds)):
                continue
            mass = _mass(problem, res.shape, variants)
            chain = "-".join(f"{v}{k}" for v, k in zip(variants, res.shape.kinds)) + res.shape.label()
            queue.append((key(problem.rank, n, mass, None, chain), res, variants))
    queue.sort(key=lambda e: e[0])
    out.screened += len(queue)
    accepted: list[Design] = []
    checks = 0
    last_key = None
    for k, res, variants in queue:
        if len(accepted) >= top and k[:2] != last_key:
            break
        if checks >= VERIFY_FACTOR * top + TRIES:
            break
        for f in res.found[:TRIES]:
            cand = Candidate(res.shape, variants, f.pivots, f.ports, f.solutions)
            checks += 1
            v = verify(problem, cand)
            if isinstance(v, str):
                out.rejections.append(f"{'-'.join(u.name for u in cand.units())}: {v}")
                continue
            accepted.append(Design(cand, v))
            last_key = k[:2]
            break
    return accepted
