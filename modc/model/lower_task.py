"""Lowering of the task statements (docs/language.md): `region`, `task`, `path`, `base within`.

Regions and the base grid are checked alone (sizes, counts, steps); tasks and paths once the
block's targets and regions are known (every name resolves to a target or a region point, and
names of targets, regions, tasks and paths are unique).
"""
from __future__ import annotations

import math

from ..diagnostics import codes
from ..syntax import ast
from .robot import MAX_REGION_POINTS, BaseGrid, Region, StraightPath, Task

MAX_BASE_POSES = 1_000  # a base grid finer than this multiplies the design search beyond use
MIN_BASE_STEP = 1e-3  # m: finer than a millimetre is no placement a cell can hold
MIN_YAW_STEP = math.radians(0.5)


def _tolerances(low, within: ast.Within | None, what: str) -> dict[str, float]:
    tol: dict[str, float] = {}
    if within is None:
        return tol
    pairs = (("position_tolerance", within.position, "a length"), ("orientation_tolerance", within.orientation,
                                                                   "an angle"))
    for key, q, kind in pairs:
        if q is None:
            continue
        v = low.quantity(q, kind, f"{key.replace('_', ' ')} of {what}")
        if v is not None and v <= 0:
            low.error(codes.NONPOSITIVE_SIZE.at(q.span, what=f"the {key.replace('_', ' ')} of {what}",
                                                value=f"{q.value:g} {q.unit}"))
        elif v is not None:
            tol[key] = v
    return tol


def region(low, st: ast.Region) -> Region | None:
    what = f"region '{st.name.text}'"
    size = low.vec3(st.size, "a length", f"size of {what}")
    at = low.vec3(st.at, "a length", f"position of {what}")
    rpy = low.vec3(st.rpy, "an angle", f"orientation of {what}") if st.rpy is not None else None
    turned = low.vec3(st.turned, "an angle", f"turn of the box of {what}") if st.turned is not None else None
    tol = _tolerances(low, st.within, what)
    pointing = direction(low, st.pointing, f"approach of {what}")
    ok = st.pointing is None or pointing is not None
    grid: list[int] = []
    for axis, q in zip("xyz", st.grid, strict=True):
        if q.value != int(q.value) or q.value < 1:
            low.error(codes.REGION_GRID.at(q.span, what=f"the grid of {what} needs a whole number of points >= 1 "
                                                         f"along {axis}, got {q.value:g}",
                                           hint="write e.g. `grid 3 x 2 x 1`"))
        else:
            grid.append(int(q.value))
    ok = ok and len(grid) == 3
    if ok and math.prod(grid) > MAX_REGION_POINTS:
        low.error(codes.REGION_GRID.at(st.span, what=f"{what} has {math.prod(grid):,} points, more than "
                                                     f"{MAX_REGION_POINTS:,}",
                                       hint="use a coarser grid: each point is a target to plan for"))
        ok = False
    if ok and size is not None:
        for axis, s, n in zip("xyz", size, grid, strict=True):
            if s < 0:
                low.error(codes.NONPOSITIVE_SIZE.at(st.size.span, what=f"the size of {what} along {axis}",
                                                    value=f"{s:g} m"))
                ok = False
            elif s == 0 and n > 1:
                low.error(codes.REGION_GRID.at(st.span, what=f"{what} has size 0 along {axis} but {n} points there",
                                               hint=f"give the box a size along {axis}, or 1 point (its centre)"))
                ok = False
    if not low.name(st.name, "region") or not ok or size is None or at is None or (st.rpy is not None and rpy is None) \
            or (st.turned is not None and turned is None):
        return None
    return Region(name=st.name.text, size=size, center=at, grid=(grid[0], grid[1], grid[2]), rpy=rpy,
                  pointing=pointing, turned=_turn(turned), span=st.span, **tol)


def _turn(rpy: tuple[float, float, float] | None) -> tuple[float, float, float] | None:
    """`turned (0, 0, 0) deg` is no turn: the model holds None, so such a region is written as an
    axis-aligned one (a region the base grid turns by a yaw of 0 stays byte-identical)."""
    return None if rpy is None or not any(rpy) else rpy


def direction(low, v: ast.Vector | None, what: str) -> tuple[float, float, float] | None:
    """`pointing (0, 0, -1)`: a direction, no unit, any non-zero length (normalised)."""
    if v is None:
        return None
    if v.unit is not None:
        low.error(codes.WRONG_UNIT.at(v.span, what=what, kind="a direction without a unit", unit=v.unit,
                                      allowed="none (write e.g. `pointing (0, 0, -1)`)"))
        return None
    if len(v.values) != 3:
        low.error(codes.VECTOR_ARITY.at(v.span, what=what, expected=3, got=len(v.values), example="(0, 0, -1)"))
        return None
    n = math.sqrt(sum(x * x for x in v.values))
    if not math.isfinite(n) or n < 1e-9:
        low.error(codes.NONPOSITIVE_SIZE.at(v.span, what=f"the length of the {what}", value="0"))
        return None
    return (v.values[0] / n, v.values[1] / n, v.values[2] / n)


def base_grid(low, st: ast.BaseWithin) -> BaseGrid | None:
    """The base grid (a yawed base turns the regions' boxes in each emitted robot's base_link:
    `turned`, modc.design.placement.cell_at)."""
    size = low.vec3(st.size, "a length", "size of the base's box")
    at = low.vec3(st.at, "a length", "position of the base's box")
    step = low.quantity(st.step, "a length", "base step")
    yaws = _yaws(low, st.yaw)
    if size is None or at is None or step is None or yaws is None:
        return None
    if any(s < 0 for s in size):
        low.error(codes.NONPOSITIVE_SIZE.at(st.size.span, what="every size of the base's box",
                                            value=", ".join(f"{s:g} m" for s in size)))
        return None
    if step < MIN_BASE_STEP:
        low.error(codes.DESIGN_BOUND.at(st.step.span,
                                        what=f"the base step must be at least {MIN_BASE_STEP * 1000:g} mm",
                                        hint="e.g. `base within box size (0.2, 0.2, 0) m at (0, 0, 0) m step 50 mm`"))
        return None
    grid = BaseGrid(size=size, center=at, step=step, yaws=yaws, span=st.span)
    n = math.prod(int(s / step + 1e-9) + 1 for s in size) * len(yaws)
    if n > MAX_BASE_POSES:
        low.error(codes.DESIGN_BOUND.at(st.span, what=f"{n:,} base poses are too many to search",
                                        hint=f"use a coarser step or a smaller box: at most {MAX_BASE_POSES:,} poses"))
        return None
    return grid


def _yaws(low, r: ast.Range | None) -> tuple[float, ...] | None:
    if r is None:
        return (0.0,)
    # `yaw 0 to 90 deg`: the low end shares the high end's unit
    lo_q = r.low if r.low.unit is not None else ast.Quantity(r.low.value, r.high.unit, r.low.span)
    lo = low.quantity(lo_q, "an angle", "lowest yaw")
    hi = low.quantity(r.high, "an angle", "highest yaw")
    step = low.quantity(r.step, "an angle", "yaw step")
    if lo is None or hi is None or step is None:
        return None
    if hi < lo:
        low.error(codes.DESIGN_BOUND.at(r.span, what="the yaw range is empty", hint="write `yaw LOWEST to HIGHEST`"))
        return None
    if step < MIN_YAW_STEP:
        low.error(codes.DESIGN_BOUND.at(r.step.span, what="the yaw step must be at least 0.5 deg",
                                        hint="e.g. `yaw 0 to 90 deg step 45 deg`"))
        return None
    n = int((hi - lo) / step + 1e-9) + 1
    return tuple(lo + k * step for k in range(n))


def _known(targets, regions) -> str:
    names = [t.name for t in targets] + [f"{r.name} (region)" for r in regions]
    return "targets: " + ", ".join(names) if names else "declare it first: `target NAME at (x, y, z) m`"


def _resolve(low, ref: ast.PointRef, kind: str, name: str, targets, regions, bad=frozenset()) -> list[str] | None:
    """The point names a reference stands for: a target, a region's points, or one point."""
    text = ref.name.text
    r = next((r for r in regions if r.name == text), None)
    t = next((t for t in targets if t.name == text), None)
    why = None
    if r is None and t is None and text in bad:  # a region with errors of its own
        return None
    if ref.index is None and t is not None:
        return [t.name]
    if ref.index is None and r is not None:
        return [r.point_name(ix) for ix in r.indices()]
    if r is None:
        why = "which is no target or region of the block" if t is None else f"but target '{text}' has no points"
    else:
        ix = tuple(q.value for q in ref.index or ())
        if all(v == int(v) and 0 <= v < n for v, n in zip(ix, r.grid, strict=True)):
            return [r.point_name((int(ix[0]), int(ix[1]), int(ix[2])))]
        nx, ny, nz = r.grid
        why = f"outside the region's grid (indices from 0 to [{nx - 1},{ny - 1},{nz - 1}])"
    low.error(codes.UNKNOWN_TASK_TARGET.at(ref.span, kind=kind, name=name, ref=ref.text, why=why,
                                           known=_known(targets, regions)))
    return None


def _same_place(a: str, b: str, targets, regions) -> bool:
    """Two task stops at one position (a name twice, or two targets or points that coincide)."""
    if a == b:
        return True
    where = {t.name: t.xyz for t in targets}
    for r in regions:
        where.update({p.name: p.xyz for p in r.points()})
    pa, pb = where.get(a), where.get(b)
    return pa is not None and pb is not None and max(abs(x - y) for x, y in zip(pa, pb, strict=True)) < 1e-9


def tasks(low, statements: list, targets, regions, block: str,
          bad=frozenset()) -> tuple[tuple[Task, ...], tuple[StraightPath, ...]]:
    """Tasks and paths with every reference resolved; names unique among targets, regions,
    tasks and paths (duplicates among targets alone are check_names' business)."""
    seen = {t.name for t in targets}
    for r in regions:
        if r.name in seen:
            low.error(codes.DUPLICATE_NAME.at(r.span, name=r.name, block=block))
        seen.add(r.name)
    out_tasks: list[Task] = []
    out_paths: list[StraightPath] = []
    for st in statements:
        if st.name.text in seen:
            low.error(codes.DUPLICATE_NAME.at(st.span, name=st.name.text, block=block))
            continue
        seen.add(st.name.text)
        if isinstance(st, ast.Task):
            visits = [_resolve(low, ref, "task", st.name.text, targets, regions, bad) for ref in st.visits]
            if low.name(st.name, "task") and None not in visits:
                stops = tuple(p for v in visits if v for p in v)
                if len(stops) < 2:
                    low.error(codes.TASK_NO_MOTION.at(st.span, kind="task", name=st.name.text,
                                                      why="it visits one place"))
                out_tasks.append(Task(name=st.name.text, visits=stops, span=st.span))
        else:
            ends = [_resolve(low, ref, "path", st.name.text, targets, regions, bad) for ref in (st.start, st.end)]
            for ref, e in zip((st.start, st.end), ends, strict=True):
                if e is not None and len(e) != 1:
                    low.error(codes.UNKNOWN_TASK_TARGET.at(ref.span, kind="path", name=st.name.text, ref=ref.text,
                                                           why="a region: a path goes from one point to another",
                                                           known=f"name one of its points, e.g. {e[0]}"))
                    ends = [None]
            if low.name(st.name, "path") and all(e is not None and len(e) == 1 for e in ends):
                a, b = ends
                assert a is not None and b is not None
                if _same_place(a[0], b[0], targets, regions):
                    low.error(codes.TASK_NO_MOTION.at(st.span, kind="path", name=st.name.text,
                                                      why=f"'{a[0]}' and '{b[0]}' are one point"))
                out_paths.append(StraightPath(name=st.name.text, start=a[0], end=b[0], span=st.span))
    return tuple(out_tasks), tuple(out_paths)
