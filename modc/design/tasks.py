"""The cell's tasks and paths for the designs the static search returns: each design's robot
(the cell's tasks, regions and paths included) planned and timed with modc.plan.task, the one
planner of `modc plan --task`. A design whose task cannot be planned or timed is rejected, the
reason recorded with the other rejections. Planning costs seconds per design, so it runs only
for the designs that passed the cheap screens and the exact check."""
from __future__ import annotations

import time
from dataclasses import replace

from .rank import TASK, Design, order

PLAN_FACTOR = 3  # designs the static search returns per design asked for when a task objective ranks
# and at least this many: arms of equal modules and mass differ by seconds of cycle time (a 12-point
# tray: 2.2 s to 11.8 s), and planning one costs about 2 s once the search stops at the shape
# where they are found
MIN_PLANNED = 6
POINT_SEARCHES = 16  # `rank coverage` with no design serving every point: points searched one at a time


def has_tasks(problem) -> bool:
    return bool(problem.cell.tasks or problem.cell.paths)


def candidates(problem, top: int) -> int:
    """How many designs the static search should return: more than `top` when a task objective
    ranks (the static order does not know which arm is fastest)."""
    return max(top * PLAN_FACTOR, MIN_PLANNED) if any(o in TASK for o in problem.rank) else top


def task_names(robot) -> list[str]:
    return [t.name for t in (*robot.tasks, *robot.paths)]


def with_points(problem, every: bool = False, only: str | None = None):
    """The problem whose cell also holds every region point as a target when every point is
    required (no `rank coverage`, or `every`), so that the static search screens them; and the
    names given to them (a point's own name, `tray[1,0,0]`, is no identifier), new name -> point
    name. only: that one point (its name, as `tray[1,0,0]`) of the regions, no other. With `rank
    coverage` the points a straight path starts or ends at stay required (a path is: a design
    that misses its end fails its planning, modc.design.coverage.missing_ends)."""
    cell = problem.cell
    taken = {t.name for t in cell.targets} | {r.name for r in cell.regions} | set(task_names(cell))
    names: dict[str, str] = {}
    extra = _path_points(cell, taken, names)
    if not cell.regions:
        return _with(problem, extra), names
    wanted = None if only is None else {only}
    if "coverage" in problem.rank and not every:
        wanted = (wanted or set()) | {e for p in cell.paths for e in (p.start, p.end)}
    for r in cell.regions:
        for ix in r.indices():
            if wanted is not None and r.point_name(ix) not in wanted:
                continue
            stem = f"{r.name}_{ix[0]}_{ix[1]}_{ix[2]}"[:60]
            name, k = stem, 2
            while name in taken:
                name, k = f"{stem}_{k}", k + 1
            taken.add(name)
            names[name] = r.point_name(ix)
            extra.append(r.point(ix).model_copy(update={"name": name}))
    return _with(problem, extra), names


def _with(problem, extra: list):
    if not extra:
        return problem
    cell = problem.cell
    return problem.model_copy(update={"cell": cell.model_copy(update={"targets": cell.targets + tuple(extra)})})


PATH_POINTS = 3  # points inside a straight path screened as targets: at 1/4, 2/4 and 3/4 of the way


def _path_points(cell, taken: set[str], names: dict[str, str]) -> list:
    """Points inside each straight path, as position targets with the tighter tolerance of its
    ends: an arm that keeps tool0 on the segment reaches each of them, so screening them is a
    sound filter, and it keeps the arms that stand at both ends only folded another way (which
    no planning can join) from taking every candidate's place. Named `seam_1_of_4`, told as
    `seam at 1/4`."""
    import numpy as np

    out = []
    for path in cell.paths:
        a, b = cell.task_target(path.start), cell.task_target(path.end)
        if a is None or b is None:
            continue
        tol = min(a.position_tolerance, b.position_tolerance)
        n = PATH_POINTS + 1
        for k in range(1, n):
            stem = f"{path.name}_{k}_of_{n}"[:60]
            name, j = stem, 2
            while name in taken:
                name, j = f"{stem}_{j}", j + 1
            taken.add(name)
            names[name] = f"{path.name} at {k}/{n}"
            xyz = tuple(float(x) for x in np.asarray(a.xyz) + (np.asarray(b.xyz) - np.asarray(a.xyz)) * k / n)
            out.append(a.model_copy(update={"name": name, "xyz": xyz, "rpy": None, "pointing": None,
                                            "position_tolerance": tol}))
    return out


def restore(out, names: dict[str, str]) -> None:
    """The outcome of a search on with_points' problem, told in the cell's names: each design's
    robot without the region points as targets (its regions hold them), its figures under the
    points' names."""
    if not names:
        return
    out.designs = [replace(d, verified=told(d.verified, names)) for d in out.designs]
    out.closest = {names.get(k, k): x for k, x in out.closest.items()}
    out.targets = {names.get(k, k): x for k, x in out.targets.items()}


def told(v, names: dict[str, str]):
    """A verified design (evaluate.Verified) of with_points' problem in the cell's names: its robot
    without the region points as targets and poses, its figures under the points' names."""
    from .evaluate import pose_name

    drop = set(names) | {pose_name(n) for n in names}
    robot = v.robot.model_copy(update={"targets": tuple(t for t in v.robot.targets if t.name not in drop),
                                       "poses": tuple(p for p in v.robot.poses if p.name not in drop)})
    return replace(v, robot=robot, targets={names.get(k, k): x for k, x in v.targets.items()})


def by_points(problem, search, n: int, seed: int, stopping=None):
    """`rank coverage` when no design serves every region point: the static designs that reach
    the cell's targets and at least one point - searched point by point (`search(screen)`: the
    static search's Outcome; at most POINT_SEARCHES points), merged one per chain - most points
    reached first (modc.plan's IK, clear of the cell: coverage.reached), then fewest modules and
    least mass; the first n of them, to be planned. An outcome of the last search carries them
    (its counts summed)."""
    from . import coverage as cov

    every = [p.name for r in problem.cell.regions for p in r.points()]
    # one static search each: at most POINT_SEARCHES of them, spread evenly over the points (a
    # region may hold 10,000)
    step = max(1, -(-len(every) // POINT_SEARCHES))
    points = every[::step]
    seen: dict[str, Design] = {}
    out = None
    for name in points:
        screen, names = with_points(problem, only=name)
        o = search(screen)
        restore(o, names)
        if out is not None:
            o.evaluated, o.excluded = o.evaluated + out.evaluated, o.excluded + out.excluded
            o.rejections = out.rejections + o.rejections
        out = o
        for d in o.designs:
            seen.setdefault(d.chain(), d)
        if o.stopped:
            break
    if out is None:
        return None
    scored = []
    for d in seen.values():
        measured = cov.reached(d.verified.robot, seed, stopping, known(d))
        if measured is None:  # out of time: rank the designs measured so far
            out.stopped = out.stopped or stopping()
            break
        got, total = measured
        share = len(got) / max(total, 1)
        scored.append((-len(got), d.modules, round(d.mass, 9), d.chain(), replace(d, coverage=share)))
    out.designs = [x[-1] for x in sorted(scored, key=lambda x: x[:4]) if x[0] < 0][:n]
    return out


def known(d: Design) -> dict[str, list[float]]:
    """The joint values the search verified d at, by target or region point name."""
    return {name: x["q"] for name, x in d.verified.targets.items() if x.get("q") is not None}


def plan_design(d: Design, seed: int, deadline: float | None, coverage: bool = False, stopping=None,
                failed: list[str] | None = None) -> Design | str | None:
    """d with its plans, or why one of its tasks cannot be planned (its name appended to `failed`),
    or None when stopping() said to stop while its coverage was measured. With `coverage`, the
    region points it does not reach are dropped from its tasks and its coverage recorded."""
    from ..plan.errors import PlanError
    from ..plan.task import plan_task_robot
    from . import coverage as cov

    robot = d.verified.robot
    if coverage and robot.regions:
        measured = cov.reached(robot, seed, stopping, known(d))
        if measured is None:
            return None
        points, total = measured
        if not points:
            return "reaches no point of the cell's regions"
        missing = cov.missing_ends(robot, points)
        if missing:
            return f"a straight path ends at region point {missing[0]}, which it does not reach"
        robot = cov.served(robot, points)
        d = replace(d, coverage=len(points) / total, verified=replace(d.verified, robot=robot))
    plans = []
    for name in task_names(robot):
        left = None if deadline is None else max(deadline - time.time(), 1.0)
        try:
            plans.append(plan_task_robot(robot, name, seed=seed, timeout=left))
        except PlanError as e:
            if failed is not None:
                failed.append(name)
            kind = "path" if any(p.name == name for p in robot.paths) else "task"
            return f"{kind} '{name}' cannot be planned ({e.code}: {e.message})"
    return replace(d, plans=tuple(plans))


def plan_all(out, top: int, seed: int, deadline: float | None, stopping,
             rejected: dict[str, tuple[str, str | None]] | None = None, tick=None) -> None:
    """Plan every design of the outcome, drop those that fail, rank by the problem's objectives
    (the task objectives now known) and keep `top`. rejected: chain -> (why, the task that could
    not be planned), for chains already planned in vain (not planned again; filled here).
    out.failed_on counts, per task, the chains that could not be planned on it; tick(k, n, chain)
    is told each design before it is planned (progress)."""
    rejected = {} if rejected is None else rejected
    kept = []
    for k, d in enumerate(out.designs):
        if tick is not None:
            tick(k + 1, len(out.designs), d.chain())
        why = stopping(deadline)
        if why:
            out.stopped = out.stopped or why
            out.not_planned = [x.chain() for x in out.designs[k:]]
            break
        if d.chain() not in rejected:
            failed: list[str] = []
            p = plan_design(d, seed, deadline, "coverage" in out.problem.rank, lambda: stopping(deadline), failed)
            if p is None:
                out.stopped = out.stopped or stopping(deadline)
                out.not_planned = [x.chain() for x in out.designs[k:]]
                break
            if not isinstance(p, str):
                kept.append(p)
                continue
            rejected[d.chain()] = (p, failed[0] if failed else None)
        why, task = rejected[d.chain()]  # planned in vain, now or in an earlier round (not planned again)
        out.rejections.append(f"{'-'.join(u.name for u in d.verified.robot.units)}: {why}")
        if task is not None:
            out.failed_on[task] = out.failed_on.get(task, 0) + 1
    out.designs = order(kept, out.problem.rank)[:top]
    out.complete = out.complete and not out.not_planned
