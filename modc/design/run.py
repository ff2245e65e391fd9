"""`modc design` end to end: the static search (modc.design.sweep) once, or over a base grid
(modc.design.placement), region points as targets, the candidates' tasks planned and timed
(modc.design.tasks), the reference arm evaluated beside them."""
from __future__ import annotations

import time
from collections.abc import Callable
from concurrent.futures import Executor

from ..model import ResolvedProblem
from .outcome import Outcome, Status
from .rank import key, static
from .sweep import _min_mass, _search, _stopping, _tiers, longest_reach

MAX_CANDIDATES = 96  # static designs a task cell plans at most, when the first ones all fail planning
PLAN_RESERVE = 4.0  # s of a task cell's time budget kept for planning each candidate (at most half of it)


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
    beyond = regions_beyond(problem, min(max_units or problem.max_units, problem.cell.library.rules.max_dof))
    if beyond and len(beyond) == len(problem.cell.regions):
        # `rank coverage` and no point of any region in reach: no arm serves a point, whichever it
        # is (the search and the planning of every candidate would only find that out)
        out = Outcome(problem, [], regions_beyond=beyond)
        out.reference = reference.evaluate(problem, seed, deadline, None)
        out.seconds = time.perf_counter() - t0
        return out
    screen, points = tasks.with_points(problem)  # every region point required: screened as a target
    screen = _static_screen(screen, problem) if tasked else screen
    n = tasks.candidates(problem, top) if tasked else top

    enough = [top]  # designs after which a round may stop (more when the first candidates all fail planning)

    # a task cell's static search leaves part of the budget to plan what it found: a search cut
    # short by the budget still hands over its best designs, planned and timed
    by = [deadline]

    def one(p: ResolvedProblem, units: int | None, k: int, diagnosing: bool = True) -> Outcome:
        # the extra candidates to time come from the shapes searched until `top` designs are found
        # (a round at a time): searching on only to have more of them cost whole tiers (6.6 M
        # settings, 369 s on a 4-goal visit cell)
        return _search(p, units, k, seed, executor, progress, by[0], enough=enough[0], diagnosing=diagnosing)

    def many(p: ResolvedProblem, cells: list[ResolvedProblem], units: int | None, k: int) -> Outcome:
        return grid.search(p, cells, units, k, seed, executor, by[0], enough=enough[0], progress=progress)

    def static_search(p: ResolvedProblem, k: int, diagnosing: bool = True) -> Outcome:
        """p's static search: at the base as written, or over the base grid (placement)."""
        if problem.base_grid is None:
            return one(p, max_units, k, diagnosing)
        hi = min(max_units or problem.max_units, problem.cell.library.rules.max_dof)
        return placement.search(p, max_units, k, longest_reach(problem, hi),
                                lambda s, u, m: one(s, u, m, diagnosing), many)

    rejected: dict[str, tuple[str, str | None]] = {}  # chain -> why (and which task) it could not be planned: once only
    while True:
        by[0] = _search_deadline(deadline, n) if tasked else deadline
        out = static_search(screen, n)
        out.problem = problem
        tasks.restore(out, points)
        if not tasked:
            break
        if _optional_points(problem) and not out.stopped:
            out = _covering(problem, out, static_search, n, top, seed, deadline)
        found = len(out.designs)
        tasks.plan_all(out, top, seed, deadline, _stopping, rejected, _planning(out, progress))
        # every candidate failed its tasks: search on for more of them while there may be more (the
        # search stopped once `enough` designs ranked first, or it returned as many as asked); with
        # fewer than `enough` it searched every shape, and a second search would find the same
        exhausted = found < n and (enough[0] >= n or found < enough[0])
        if out.designs or out.stopped or exhausted or n >= MAX_CANDIDATES:
            break
        n = enough[0] = min(n * 4, MAX_CANDIDATES)
    out.reference = reference.evaluate(problem, seed, deadline, out.bases_kept)
    out.seconds = time.perf_counter() - t0
    return out


def _search_deadline(deadline: float | None, candidates: int) -> float | None:
    """When a task cell's static search must stop (time.time()): PLAN_RESERVE s per candidate
    before the budget's end, at most half of what is left of it."""
    if deadline is None:
        return None
    left = max(deadline - time.time(), 0.0)
    return deadline - min(PLAN_RESERVE * candidates, left / 2)


def _planning(out: Outcome, progress: Callable[..., None] | None) -> Callable[[int, int, str], None] | None:
    """The progress callback told which design is being planned and timed (k of n)."""
    if progress is None:
        return None

    def tick(k: int, n: int, chain: str) -> None:
        status = Status(out.shapes, out.shapes, out.evaluated, out.screened, chain, None,
                        f"planning and timing design {k} of {n}")
        progress(status, True)
    return tick


def _covering(problem: ResolvedProblem, out: Outcome, search, n: int, top: int, seed: int,
              deadline: float | None) -> Outcome:
    """`rank coverage`: the candidates to plan are those that serve every region point when some
    do (coverage 1, the most there is), else those serving at least one (tasks.by_points), and
    only when none serves any, out's (the cell's targets alone: they are then told what they miss).
    search(problem, k, diagnosing): the static search, at one base pose or over the base grid."""
    from . import tasks

    every, names = tasks.with_points(problem, every=True)
    whole = search(_static_screen(every, problem), n, False)
    tasks.restore(whole, names)
    picked = whole if whole.designs or whole.stopped else tasks.by_points(
        problem, lambda s: search(_static_screen(s, problem), top, False), n, seed, lambda: _stopping(deadline))
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


def regions_beyond(problem: ResolvedProblem, hi: int) -> dict[str, float]:
    """`rank coverage` with regions: per region whose every point lies beyond the reach bound of the
    longest arm of at most hi units (screen.reach_bound, from base_link's origin) from every base
    pose, how far its nearest point lies beyond it (m). Sound: no design reaches such a point."""
    if not _optional_points(problem):
        return {}
    import numpy as np

    longest = longest_reach(problem, hi)
    grid = problem.base_grid
    bases = np.array([(0.0, 0.0, 0.0)] if grid is None else grid.positions(), float).reshape(-1, 3)
    out = {}
    for r in problem.cell.regions:
        pts = r.points()
        xyz = np.array([p.xyz for p in pts], float)
        tol = np.array([p.position_tolerance for p in pts], float)
        gap = (np.linalg.norm(xyz[:, None] - bases[None], axis=-1).min(1) - tol - longest).min()
        if gap > 0:
            out[r.name] = float(gap)
    return out


def _optional_points(problem: ResolvedProblem) -> bool:
    """`rank coverage` with regions: the static search screened no region point (but the ends
    of straight paths)."""
    return "coverage" in problem.rank and bool(problem.cell.regions)


# re-exported: the search's outcome and where tests reach the static search (run._search, _tiers,
# _min_mass)
__all__ = ["Outcome", "Status", "_min_mass", "_search", "_tiers", "design", "key", "longest_reach"]
