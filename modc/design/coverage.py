"""The `coverage` objective: the share of the cell's region points a design reaches.

Without `rank coverage` every region point is required (the static search screens them as
targets, modc.design.tasks.with_points). With it, the region points are optional: a design's
coverage is the share of them it reaches within their tolerances, clear of the cell (the
planner's own IK and collision model, modc.plan), its tasks visit the points it reaches (the
others are dropped from the visits of its robot file, which keeps the regions whole) and the
design is ranked by the share, larger first (modc.objectives.coverage)."""
from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

from ..model import ResolvedRobot, Robot


def reached(robot: ResolvedRobot, seed: int, stopping: Callable[[], str | None] | None = None,
            known: Mapping[str, Sequence[float]] | None = None) -> tuple[set[str], int] | None:
    """The names of the region points the robot reaches clear of the cell, and how many there are;
    None when stopping() says to stop (the time budget, Ctrl-C) before every point is tried: a
    region may hold 10,000 points, each an IK run. known: joint values the design search found
    (and verified) at some points, the planner's IK's first start there (its seeds around home
    can miss a pose such as a tool pointing down that the search's seeds found)."""
    from ..physical.checker import CollisionChecker
    from ..plan import clear_solution, start_pose

    points = [p for r in robot.regions for p in r.points()]
    if not points:
        return set(), 0
    checker = CollisionChecker(robot)
    _where, home, _span = start_pose(robot, None)
    got = set()
    for t in points:
        if stopping is not None and stopping():
            return None
        start = home if known is None or t.name not in known else known[t.name]
        if clear_solution(robot, checker, t, start, seed) is not None:
            got.add(t.name)
    return got, len(points)


def served(robot: ResolvedRobot, points: set[str]) -> ResolvedRobot:
    """The robot with its tasks visiting only the region points in `points` (targets stay)."""
    names = {p.name for r in robot.regions for p in r.points()}
    tasks = tuple(t.model_copy(update={"visits": tuple(v for v in t.visits if v not in names or v in points)})
                  for t in robot.tasks)
    return robot.model_copy(update={"tasks": tasks})


def missing_ends(robot: Robot, points: set[str]) -> list[str]:
    """Region points a straight path starts or ends at that the robot does not reach (paths are required)."""
    names = {p.name for r in robot.regions for p in r.points()}
    return [e for p in robot.paths for e in (p.start, p.end) if e in names and e not in points]
