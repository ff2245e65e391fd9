"""The search, end to end: shapes by number of units, the twist search of each shape in ranges
of its settings (on any concurrent.futures executor), variant splits re-weighed, exact checks in
ranking order, with a time budget, Ctrl-C and progress.

Work goes to the executor as ranges of one shape's settings (search.WORK); results are merged
per shape in submission order and every range is a pure function of its inputs, so the ranking
is the same for one process, a local pool or a Dask cluster.
"""
from __future__ import annotations

import time
from collections.abc import Callable, Iterable
from concurrent.futures import Executor
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..model import ResolvedProblem
from . import space
from .bounds import blocked as bounds_blocked
from .diagnose import diagnose, why_none
from .evaluate import Spec
from .rank import Design, distinct, key, static
from .screen import reach_bound
from .search import STOP, TICK, Part, ShapeResult, estimate, follow, listed, merge, parts_of, search_chunk
from .verify_order import Verifier

ROUND = 16  # shapes in a tier's first round of search between exact checks; rounds double up to ROUND_MAX
ROUND_MAX = 512  # (sizes independent of the workers: where the search stops does not depend on them)


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

    def why_none(self) -> str:
        return why_none(self)


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


def _edge(problem: ResolvedProblem, mass: float) -> float:
    """The lightest unsearched shape's mass as the search compares designs with it: equal masses
    summed in another order differ in the last bits, so 1e-9 kg either way - ahead of a design
    as heavy when margin may still tell them apart, level with it when nothing can."""
    return mass - 1e-9 if "margin" in problem.rank else mass + 1e-9


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


MAX_CANDIDATES = 96  # static designs a task cell plans at most, when the first ones all fail planning


def design(problem: ResolvedProblem, *, max_units: int | None = None, top: int = 5, seed: int = 0,
           executor: Executor | None = None, progress: Callable[..., None] | None = None,
           deadline: float | None = None) -> Outcome:
    """Ranked designs for a checked problem (its library resolved).

    A cell with tasks or paths: the static search (ranked by the objectives it knows) returns
    its best designs, more of them when a task objective ranks (tasks.candidates); each is then
    planned and timed (tasks.plan_all) and the survivors ranked by every objective. With
    `base within`, the static search runs per base pose (modc.design.placement)."""
    from . import grid, placement, reference, tasks

    t0 = time.perf_counter()
    if max_units is not None:  # --max-units: the design's bound for everything below, the diagnosis too
        if max_units < problem.min_units:
            raise ValueError(f"--max-units {max_units} is below the {problem.min_units} units design "
                             f"'{problem.name}' asks for at least")
        problem = problem.model_copy(update={"max_units": max_units})
    tasked = tasks.has_tasks(problem) or "coverage" in problem.rank
    screen, points = tasks.with_points(problem)  # every region point required: screened as a target
    screen = _static_screen(screen, problem) if tasked else screen
    n = tasks.candidates(problem, top) if tasked else top

    enough = [top]  # designs after which a round may stop (more when the first candidates all fail planning)

    def one(p: ResolvedProblem, units: int | None, k: int, diagnosing: bool = True) -> Outcome:
        # the extra candidates to time come from the shapes searched until `top` designs are found
        # (a round at a time): searching on only to have more of them cost whole tiers (6.6 M
        # settings, 369 s on a 4-goal visit cell)
        return _search(p, units, k, seed, executor, progress, deadline, enough=enough[0],
                       diagnosing=diagnosing)

    def many(p: ResolvedProblem, cells: list[ResolvedProblem], units: int | None, k: int) -> Outcome:
        return grid.search(p, cells, units, k, seed, executor, deadline, enough=enough[0], progress=progress)

    rejected: dict[str, tuple[str, str | None]] = {}  # chain -> why (and which task) it could not be planned: once only
    while True:
        if problem.base_grid is None:
            out = one(screen, max_units, n)
        else:
            hi = min(max_units or problem.max_units, problem.cell.library.rules.max_dof)
            out = placement.search(screen, max_units, n, longest_reach(problem, hi), one, many)
        out.problem = problem
        tasks.restore(out, points)
        if not tasked:
            break
        if _optional_points(problem) and not out.stopped:
            out = _covering(problem, out, one, max_units, n, top, seed, deadline)
        found = len(out.designs)
        tasks.plan_all(out, top, seed, deadline, _stopping, rejected, _planning(out, progress))
        # every candidate failed its tasks: search on for more of them while there may be more (the
        # search stopped once `enough` designs ranked first, or it returned as many as asked)
        exhausted = found < n and enough[0] >= n
        if out.designs or out.stopped or exhausted or n >= MAX_CANDIDATES:
            break
        n = enough[0] = min(n * 4, MAX_CANDIDATES)
    out.reference = reference.evaluate(problem, seed, deadline, out.bases_kept)
    out.seconds = time.perf_counter() - t0
    return out


def _planning(out: Outcome, progress: Callable[..., None] | None) -> Callable[[int, int, str], None] | None:
    """The progress callback told which design is being planned and timed (k of n)."""
    if progress is None:
        return None

    def tick(k: int, n: int, chain: str) -> None:
        status = Status(out.shapes, out.shapes, out.evaluated, out.screened, chain, None,
                        f"planning and timing design {k} of {n}")
        progress(status, True)
    return tick


def _covering(problem: ResolvedProblem, out: Outcome, one, max_units: int | None, n: int, top: int,
              seed: int, deadline: float | None) -> Outcome:
    """`rank coverage`: the candidates to plan are those that serve every region point when some
    do (coverage 1, the most there is), else those serving at least one (tasks.by_points), and
    only when none serves any, out's (the cell's targets alone: they are then told what they miss)."""
    from . import tasks

    every, names = tasks.with_points(problem, every=True)
    whole = one(_static_screen(every, problem), max_units, n, diagnosing=False)
    tasks.restore(whole, names)
    picked = whole if whole.designs or whole.stopped else tasks.by_points(
        problem, lambda s: one(_static_screen(s, problem), max_units, top, diagnosing=False), n, seed,
        lambda: _stopping(deadline))
    if picked is None or not picked.designs:
        return out
    picked.problem = problem
    return picked


def _static_screen(screen: ResolvedProblem, problem: ResolvedProblem) -> ResolvedProblem:
    """The problem the static search runs on for a cell with tasks: it only picks the candidates
    to plan and time, fewest modules then least mass (the torque margin along the motion is judged
    by the planning, not by a static tie-break)."""
    return screen.model_copy(update={"rank": tuple(k for k in static(problem.rank) if k != "margin")
                                     or ("modules", "mass")})


def _optional_points(problem: ResolvedProblem) -> bool:
    """`rank coverage` with regions, no base grid: the static search screened no region point."""
    return "coverage" in problem.rank and bool(problem.cell.regions) and problem.base_grid is None


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
    t0 = time.perf_counter()
    spec = Spec.of(problem)
    lib = problem.cell.library
    out = Outcome(problem, [])
    hi = min(max_units or problem.max_units, lib.rules.max_dof)
    names = [t.name for t in problem.cell.targets]
    closest = {t: np.inf for t in names}
    hit = dict.fromkeys(names, False)
    clear = dict.fromkeys(names, False)
    tg = spec.targets
    longest = longest_reach(problem, hi)
    starts = np.array([(u.x01, 0.0, u.z01) for u in lib.units.values()], float)
    blocked, walls = bounds_blocked(spec.obstacles, tg.xyz, tg.tol_p, float(np.linalg.norm(problem.cell.tool.xyz)),
                                    float(spec.radii.min()), longest, starts)
    tiers = [] if blocked.any() else _tiers(problem, spec, hi, closest)
    total_shapes = sum(len(s) for _, _, s in tiers)
    total_settings = sum(estimate(spec, s) for _, _, shapes in tiers for _, _, s in shapes)
    early = problem.rank[:2] == ("modules", "mass")
    tally = Verifier(problem, top, out, _mass)
    state: dict = {"done": 0, "settings": 0, "best": ""}

    def report(force: bool = False, final: bool = False) -> None:
        if progress is None:
            return
        spent = time.perf_counter() - t0
        # the share of every shape's settings done: an upper bound on what is left (the search
        # may stop early once the top designs are found)
        frac = state["settings"] / max(total_settings, 1)
        eta = (None if out.stopped else 0.0) if final else spent * (1 - frac) / frac if frac > 0.01 else None
        status = Status(state["done"], total_shapes, out.evaluated, out.screened, state["best"], eta)
        if force:
            progress(status, True)
        else:
            progress(status)

    searched: list[ShapeResult] = []
    report(force=True)
    for n, splits, shapes in tiers:
        rounds = _rounds(shapes) if early else [shapes]
        for k, batch in enumerate(rounds):
            # lazily in one process: a shape's plan (its family bounds) is worked out only if the
            # round gets to it
            work = (w for _, _, s in batch for w in parts_of(spec, s))
            pending: dict[str, list[Part]] = {}
            expected: dict[str, int] = {}
            # the mass of the shape after each one of the round (shapes are searched in that order)
            after = {s.label(): batch[j + 1][0] for j, (_, _, s) in enumerate(batch[:-1])}
            halt: list[float] = []  # the lightest unsearched mass, once the round stops early
            later: list = []  # a shape's next level, once its round is whole (search.follow)
            waiting: set[str] = set()  # shapes with a level still to search: no early stop before them

            def each(p: Part, n=n, splits=splits, pending=pending, expected=expected, after=after,
                     halt=halt, later=later, waiting=waiting) -> bool:
                out.evaluated += p.screened + p.excluded
                # progress in the units of total_settings: this part's share of its shape
                state["settings"] += estimate(spec, p.shape) * max(p.upto - p.lo, p.hi == p.lo) \
                    / max(listed(spec, p.shape), 1)
                pending.setdefault(p.shape.label(), []).append(p)
                label = p.shape.label()
                expect = expected.setdefault(label, len(parts_of(spec, p.shape)))
                if len(pending[label]) == expect and (more := follow(spec, p.shape, pending[label])):
                    expected[label] += len(more)
                    later.extend(more)
                    waiting.add(label)
                elif len(pending[label]) == expect:
                    waiting.discard(label)
                    res = merge(spec, p.shape, pending.pop(p.shape.label()))
                    _absorb(out, res, names, closest, hit, clear, searched)
                    state["done"] += 1
                    tally.add(n, splits, res)
                    if res.found and not state["best"]:
                        state["best"] = f"shape {res.shape.label()} (unchecked)"
                    # every shape lighter than the next one is searched: check what it found now,
                    # and stop the round once `top` designs rank before every unsearched shape (the
                    # same point whatever the executor: shapes complete in submission order). A
                    # round searched to its end stops the search at `enough` (below).
                    heavier = after.get(p.shape.label())
                    below = None if heavier is None else _edge(problem, heavier)
                    if early and below is not None and not waiting and (res.found or tally.accepted):
                        tally.settle(n, below)
                        if tally.done(n, below, top):
                            halt.append(below)
                            return True
                report()
                return False

            out.shapes += len(batch)
            _run_parts(executor, spec, work, seed, deadline, each, report)
            while later and not halt and not _stopping(deadline):
                levels, later[:] = list(later), []
                _run_parts(executor, spec, levels, seed, deadline, each, report)
            for ps in pending.values():  # shapes cut short: what their finished ranges found
                res = merge(spec, ps[0].shape, ps)
                _absorb(out, res, names, closest, hit, clear, searched)
                tally.add(n, splits, res)
            stop = _stopping(deadline)
            nxt = _edge(problem, rounds[k + 1][0][0]) if k + 1 < len(rounds) and not stop else float("inf")
            if halt:  # the rest of the round unsearched: nothing heavier than it may be checked
                nxt = halt[0]
                seen = {r.shape.label() for r in searched}
                out.shapes -= sum(1 for _, _, s in batch if s.label() not in seen)
            tally.settle(n, nxt)
            if tally.accepted:
                state["best"] = distinct(tally.accepted, problem.rank)[0].chain()
                report()
            if stop:
                out.stopped = stop
                break
            if early and tally.done(n, nxt, enough):
                break
        if out.stopped:
            break
        if not early:
            continue
        tally.settle(n, float("inf"))
        if tally.distinct_count() >= (enough or top):
            break
    tally.settle(hi, float("inf"))
    done = {r.shape.label() for r in searched if r.finished}
    if out.stopped:
        out.unfinished = [s.label() for _, _, shapes in tiers for _, _, s in shapes if s.label() not in done]
    else:
        out.unfinished = [r.shape.label() for r in searched if not r.finished]
    out.coarse = [r.shape.label() for r in searched if r.finished and not r.complete]
    out.complete = not out.unfinished and not out.coarse
    out.closest = {t: (0.0 if hit[t] else float(c)) for t, c in closest.items()}
    out.designs = [tally.swaps(d) for d in distinct(tally.accepted, problem.rank)[:top]]
    if not out.designs and diagnosing:
        out.targets = diagnose(problem, spec, names, walls, hit, clear, closest, seed, deadline, bool(out.stopped))
    out.seconds = time.perf_counter() - t0
    state["done"] = total_shapes - len(out.unfinished)
    report(force=True, final=True)
    return out


def _absorb(out: Outcome, res: ShapeResult, names, closest, hit, clear, searched) -> None:
    out.excluded += res.excluded
    out.dominated += res.dominated
    out.evaluated += res.evaluated - sum(p.screened + p.excluded for p in res.parts)  # families excluded whole
    searched.append(res)
    for i, name in enumerate(names):
        closest[name] = min(closest[name], res.closest[i])
        hit[name] = hit[name] or res.hit[i]
        clear[name] = clear[name] or res.clear[i]


__all__ = ["Outcome", "Status", "design", "key"]
