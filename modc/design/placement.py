"""Base placement (`base within box … step … [yaw …]`): the base pose is a design variable.

The design's obstacles, targets and regions are given in the cell frame of the box. For each base
pose of the grid the cell is written in that base's frame (base_link, the frame every robot file
gives its environment in) with `base at` the pose, and the static search runs on it unchanged;
the designs of all poses are merged into one ranking where a design is a (base pose, chain)
pair, one entry per chain: its best pose (ties: the pose searched first). Each design's robot
states its `base at …` and holds the same cell around it, so it compiles, plans and views in the
same world as every other design.

Cheap first: a pose from which some target lies beyond the reach bound of the longest arm in the
bounds is skipped (sound: no chain could reach it from there), so is one where base_link sinks
into the cell whatever the first unit (sound: the exact check would reject every design). The
answer is the best over the grid under the ranking's static objectives, not the first fit:
with fewest modules ranked first, one number of units at a time is searched over every kept pose
(closest cell first), each pose only for shapes that could rank before the `top`-th design found
so far (search()). ranking.json "bases" says how many poses were searched and skipped. The
ranking keeps one entry per chain (its best pose), so it may hold fewer than `top` designs.

Only the designs the merged ranking keeps get their H/L swaps checked (their alternatives, at
their own pose, by the same Verifier.swaps a pose's own search runs): alternatives never change a
design's rank, so checking them for designs a later pose beats only cost exact checks.

Where the time goes (benchmarks/bench_task_base.py): the static search at every pose in reach,
mostly the IK of the settings the bounds keep. With the default ranking (modules, mass, margin)
designs of equal modules and mass are told apart by torque margin, which only the exact check
measures, so each pose in reach is searched for every shape as light as the designs found (the
ceiling prunes nothing where those shapes weigh the same). A sound margin bound skipping a
(shape, pose) would have to hold over every setting the bounds keep there: one shape's settings
span 0.91-0.97 of margin, the poses' designs 0.948-0.960, so it would skip nothing.
"""
from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING, TypeVar

import numpy as np

from ..model import ResolvedProblem, Robot, Transform, resolved
from .rank import Design, order

if TYPE_CHECKING:
    from .run import Outcome


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


_R = TypeVar("_R", bound=Robot)


def cell_at(cell: _R, pose: Transform) -> _R:
    """The cell written in the frame of a base at `pose` (cell frame), with `base at` the pose.

    Regions are axis-aligned boxes: a yawed base keeps them only at yaw 0 (modc.model.lower_task
    refuses `base within … yaw` with regions), so a region moves, it does not turn."""
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
        regions.append(r.model_copy(update={"center": xyz, "rpy": rpy, "pointing": _turn(R, r.pointing)}))
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


def base_blocked(problem: ResolvedProblem, pose: Transform) -> bool:
    """Does base_link, at pose, sink into the cell whatever the first unit (every allowed variant
    and type)? The exact check rejects every design there ("base_link touches the cell"), so
    the pose is not worth a search (sound)."""
    from ..model import UnitSpec
    from ..physical.checker import CollisionChecker
    from . import space

    lib = problem.cell.library
    if not problem.cell.obstacles:
        return False
    cell = cell_at(resolved(problem.cell, lib), pose)
    for v in lib.variants:
        for k in lib.units:
            if not space.allowed(problem, v, k):
                continue
            robot = cell.model_copy(update={"units": (UnitSpec(name=f"{v}{k}", variant=v, kind=k),)})
            if not CollisionChecker(robot).static_contacts():
                return False
    return True


def poses(problem: ResolvedProblem, longest: float) -> tuple[list[Transform], int, int]:
    """The grid's poses worth a search, closest cell first, how many the reach bound ruled out
    and how many base_link's contact with the cell did."""
    grid = problem.base_grid
    assert grid is not None
    cell = problem.cell
    kept = []
    touching = 0
    for i, pose in enumerate(grid.poses()):
        if gap(cell, pose, longest) > 0:
            continue
        if base_blocked(problem, pose):
            touching += 1
            continue
        p = np.asarray(pose.xyz, float)
        far = max((float(np.linalg.norm(np.asarray(t.xyz, float) - p)) for t in points(cell)), default=0.0)
        kept.append((round(far, 9), i, pose))
    kept.sort(key=lambda e: e[:2])
    return [k[2] for k in kept], len(grid.poses()) - len(kept) - touching, touching


def _levels(problem: ResolvedProblem, max_units: int | None) -> list[tuple[int, int]]:
    """Ranges of units searched one after the other over every pose: one number of units at a
    time when the ranking puts fewest modules first, else the whole range at once."""
    lib = problem.cell.library
    lo, hi = max(problem.min_units, lib.rules.min_dof), min(max_units or problem.max_units, lib.rules.max_dof)
    if problem.rank[:2] == ("modules", "mass"):
        return [(n, n) for n in range(lo, hi + 1)]
    return [(lo, hi)]


def search(problem: ResolvedProblem, max_units: int | None, top: int, longest: float,
           one: Callable[..., Outcome], ties: bool = True) -> Outcome:
    """The merged outcome of one(sub_problem, max_units, top, ceiling, diagnosing) over the kept
    base poses: the best (pose, chain) designs of the grid under the ranking's static objectives.

    Fewest modules first, a number of units at a time over every pose (nearest first), and at
    each pose only the shapes that could rank before the `top`-th design found so far (the
    ceiling: fewer modules, or as many and lighter; with `ties`, as light too, when a later
    objective may still tell them apart); a number of units is searched only while fewer than
    `top` designs are found. So a pose is skipped only where no chain could beat what is found."""
    from .run import Outcome

    kept, pruned, touching = poses(problem, longest)
    outs: list[Outcome] = []
    at: dict[int, ResolvedProblem] = {}  # id(design) -> its pose's problem (outs keeps every design alive)
    searched: set[int] = set()
    designs: list[Design] = []
    levels = _levels(problem, max_units)
    by_level = problem.rank[:2] == ("modules", "mass")
    stopped = None
    for lo, hi in levels:
        for i, pose in enumerate(kept):
            ceiling = None
            if by_level and len(designs) >= top:
                d = designs[top - 1]
                ceiling = (d.modules, d.mass, ties)
                if d.modules < lo:
                    break  # every chain of this number of units has more modules than the top designs
            sub = problem.model_copy(update={"cell": cell_at(problem.cell, pose), "base_grid": None,
                                             "min_units": lo, "max_units": hi})
            o = one(sub, hi, top, ceiling, False, swaps=False)
            outs.append(o)
            at.update((id(d), sub) for d in o.designs)
            searched.add(i)
            designs = _best_per_chain(designs + list(o.designs), problem.rank)
            stopped = stopped or o.stopped
            if stopped:
                break
        if stopped or (by_level and len(designs) >= top):
            break
    diagnosis = None
    if not designs and kept and not stopped:  # why none: the nearest pose's search, told per target
        diagnosis = one(problem.model_copy(update={"cell": cell_at(problem.cell, kept[0]), "base_grid": None}),
                        max_units, top)
    out = Outcome(problem, [_swaps(at[id(d)], top, d) for d in designs[:top]])
    out.bases_searched, out.bases_pruned, out.bases_total = len(searched), pruned, len(kept) + pruned + touching
    out.bases_touching = touching
    names = [t.name for t in problem.cell.targets]
    out.closest = {t: min((o.closest.get(t, math.inf) for o in outs), default=math.inf) for t in names}
    if not outs:  # every pose ruled out by reach: how far the nearest pose leaves the cell
        grid = problem.base_grid
        assert grid is not None
        short = min(gap(problem.cell, p, longest) for p in grid.poses())
        out.closest = dict.fromkeys(names, max(short, 0.0))
    for o in outs:
        out.evaluated += o.evaluated
        out.shapes += o.shapes
        out.screened += o.screened
        out.excluded += o.excluded
        out.dominated += o.dominated
        out.rejections += o.rejections
        out.complete &= o.complete
        out.stopped = out.stopped or o.stopped
        out.unfinished += [s for s in o.unfinished if s not in out.unfinished]
        out.coarse += [s for s in o.coarse if s not in out.coarse]
    if diagnosis is not None:
        out.targets = diagnosis.targets
    return out


def _swaps(sub: ResolvedProblem, top: int, d: Design) -> Design:
    """d with its other H/L splits checked at its pose (as the pose's own search would have):
    only for the designs the merged ranking keeps."""
    from .run import _mass
    from .verify_order import Verifier

    return Verifier(sub, top, None, _mass).swaps(d)


def _best_per_chain(designs: list[Design], objectives: tuple[str, ...]) -> list[Design]:
    seen: set[str] = set()
    out = []
    for d in order(designs, objectives):  # stable: of equal designs, the pose searched first
        if d.chain() not in seen:
            seen.add(d.chain())
            out.append(d)
    return out
