"""The static search: shapes by number of units, the twist search of each shape in ranges of
its settings (on any concurrent.futures executor), variant splits re-weighed, exact checks in
ranking order, with a time budget, Ctrl-C and progress (run.design drives it, once or per base
grid, and plans what it returns).

Work goes to the executor as ranges of one shape's settings (search.WORK); results are merged
per shape in submission order and every range is a pure function of its inputs, so the ranking
is the same for one process, a local pool or a Dask cluster.
"""
from __future__ import annotations

import time
from collections.abc import Callable, Iterable
from concurrent.futures import Executor

import numpy as np

from ..model import ResolvedProblem
from . import space
from .bounds import blocked as bounds_blocked
from .diagnose import diagnose
from .evaluate import Spec
from .outcome import Outcome, Status
from .rank import distinct
from .screen import reach_bound
from .search import STOP, TICK, Part, ShapeResult, estimate, follow, listed, merge, parts_of, search_chunk
from .verify_order import Verifier

ROUND = 16  # shapes in a tier's first round of search between exact checks; rounds double up to ROUND_MAX
ROUND_MAX = 512  # (sizes independent of the workers: where the search stops does not depend on them)



_UNIT_MASS: dict[tuple, float] = {}  # (library, variant, kind, link) -> kg: thousands of shapes share a few units


def _mass(problem: ResolvedProblem, shape: space.Shape, variants: tuple[str, ...]) -> float:
    from ..physical.parts import unit_mass

    lib = problem.cell.library
    total = 0.0
    for v, k, x in zip(variants, shape.kinds, shape.links, strict=True):
        link = (x if x is not None else lib.units[k].x23) if lib.units[k].link else 0.0
        key_ = (id(lib), v, k, link)
        if key_ not in _UNIT_MASS:
            _UNIT_MASS[key_] = unit_mass(lib, v, k, link)
        total += _UNIT_MASS[key_]
    return total


def _min_mass(problem: ResolvedProblem, shape: space.Shape, splits) -> float:
    masses = [_mass(problem, shape, v) for v in splits
              if all(space.allowed(problem, x, k) for x, k in zip(v, shape.kinds, strict=True))]
    return min(masses, default=float("inf"))


def _rounds(items: list) -> list[list]:
    """ROUND items, then twice as many, … up to ROUND_MAX: few shapes searched past the first
    designs on small cells, and enough units of work in flight to keep many workers busy on a
    large tier (4,096 six-unit shapes: rounds of 512)."""
    out, i, k = [], 0, ROUND
    while i < len(items):
        out.append(items[i:i + k])
        i, k = i + k, min(2 * k, ROUND_MAX)
    return out


def _stopping(deadline: float | None) -> str | None:
    if STOP.is_set():
        return "interrupted"
    if deadline is not None and time.time() > deadline:
        return "time budget"
    return None


def _run_parts(executor: Executor | None, spec: Spec, work: Iterable, seed: int, deadline: float | None,
               each: Callable[[Part], bool], tick: Callable[[], None]) -> None:
    """Every range of work, its Part handed to each() in submission order; stops early (the
    rest unsearched) on Ctrl-C, at the deadline or when each() says so (True)."""
    if executor is None:
        TICK.append(tick)
        try:
            for w in work:
                if _stopping(deadline):
                    return
                for p in search_chunk(spec, [w], seed, deadline):
                    if each(p):
                        return
        finally:
            TICK.remove(tick)
        return
    futures = [executor.submit(search_chunk, spec, [w], seed, deadline) for w in work]
    try:
        for f in futures:
            while True:
                if _stopping(deadline) == "interrupted":
                    return
                try:
                    parts = f.result(timeout=0.2)
                    break
                except TimeoutError:
                    tick()
            for p in parts:
                if each(p):
                    return
    finally:
        for f in futures:
            f.cancel()


def _longest(problem: ResolvedProblem, n: int) -> list[space.Shape]:
    """The shapes of n units with the longest links allowed (the reach bound grows with them)."""
    if not space.variant_splits(problem, n):
        return []
    return space.shapes(problem, n)


def floors(tiers: list) -> dict[int, float]:
    """n -> the least mass of a shape of more than n units in the tiers ((n, splits, [(mass,
    label, shape)]) each; Verifier.frontier's bound on what later tiers hold)."""
    out: dict[int, float] = {}
    least = float("inf")
    for n, _, shapes in reversed(tiers):
        out[n] = least
        least = min([least, *(m for m, _, _ in shapes)])
    return out


def _tiers(problem: ResolvedProblem, spec: Spec, hi: int, closest: dict[str, float]) -> list:
    lib = problem.cell.library
    tiers = []
    for n in range(max(problem.min_units, lib.rules.min_dof), hi + 1):
        splits = space.variant_splits(problem, n)
        if not splits:
            continue
        shapes = []
        for s in space.shapes(problem, n):
            lengths = [x or lib.units[k].x23 for k, x in zip(s.kinds, s.links, strict=True)]
            r = reach_bound([lib.units[k] for k in s.kinds], lengths, problem.cell.tool.xyz)
            gaps = [float(np.linalg.norm(t.xyz)) - r - t.position_tolerance for t in problem.cell.targets]
            for t, g in zip(problem.cell.targets, gaps, strict=True):
                closest[t.name] = min(closest[t.name], max(g + t.position_tolerance, 0.0))
            if max(gaps, default=-1.0) > 0:  # a target beyond any pose of this shape: no IK needed
                continue
            shapes.append((_min_mass(problem, s, splits), s.label(), s))
        shapes.sort(key=lambda e: e[:2])
        tiers.append((n, splits, shapes))
    return tiers


def longest_reach(problem: ResolvedProblem, hi: int) -> float:
    """m: the reach bound of the longest arm of at most hi units in the bounds (0 if none)."""
    lib = problem.cell.library
    return max((reach_bound([lib.units[k] for k in s.kinds], [x or lib.units[k].x23 for k, x in
                            zip(s.kinds, s.links, strict=True)], problem.cell.tool.xyz)
                for n in range(max(problem.min_units, lib.rules.min_dof), hi + 1)
                for s in _longest(problem, n)), default=0.0)


def _search(problem: ResolvedProblem, max_units: int | None, top: int, seed: int, executor: Executor | None,
            progress: Callable[..., None] | None, deadline: float | None, enough: int | None = None,
            diagnosing: bool = True) -> Outcome:
    """The static search: designs ranked by the problem's (static) objectives.

    With the default objectives (fewest modules first), chains are searched by number of units,
    and within one number lightest shape first, ROUND shapes at a time: the search stops as soon
    as `enough` (default `top`) kinematically distinct designs are checked that no unsearched
    shape could beat; up to `top` are kept.
    ROUND does not depend on the number of workers, so neither does where the search stops.
    deadline (time.time()) and search.STOP end it early with what was found. diagnosing: say per
    target why there is no design (probes of seconds each). Each design comes with its other H/L
    splits that pass the exact check as its alternatives."""
    sweep = _Sweep(problem, max_units, top, seed, executor, progress, deadline)
    sweep.report(force=True)
    for n, splits, shapes in sweep.tiers:
        if sweep.tier(n, splits, shapes, enough or top):
            break
    return sweep.finish(diagnosing)


class _Sweep:
    """One static search's state: what it found per target, the exact checks in ranking order
    (Verifier), the shapes searched, and its progress."""

    def __init__(self, problem: ResolvedProblem, max_units: int | None, top: int, seed: int,
                 executor: Executor | None, progress: Callable[..., None] | None, deadline: float | None):
        self.t0 = time.perf_counter()
        self.problem, self.top, self.seed, self.executor = problem, top, seed, executor
        self.progress, self.deadline = progress, deadline
        self.spec = spec = Spec.of(problem)
        lib = problem.cell.library
        self.out = Outcome(problem, [])
        self.hi = min(max_units or problem.max_units, lib.rules.max_dof)
        self.names = [t.name for t in problem.cell.targets]
        self.closest = {t: np.inf for t in self.names}
        self.hit = dict.fromkeys(self.names, False)
        self.clear = dict.fromkeys(self.names, False)
        tg = spec.targets
        starts = np.array([(u.x01, 0.0, u.z01) for u in lib.units.values()], float)
        blocked, self.walls = bounds_blocked(spec.obstacles, tg.xyz, tg.tol_p,
                                             float(np.linalg.norm(problem.cell.tool.xyz)), float(spec.radii.min()),
                                             longest_reach(problem, self.hi), starts)
        self.tiers = [] if blocked.any() else _tiers(problem, spec, self.hi, self.closest)
        self.total_shapes = sum(len(s) for _, _, s in self.tiers)
        self.total_settings = sum(estimate(spec, s) for _, _, shapes in self.tiers for _, _, s in shapes)
        self.tally = Verifier(problem, top, self.out, _mass)
        self.tally.floors = floors(self.tiers)
        self.early = self.tally.bounded
        self.done, self.settings, self.best = 0, 0.0, ""
        self.searched: list[ShapeResult] = []

    def report(self, force: bool = False, final: bool = False) -> None:
        if self.progress is None:
            return
        spent = time.perf_counter() - self.t0
        # the share of every shape's settings done: an upper bound on what is left (the search
        # may stop early once the top designs are found)
        frac = self.settings / max(self.total_settings, 1)
        eta = (None if self.out.stopped else 0.0) if final else spent * (1 - frac) / frac if frac > 0.01 else None
        status = Status(self.done, self.total_shapes, self.out.evaluated, self.out.screened, self.best, eta)
        if force:
            self.progress(status, True)
        else:
            self.progress(status)

    def tier(self, n: int, splits, shapes: list, enough: int) -> bool:
        """The shapes of n units, a round at a time: True when the search ends here (stopped, or
        `enough` designs rank before every unsearched shape)."""
        rounds = _rounds(shapes) if self.early else [shapes]
        for k, batch in enumerate(rounds):
            halt = _Round(self, n, splits, batch).run()
            stop = _stopping(self.deadline)
            nxt = rounds[k + 1][0][0] if k + 1 < len(rounds) and not stop else float("inf")
            if halt is not None:  # the rest of the round unsearched: nothing heavier than it may be checked
                nxt = halt
                seen = {r.shape.label() for r in self.searched}
                self.out.shapes -= sum(1 for _, _, s in batch if s.label() not in seen)
            self.tally.settle(n, nxt)
            if self.tally.accepted:
                self.best = distinct(self.tally.accepted, self.problem.rank)[0].chain()
                self.report()
            if stop:
                self.out.stopped = stop
                return True
            if self.early and self.tally.done(n, nxt, enough):
                break
        if not self.early:
            return False
        self.tally.settle(n, float("inf"))
        return self.tally.done(n, float("inf"), enough)

    def absorb(self, n: int, splits, res: ShapeResult) -> None:
        out = self.out
        out.excluded += res.excluded
        out.dominated += res.dominated
        out.evaluated += res.evaluated - sum(p.screened + p.excluded for p in res.parts)  # families excluded whole
        self.searched.append(res)
        for i, name in enumerate(self.names):
            self.closest[name] = min(self.closest[name], res.closest[i])
            self.hit[name] = self.hit[name] or res.hit[i]
            self.clear[name] = self.clear[name] or res.clear[i]
        self.tally.add(n, splits, res)

    def finish(self, diagnosing: bool) -> Outcome:
        out, problem, tally = self.out, self.problem, self.tally
        tally.settle(self.hi, float("inf"))
        done = {r.shape.label() for r in self.searched if r.finished}
        if out.stopped:
            out.unfinished = [s.label() for _, _, shapes in self.tiers for _, _, s in shapes if s.label() not in done]
        else:
            out.unfinished = [r.shape.label() for r in self.searched if not r.finished]
        out.coarse = [r.shape.label() for r in self.searched if r.finished and not r.complete]
        out.complete = not out.unfinished and not out.coarse
        out.closest = {t: (0.0 if self.hit[t] else float(c)) for t, c in self.closest.items()}
        out.designs = [tally.swaps(d) for d in distinct(tally.accepted, problem.rank)[:self.top]]
        if not out.designs and diagnosing:
            out.targets = diagnose(problem, self.spec, self.names, self.walls, self.hit, self.clear, self.closest,
                                   self.seed, self.deadline, bool(out.stopped))
        out.seconds = time.perf_counter() - self.t0
        self.done = self.total_shapes - len(out.unfinished)
        self.report(force=True, final=True)
        return out


class _Round:
    """One round of a tier's shapes, searched in ranges (and level by level for large shapes):
    each shape's parts merged once all are in, checked at once, and the round stopped early
    once `top` designs rank before every unsearched shape."""

    def __init__(self, sweep: _Sweep, n: int, splits, batch: list):
        self.sweep, self.n, self.splits, self.batch = sweep, n, splits, batch
        self.pending: dict[str, list[Part]] = {}
        self.expected: dict[str, int] = {}
        # the mass of the shape after each one of the round (shapes are searched in that order)
        self.after = {s.label(): batch[j + 1][0] for j, (_, _, s) in enumerate(batch[:-1])}
        self.halt: float | None = None  # the lightest unsearched mass, once the round stops early
        self.later: list = []  # a shape's next level, once its round is whole (search.follow)
        self.waiting: set[str] = set()  # shapes with a level still to search: no early stop before them

    def run(self) -> float | None:
        """The round searched; the lightest unsearched mass when it stopped early, else None."""
        sw = self.sweep
        # lazily in one process: a shape's plan (its family bounds) is worked out only if the
        # round gets to it
        work = (w for _, _, s in self.batch for w in parts_of(sw.spec, s))
        sw.out.shapes += len(self.batch)
        _run_parts(sw.executor, sw.spec, work, sw.seed, sw.deadline, self.each, sw.report)
        while self.later and self.halt is None and not _stopping(sw.deadline):
            levels, self.later[:] = list(self.later), []
            _run_parts(sw.executor, sw.spec, levels, sw.seed, sw.deadline, self.each, sw.report)
        for ps in self.pending.values():  # shapes cut short: what their finished ranges found
            sw.absorb(self.n, self.splits, merge(sw.spec, ps[0].shape, ps))
        return self.halt

    def each(self, p: Part) -> bool:
        sw = self.sweep
        sw.out.evaluated += p.screened + p.excluded
        # progress in the units of total_settings: this part's share of its shape
        sw.settings += estimate(sw.spec, p.shape) * max(p.upto - p.lo, p.hi == p.lo) / max(listed(sw.spec, p.shape), 1)
        label = p.shape.label()
        self.pending.setdefault(label, []).append(p)
        expect = self.expected.setdefault(label, len(parts_of(sw.spec, p.shape)))
        if len(self.pending[label]) == expect and (more := follow(sw.spec, p.shape, self.pending[label])):
            self.expected[label] += len(more)
            self.later.extend(more)
            self.waiting.add(label)
        elif len(self.pending[label]) == expect:
            self.waiting.discard(label)
            if self._shape_done(merge(sw.spec, p.shape, self.pending.pop(label))):
                return True
        sw.report()
        return False

    def _shape_done(self, res: ShapeResult) -> bool:
        """A shape's search merged: its designs checked now, and True when the round may stop."""
        sw = self.sweep
        sw.absorb(self.n, self.splits, res)
        sw.done += 1
        if res.found and not sw.best:
            sw.best = f"shape {res.shape.label()} (unchecked)"
        # every shape lighter than the next one is searched: check what it found now, and stop the
        # round once `top` designs rank before every unsearched shape (the same point whatever the
        # executor: shapes complete in submission order). A round searched to its end stops the
        # search at `enough` (Sweep.tier).
        heavier = self.after.get(res.shape.label())
        below = heavier
        if sw.early and below is not None and not self.waiting and (res.found or sw.tally.accepted):
            sw.tally.settle(self.n, below)
            if sw.tally.done(self.n, below, sw.top):
                self.halt = below
                return True
        return False


__all__ = ["ROUND", "ROUND_MAX", "longest_reach"]
