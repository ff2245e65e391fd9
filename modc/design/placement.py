"""Base placement (`base within box … step … [yaw …]`): the base pose is a design variable.

The design's obstacles, targets and regions are given in the cell frame of the box. For each base
pose of the grid the cell is written in that base's frame (base_link, the frame every robot file
gives its environment in) with `base at` the pose; each design's robot states its `base at …` and
holds the same cell around it, so it compiles, plans and views in the same world as every other.

Cheap first: a pose from which some target lies beyond the reach bound of the longest arm in the
bounds is skipped (sound: no chain could reach it from there), so is one where base_link sinks
into the cell whatever the first unit (sound: the exact check would reject every design; one
base_link checker per variant and type serves every pose, its obstacles moved).
The poses kept are searched together (modc.design.grid): a shape's candidates are (twist
setting, pose) pairs, ranked within the shape as one pose's settings are, then nearest pose
first, and the shape gives one design over the grid, at its setting's best pose. The answer is
the best design over the grid under the ranking's static objectives, not the first fit.
ranking.json "bases" says how many poses were searched and skipped.

Only the designs kept get their H/L swaps checked (their alternatives, at their own pose, by the
same Verifier.swaps a pose's own search runs).

Where the time goes (benchmarks/bench_task_base.py): the IK of the settings the bounds keep at
every pose in reach. A shape that works somewhere closes, at every pose, once its kept settings
are all dead on (dominance over the grid: usually after two nonzero twists); a shape that works
nowhere is screened at every pose in reach, each setting the family and per-setting bounds leave.
On benchmarks/bench_task_base.py's cell (27 Nov 2026, one core, compiled IK): one pose 0.15-0.3 s,
25 poses 2.0-2.7 s CPU (ratio 9-15; the goal is 5); the screen's retry inside the tolerance
(evaluate.clear_within) costs ~10-20 % of it there and changes no design.
"""
from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, TypeVar

import numpy as np

from ..model import ResolvedProblem, Robot, Transform, resolved
from .rank import Design

if TYPE_CHECKING:
    from .outcome import Outcome


def _frame(pose: Transform) -> tuple[np.ndarray, np.ndarray]:
    from ..kinematics import rpy_matrix

    return rpy_matrix(pose.rpy), np.asarray(pose.xyz, float)


Vec = tuple[float, float, float]


def _to_base(R: np.ndarray, p: np.ndarray, xyz, rpy) -> tuple[Vec, Vec | None]:
    """A cell-frame position (and orientation) in the base frame of pose (R, p)."""
    from ..kinematics import matrix_rpy, rpy_matrix

    x = R.T @ (np.asarray(xyz, float) - p)
    xyz_b = (float(x[0]), float(x[1]), float(x[2]))
    if rpy is None:
        return xyz_b, None
    return xyz_b, matrix_rpy(R.T @ rpy_matrix(rpy))


def _turn(R: np.ndarray, d) -> Vec | None:
    """A cell-frame direction in the base frame."""
    if d is None:
        return None
    v = R.T @ np.asarray(d, float)
    return (float(v[0]), float(v[1]), float(v[2]))


def _box(R: np.ndarray, turned: Vec | None) -> Vec | None:
    """A region box's axes (rpy in the cell frame, None: the cell's) in the base frame."""
    from ..kinematics import matrix_rpy, rpy_matrix

    R_base_box = R.T @ rpy_matrix(turned if turned is not None else (0.0, 0.0, 0.0))
    if np.allclose(R_base_box, np.eye(3), rtol=0.0, atol=1e-12):
        return None
    return matrix_rpy(R_base_box)


_R = TypeVar("_R", bound=Robot)


def cell_at(cell: _R, pose: Transform) -> _R:
    """The cell written in the frame of a base at `pose` (cell frame), with `base at` the pose.

    A region's box turns with the base: `turned` is its axes in the base frame (None when they
    are the base frame's, so a region at yaw 0 stays as written), and its points are the same
    points of the cell."""
    R, p = _frame(pose)
    obstacles = []
    for o in cell.obstacles:
        xyz, rpy = _to_base(R, p, o.origin.xyz, o.origin.rpy)
        assert rpy is not None
        obstacles.append(o.model_copy(update={"origin": Transform(xyz=xyz, rpy=rpy)}))
    targets = []
    for t in cell.targets:
        xyz, rpy = _to_base(R, p, t.xyz, t.rpy)
        targets.append(t.model_copy(update={"xyz": xyz, "rpy": rpy, "pointing": _turn(R, t.pointing)}))
    regions = []
    for r in cell.regions:
        xyz, rpy = _to_base(R, p, r.center, r.rpy)
        regions.append(r.model_copy(update={"center": xyz, "rpy": rpy, "pointing": _turn(R, r.pointing),
                                            "turned": _box(R, r.turned)}))
    return cell.model_copy(update={"base": pose, "obstacles": tuple(obstacles), "targets": tuple(targets),
                                   "regions": tuple(regions)})


def points(cell: Robot) -> list:
    """Every position the arm must reach: targets and region points."""
    return [*cell.targets, *(p for r in cell.regions for p in r.points())]


def gap(cell: Robot, pose: Transform, longest: float) -> float:
    """m by which the farthest point of the cell lies beyond `longest` from a base at pose (<= 0: none)."""
    p = np.asarray(pose.xyz, float)
    return max((float(np.linalg.norm(np.asarray(t.xyz, float) - p)) - t.position_tolerance - longest
                for t in points(cell)), default=-1.0)


def base_blocked(problem: ResolvedProblem, pose: Transform, checkers: dict | None = None) -> bool:
    """Does base_link, at pose, sink into the cell whatever the first unit (every allowed variant
    and type)? The exact check rejects every design there ("base_link touches the cell"), so
    the pose is not worth a search (sound). checkers: one CollisionChecker per (variant, type)
    kept across the poses of a grid, its obstacles moved to each pose (base_link's geometry does
    not depend on the pose; the obstacles' placements are what a checker built at the pose
    would hold: the same decision for a fraction of the cost)."""
    from ..model import UnitSpec
    from ..physical.checker import CollisionChecker
    from . import space

    lib = problem.cell.library
    if not problem.cell.obstacles:
        return False
    cell = cell_at(resolved(problem.cell, lib), pose)
    checkers = {} if checkers is None else checkers
    for v in lib.variants:
        for k in lib.units:
            if not space.allowed(problem, v, k):
                continue
            checker = checkers.get((v, k))
            if checker is None:
                robot = cell.model_copy(update={"units": (UnitSpec(name=f"{v}{k}", variant=v, kind=k),)})
                checker = checkers[(v, k)] = CollisionChecker(robot)
            else:
                _move_obstacles(checker, cell.obstacles)
            if not checker.static_contacts():
                return False
    return True


def _move_obstacles(checker, obstacles) -> None:
    """Place a checker's obstacles (static model, the one static_contacts tests) as `obstacles`
    (the same names and shapes, in another base frame)."""
    from ..physical.multibody import obstacle_geometry

    at = {o.name: o for o in obstacles}
    for go in checker.gm_static.geometryObjects:
        if go.name.startswith("obstacle:"):
            go.placement = obstacle_geometry(at[go.name[len("obstacle:"):]])[1]


def poses(problem: ResolvedProblem, longest: float) -> tuple[list[Transform], int, int]:
    """The grid's poses worth a search, closest cell first, how many the reach bound ruled out
    and how many base_link's contact with the cell did."""
    grid = problem.base_grid
    assert grid is not None
    cell = problem.cell
    kept = []
    touching = 0
    checkers: dict = {}
    for i, pose in enumerate(grid.poses()):
        if gap(cell, pose, longest) > 0:
            continue
        if base_blocked(problem, pose, checkers):
            touching += 1
            continue
        p = np.asarray(pose.xyz, float)
        far = max((float(np.linalg.norm(np.asarray(t.xyz, float) - p)) for t in points(cell)), default=0.0)
        kept.append((round(far, 9), i, pose))
    kept.sort(key=lambda e: e[:2])
    return [k[2] for k in kept], len(grid.poses()) - len(kept) - touching, touching


def search(problem: ResolvedProblem, max_units: int | None, top: int, longest: float,
           one: Callable[..., Outcome], many: Callable[..., Outcome]) -> Outcome:
    """The best (pose, chain) designs of the grid under the ranking's static objectives:
    many(problem, cells, max_units, top) searches every kept pose at once (modc.design.grid: a
    shape's settings at every pose, one design per shape at its best pose); one(sub_problem,
    max_units, top) at the nearest pose says why when no design is found."""
    from .outcome import Outcome

    kept, pruned, touching = poses(problem, longest)
    subs = [problem.model_copy(update={"cell": cell_at(problem.cell, pose), "base_grid": None}) for pose in kept]
    out = many(problem, subs, max_units, top) if subs else Outcome(problem, [])
    out.designs = [_swaps(_at(subs, d), top, d) for d in out.designs]
    out.bases_searched, out.bases_pruned, out.bases_total = len(kept), pruned, len(kept) + pruned + touching
    out.bases_touching = touching
    out.bases_kept = kept
    names = [t.name for t in problem.cell.targets]
    if not subs:  # every pose ruled out by reach: how far the nearest pose leaves the cell
        grid = problem.base_grid
        assert grid is not None
        short = min(gap(problem.cell, p, longest) for p in grid.poses())
        out.closest = dict.fromkeys(names, max(short, 0.0))
    elif not out.designs and not out.stopped:  # why none: the nearest pose's search, told per target
        out.targets = one(subs[0], max_units, top).targets
    return out


def _at(subs: list[ResolvedProblem], d: Design) -> ResolvedProblem:
    """The pose's problem a design was checked in (its robot's base, read back from its text)."""
    b = d.verified.robot.base
    return min(subs, key=lambda s: float(np.abs(np.subtract(s.cell.base.xyz, b.xyz)).sum()
                                         + np.abs(np.subtract(s.cell.base.rpy, b.rpy)).sum()))


def _swaps(sub: ResolvedProblem, top: int, d: Design) -> Design:
    """d with its other H/L splits checked at its pose (as the pose's own search would have):
    only for the designs the merged ranking keeps."""
    from .sweep import _mass
    from .verify_order import Verifier

    return Verifier(sub, top, None, _mass).swaps(d)
