"""Base placement's static search: each shape's twist settings tried at every base pose at once.

With `base within` a shape's candidates are (twist setting, base pose) pairs. Within a shape
they rank as one pose's settings do (search.order_key: worst target error as a share of its
tolerance to 1 %, nonzero twists, sum of |angles|, the values), then by the pose's place in the
grid's order (placement.poses: nearest cell first). A setting counts once, at its best pose
(where that key is least; of equal keys, the first pose). The shape's kept list is the KEEP
best settings so ranked; its design is, per H/L split, the first of them (up to TRIES) that
passes the exact check at its pose, as at one pose. So a shape gives one design over the grid,
not one per pose.

The kept list is the KEEP best of the union of every pose's own kept list (a setting among the
KEEP best pairs is among the KEEP best of its best pose), which is what tests compare it with.

Search: level by level (dominance.py: level c is the live settings with c nonzero twists),
level c at every pose before level c + 1. Once level c is done at every pose and the kept list
holds KEEP settings of worst share 0.00, no setting of a higher level at any pose can enter it
(its key is larger on the first or second entry, before the pose breaks a tie), so the rest of
the shape at every pose is excluded by that bound (`dominated`) and the shape is complete. Every
other setting at every pose is screened there or excluded by that pose's family and per-setting
bounds: complete within its bounds, as one pose's search is. This is where the grid saves: a
setting kept from the pose where it works closes the shape at the poses where it does not.
Past search.COMPLETE settings listed at a pose the levels left there go on its coarse grid
(not complete), as at one pose.

A shape's family bounds at every pose in reach are refined in one pass (prefix.refine_many:
each pose gets the families its own prefix.refine gives, so the same settings are listed and
counted as pose by pose).

Every unit of work is search.search_chunk on a pose's Spec, merged in a fixed order, so the
ranking is the same in one process, a process pool or Dask.
"""
from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import Executor
from dataclasses import dataclass, field

import numpy as np

from ..kinematics import transform
from ..model import ResolvedProblem
from . import dominance, prefix, space
from .bounds import blocked as bounds_blocked
from .evaluate import Spec
from .rank import distinct
from .screen import reach_bound
from .search import COMPLETE, KEEP, Found, Part, ShapeResult, _listed, _split, order_key, search_chunk
from .settings import full_axes
from .verify_order import Verifier


@dataclass(frozen=True)
class Placed(Found):
    pose: int = 0  # index into the searched poses (nearest cell first)


def rank_key(f: Placed) -> tuple:
    return (order_key(f), f.pose)


def kept(found) -> list[Placed]:
    """The KEEP best settings, each once at its best pose."""
    best: dict[tuple, Placed] = {}
    for f in found:
        k = (f.pivots, f.ports)
        if k not in best or rank_key(f) < rank_key(best[k]):
            best[k] = f
    return sorted(best.values(), key=rank_key)[:KEEP]


class _Tally(Verifier):
    """The exact checks, each setting at its pose's cell."""

    def __init__(self, subs: list[ResolvedProblem], top: int, out, mass):
        super().__init__(subs[0], top, out, mass)
        self.subs = subs

    def at(self, f) -> ResolvedProblem:
        return self.subs[f.pose]


def _options(spec: Spec, shape: space.Shape) -> list[prefix.Level]:
    """The shape's fixed transforms K_0 … K_n as option lists (the same at every pose)."""
    lib = spec.problem.cell.library
    types = [lib.units[k] for k in shape.kinds]
    links = [(x if x is not None else t.x23) for t, x in zip(types, shape.links, strict=True)]
    tool = spec.problem.cell.tool
    return prefix.levels(types, links, space.twist_values(lib.twists.pivot), space.twist_values(lib.twists.port),
                         space.port_free(spec.problem, shape, lib), transform(tool.xyz, tool.rpy))


def _live(spec: Spec, shape: space.Shape, fam: prefix.Families) -> tuple[dominance.Levels, int]:
    """The shape's live settings at this pose by level (its families, as search._plan finds
    them) and how many settings the families exclude."""
    full = full_axes(spec, shape)
    return dominance.levels_of(full.values, fam.alive, fam.per), full.count - fam.settings


def _runs(numbers: np.ndarray) -> list[tuple[int, int]]:
    """Sorted setting numbers as [lo, hi) ranges."""
    if not len(numbers):
        return []
    cut = np.flatnonzero(np.diff(numbers) != 1) + 1
    lo = numbers[np.r_[0, cut]]
    hi = numbers[np.r_[cut - 1, len(numbers) - 1]] + 1
    return list(zip(lo.tolist(), hi.tolist(), strict=True))


@dataclass
class _Shape:
    """One shape's search over the poses."""

    shape: space.Shape
    live: dict[int, dominance.Levels]  # pose -> its live settings by level (poses in reach only)
    excluded: int  # settings excluded by families, over the poses
    parts: list[Part] = field(default_factory=list)
    found: list[Placed] = field(default_factory=list)
    level: int = -1  # levels done at every pose
    coarse: set[int] = field(default_factory=set)  # poses whose levels left went on the coarse grid
    dominated: int = 0
    closed: bool = False
    finished: bool = True

    def result(self, targets: int) -> ShapeResult:
        closest = np.full(targets, np.inf)
        hit, clear = np.zeros(targets, bool), np.zeros(targets, bool)
        for p in self.parts:
            closest = np.minimum(closest, p.closest)
            hit |= np.array(p.hit, bool)
            clear |= np.array(p.clear, bool)
        screened = sum(p.screened for p in self.parts)
        excluded = sum(p.excluded for p in self.parts) + self.excluded + self.dominated
        found = tuple(kept(self.found))
        total = screened + excluded
        return ShapeResult(self.shape, found, total, tuple(float(x) for x in closest), 0.0 if found else 1.0,
                           screened, excluded, self.dominated, total, self.finished and not self.coarse,
                           self.finished, tuple(bool(x) for x in hit), tuple(bool(x) for x in clear), self.parts)


def _next(s: _Shape) -> int:
    """The last level of shape s's next round: levels 0 and 1 together (a setting and a few
    dozen), then one level at a time; past level 2 with nothing found anywhere, every level left
    (the dominance bound needs KEEP settings found: one more level would rarely close the shape,
    and one round is a batch per pose rather than several)."""
    if s.level >= 2 and not s.found:
        return max(len(lv.counts) for lv in s.live.values()) - 1
    return max(s.level + 1, 1)


def _work(specs: list[Spec], s: _Shape, lo: int, hi: int) -> list[tuple[int, tuple]]:
    """Levels lo … hi of shape s at every pose: (pose, unit of work) pairs."""
    out: list[tuple[int, tuple]] = []
    for i, lv in s.live.items():
        if i in s.coarse or lo >= len(lv.counts):
            continue
        if sum(lv.counts[:hi + 1]) > COMPLETE:  # the levels left here on the coarse grid
            s.coarse.add(i)
            how: tuple = ("rest", lo - 1)
            n = len(_listed(specs[i], s.shape, how)[1])  # type: ignore[arg-type]
            out += [(i, (s.shape, r, how)) for r in _split([(0, n)])]
        elif sum(lv.counts[lo:hi + 1]):
            numbers = np.sort(np.concatenate([dominance.level_numbers(lv, c) for c in range(lo, hi + 1)]))
            out += [(i, (s.shape, r, True)) for r in _split(_runs(numbers))]
    return out


def _run(specs: list[Spec], work: list[tuple[int, tuple]], seed: int, deadline: float | None,
         executor: Executor | None, seen: Callable[[int], None] = lambda k: None) -> list[tuple[int, Part]]:
    """Every unit of work, in order; seen(k) with each Part's settings screened or excluded as
    it comes back (the progress display: a round over every pose takes minutes in a large cell)."""
    out: list[tuple[int, Part]] = []
    if executor is None:
        for i, w in work:
            for p in search_chunk(specs[i], [w], seed, deadline):
                out.append((i, p))
                seen(p.screened + p.excluded)
        return out
    futures = [(i, executor.submit(search_chunk, specs[i], [w], seed, deadline)) for i, w in work]
    for i, f in futures:
        for p in f.result():
            out.append((i, p))
            seen(p.screened + p.excluded)
    return out


def walled(spec: Spec, longest: float) -> bool:
    """Is some target at this pose out of every arm's service because of an obstacle
    (bounds.blocked, as run._search tests one pose)?"""
    lib = spec.problem.cell.library
    tg = spec.targets
    starts = np.array([(u.x01, 0.0, u.z01) for u in lib.units.values()], float)
    out, _ = bounds_blocked(spec.obstacles, tg.xyz, tg.tol_p, float(np.linalg.norm(spec.problem.cell.tool.xyz)),
                            float(spec.radii.min()), longest, starts)
    return bool(out.any())


def _opened(specs: list[Spec], shape: space.Shape, skip: frozenset[int]) -> _Shape:
    """A shape's live families at every pose but those skipped (walled off) or beyond its reach."""
    lib = specs[0].problem.cell.library
    lengths = [x or lib.units[k].x23 for k, x in zip(shape.kinds, shape.links, strict=True)]
    r = reach_bound([lib.units[k] for k in shape.kinds], lengths, specs[0].problem.cell.tool.xyz)
    live, excluded, near = {}, 0, []
    for i, spec in enumerate(specs):
        tg = spec.targets
        if i in skip or np.any(np.linalg.norm(tg.xyz, axis=1) - r - tg.tol_p > 0):  # walled off, beyond reach
            excluded += full_axes(spec, shape).count
        else:
            near.append(i)
    if near:  # the family bounds of every pose in reach in one pass (prefix.refine_many)
        options = _options(specs[near[0]], shape)
        # position only: the orientation bounds per family (prefix.refine's tg) cost a base grid's
        # every pose as much as a whole search's budget; the settings get them (bounds.posed)
        families = prefix.refine_many(options, [(specs[i].targets.xyz, specs[i].targets.tol_p) for i in near])
        for i, fam in zip(near, families, strict=True):
            live[i], out = _live(specs[i], shape, fam)
            excluded += out
    return _Shape(shape, live, excluded)


def _level_done(s: _Shape, c: int) -> None:
    """Levels up to c searched at every pose: the shape closes when cut short, when dominance
    bounds the rest, or when no level is left."""
    s.level = c
    if not s.finished:
        s.closed = True
    elif dominance.dominates(kept(s.found), KEEP):
        s.dominated = sum(sum(lv.counts[c + 1:]) for i, lv in s.live.items() if i not in s.coarse)
        s.closed = True
    elif all(c + 1 >= len(lv.counts) or i in s.coarse for i, lv in s.live.items()):
        s.closed = True


def search_shapes(specs: list[Spec], shapes: list[space.Shape], seed: int, deadline: float | None,
                  executor: Executor | None, stopping: Callable[[], str | None],
                  skip: frozenset[int] = frozenset(),
                  seen: Callable[[int], None] = lambda k: None) -> list[ShapeResult]:
    """The shapes searched over every pose but those in skip, a level at a time (see the
    module's docstring). seen(k): k more settings screened or excluded (progress)."""
    open_: list[_Shape] = []
    for shape in shapes:  # the family bounds of a shape at every pose take seconds: the budget between them
        if stopping():
            break
        open_.append(_opened(specs, shape, skip))
        seen(open_[-1].excluded)
    todo = [s for s in open_ if s.live]
    while todo and not stopping():
        upto = {id(s): _next(s) for s in todo}
        work = [(s, w) for s in todo for w in _work(specs, s, s.level + 1, upto[id(s)])]
        parts = _run(specs, [w for _, w in work], seed, deadline, executor, seen)
        for (s, _), (i, p) in zip(work, parts, strict=True):
            s.parts.append(p)
            s.found += [Placed(f.pivots, f.ports, f.solutions, f.worst, i) for f in p.found]
            s.finished &= p.upto >= p.hi
        for s in todo:
            _level_done(s, upto[id(s)])
        todo = [s for s in todo if not s.closed]
    for s in todo:  # stopped: what was screened
        s.finished = False
    T = len(specs[0].targets.names)
    return [s.result(T) for s in open_]


def _mass_groups(problem: ResolvedProblem, shapes: list[space.Shape], splits) -> list[tuple[float, list]]:
    """Shapes of equal least mass together, lightest first."""
    from .sweep import _min_mass

    ranked = sorted(((_min_mass(problem, s, splits), s.label(), s) for s in shapes), key=lambda e: e[:2])
    groups: list[tuple[float, list]] = []
    for m, _, s in ranked:
        if m == float("inf"):
            continue
        if groups and abs(groups[-1][0] - m) <= 1e-9:
            groups[-1][1].append(s)
        else:
            groups.append((m, [s]))
    return groups


def _floors(problem: ResolvedProblem, hi: int) -> dict[int, float]:
    """n -> the least mass of a shape of more than n units (Verifier.floors)."""
    from .sweep import floors

    lib = problem.cell.library
    tiers = []
    for n in range(max(problem.min_units, lib.rules.min_dof), hi + 1):
        splits = space.variant_splits(problem, n)
        if splits:
            tiers.append((n, splits, [(m, "", None) for m, shapes in _mass_groups(problem, space.shapes(problem, n),
                                                                                splits) for _ in shapes]))
    return floors(tiers)


def search(problem: ResolvedProblem, subs: list[ResolvedProblem], max_units: int | None, top: int, seed: int,
           executor: Executor | None, deadline: float | None, enough: int | None = None,
           progress: Callable[..., None] | None = None):
    """The static search over the base poses (subs: the cell at each pose, nearest first):
    designs ranked by the problem's static objectives, at most `top`, each at its pose. By number
    of units, lightest shapes first, stopping as the one-pose search (modc.design.sweep) does
    once `enough` designs rank ahead of every shape not searched. progress(Status) after each
    group of shapes."""
    g = _Grid(problem, subs, max_units, top, seed, executor, deadline, progress)
    g.report(force=True)
    for n in range(max(problem.min_units, problem.cell.library.rules.min_dof), g.hi + 1):
        splits = space.variant_splits(problem, n)
        if splits and g.tier(n, splits, enough or top):
            break
    return g.finish()


class _Grid:
    """One grid search's state: the poses' Specs, the exact checks in ranking order, the shapes
    searched, what came closest to each target."""

    def __init__(self, problem: ResolvedProblem, subs: list[ResolvedProblem], max_units: int | None, top: int,
                 seed: int, executor: Executor | None, deadline: float | None,
                 progress: Callable[..., None] | None):
        from .outcome import Outcome
        from .sweep import _mass, longest_reach

        self.problem, self.top, self.seed, self.executor = problem, top, seed, executor
        self.deadline, self.progress = deadline, progress
        self.out = Outcome(problem, [])
        self.specs = [Spec.of(s) for s in subs]
        self.tally = _Tally(subs, top, self.out, _mass)
        lib = problem.cell.library
        self.hi = min(max_units or problem.max_units, lib.rules.max_dof)
        self.tally.floors = _floors(problem, self.hi)
        self.early = self.tally.bounded
        self.names = [t.name for t in problem.cell.targets]
        self.closest = np.full(len(self.names), np.inf)
        self.results: list[ShapeResult] = []
        self.skip = frozenset(i for i, spec in enumerate(self.specs)
                              if walled(spec, longest_reach(problem, self.hi)))
        self.running = 0  # settings screened or excluded in the group of shapes under way
        self.every = [s.label() for n in range(max(problem.min_units, lib.rules.min_dof), self.hi + 1)
                      if space.variant_splits(problem, n) for s in space.shapes(problem, n)]

    def report(self, force: bool = False, final: bool = False) -> None:
        from .outcome import Status

        if self.progress is None:
            return
        tally, out = self.tally, self.out
        best = distinct(tally.accepted, self.problem.rank)[0].chain() if tally.accepted else ""
        eta = (None if out.stopped else 0.0) if final else None
        st = Status(len(self.results), len(self.every), out.evaluated + self.running, out.screened, best, eta)
        if force:
            self.progress(st, True)
        else:
            self.progress(st)

    def _seen(self, k: int) -> None:
        self.running += k
        self.report()

    def tier(self, n: int, splits, want: int) -> bool:
        """The shapes of n units, a group of equal least mass at a time: True when the search
        ends here (stopped, or `want` designs rank before every unsearched shape)."""
        from .sweep import _stopping

        out, tally = self.out, self.tally
        groups = _mass_groups(self.problem, space.shapes(self.problem, n), splits)
        for g, (_, shapes) in enumerate(groups):
            res = search_shapes(self.specs, shapes, self.seed, self.deadline, self.executor,
                                lambda: _stopping(self.deadline), self.skip, self._seen)
            self.running = 0  # the group's results count them now
            for r in res:
                self.results.append(r)
                out.shapes += 1
                out.evaluated += r.evaluated
                out.excluded += r.excluded
                out.dominated += r.dominated
                self.closest = np.minimum(self.closest, r.closest)
                tally.add(n, splits, r)
            out.stopped = _stopping(self.deadline) or (None if all(r.finished for r in res) else "time budget")
            nxt = groups[g + 1][0] if g + 1 < len(groups) and not out.stopped else float("inf")
            tally.settle(n, nxt)
            self.report()
            if out.stopped:
                return True
            if self.early and tally.done(n, nxt, want):
                break
        if not self.early:
            return False
        tally.settle(n, float("inf"))
        return tally.done(n, float("inf"), want)

    def finish(self):
        out, results = self.out, self.results
        self.tally.settle(self.hi, float("inf"))
        done = {r.shape.label() for r in results if r.finished}
        out.unfinished = [x for x in self.every if x not in done] if out.stopped else \
            [r.shape.label() for r in results if not r.finished]
        out.coarse = [r.shape.label() for r in results if r.finished and not r.complete]
        out.complete = not out.unfinished and not out.coarse
        out.closest = {t: (0.0 if any(r.hit[k] for r in results) else float(self.closest[k]))
                       for k, t in enumerate(self.names)}
        out.designs = distinct(self.tally.accepted, self.problem.rank)[:self.top]
        self.report(force=True, final=True)
        return out
