"""Base placement's shared work over the poses of a grid: the family bounds of a shape at every
pose in one pass (prefix.refine_many) and one base_link checker per (variant, type) moved from
pose to pose (placement.base_blocked) decide exactly what the per-pose work decides."""
from __future__ import annotations

import numpy as np
import pytest
from conftest import THREE_TARGETS

from modc.compiler import check_text

CELL = THREE_TARGETS.replace("    units 2 to 3\n", "    units 2 to 3\n    base within box size (0.2, 0.2, 0) m at "
                            "(0, 0, 0) m step 100 mm yaw 0 to 90 deg step 45 deg\n")


def problem(text: str = CELL):
    checked = check_text(text, "cell.mod")
    assert checked.ok, [d.message for d in checked.diagnostics]
    return checked.design.problems[0]


def _specs(p):
    from modc.design import placement
    from modc.design.evaluate import Spec

    return [Spec.of(p.model_copy(update={"cell": placement.cell_at(p.cell, pose), "base_grid": None}))
            for pose in p.base_grid.poses()]


def _same(a, b) -> bool:
    return a.depth == b.depth and a.per == b.per and np.array_equal(a.alive, b.alive)


@pytest.mark.parametrize("cap, every", [(200_000, 4), (3_000, 1)])
def test_the_family_bounds_of_every_pose_at_once_are_each_poses_own(cap, every):
    """Yawed and shifted poses (their targets differ in the base frame), 2- and 3-unit shapes; a
    small cap makes poses stop refining at different depths."""
    from modc.design import grid, prefix, space

    p = problem()
    specs = _specs(p)
    assert len(specs) == 27
    specs = specs[::every]
    assert len({s.problem.cell.base.rpy for s in specs}) == 3
    shapes = [s for n in (2, 3) for s in space.shapes(p, n)][::5 * every]
    depths = set()
    for shape in shapes:
        lv = grid._options(specs[0], shape)
        sets = [(s.targets.xyz, s.targets.tol_p) for s in specs]
        one = [prefix.refine(lv, x, t, cap) for x, t in sets]
        many = prefix.refine_many(lv, sets, cap)
        assert all(_same(a, b) for a, b in zip(one, many, strict=True)), shape.label()
        depths |= {f.depth for f in one}
    assert len(depths) > 1 and any(f.settings for f in one)


def test_too_many_families_at_once_fall_back_to_one_pose_at_a_time(monkeypatch):
    from modc.design import grid, prefix, space

    p = problem()
    specs = _specs(p)[:6]
    shape = next(s for s in space.shapes(p, 3) if s.kinds == (3, 3, 4))
    lv = grid._options(specs[0], shape)
    sets = [(s.targets.xyz, s.targets.tol_p) for s in specs]
    one = [prefix.refine(lv, x, t) for x, t in sets]
    monkeypatch.setattr(prefix, "TOGETHER", 50)
    many = prefix.refine_many(lv, sets)
    assert all(_same(a, b) for a, b in zip(one, many, strict=True))


def test_one_checker_per_unit_type_moved_over_the_poses_decides_as_a_checker_per_pose(monkeypatch):
    """The base sinks into the shelf (z 0.04 to 0.06 m) at some poses of a grid that rises to
    0.1 m, turned and shifted: the shared checkers block exactly the poses fresh ones do."""
    from modc.design import placement
    from modc.physical import checker

    p = problem(CELL.replace("box size (0.2, 0.2, 0) m at (0, 0, 0) m step 100 mm yaw 0 to 90 deg step 45 deg",
                             "box size (0.2, 0.2, 0.1) m at (0.1, 0, 0.05) m step 100 mm yaw 0 to 90 deg step 90 deg"))
    poses = p.base_grid.poses()
    fresh = [placement.base_blocked(p, pose) for pose in poses]
    built = []
    real = checker.CollisionChecker

    def counted(*a, **k):
        built.append(1)
        return real(*a, **k)

    monkeypatch.setattr(checker, "CollisionChecker", counted)
    shared: dict = {}
    assert [placement.base_blocked(p, pose, shared) for pose in poses] == fresh
    assert 0 < sum(fresh) < len(poses)
    assert len(built) == len(shared) <= len(p.cell.library.variants) * len(p.cell.library.units)


def test_the_bounds_norm_has_numpys_bits():
    """bounds._norm replaces np.linalg.norm in the bounds' hot loops: the same bits (so the
    families, and what they count, are unchanged), on contiguous and strided vectors."""
    from modc.design import bounds

    rng = np.random.default_rng(5)
    for v in (rng.normal(size=(4000, 7, 3)), rng.normal(size=(4000, 5, 3))[:, 2], rng.uniform(-1, 1, (9, 3)) * 1e-3):
        assert np.array_equal(bounds._norm(v), np.linalg.norm(v, axis=-1))
    a, b = rng.normal(size=(2, 1000))
    assert np.array_equal(bounds._floor(a, b), np.maximum.reduce([np.zeros_like(a), a, b]))


@pytest.mark.parametrize("elements", [None, 100])
def test_the_bounds_by_group_of_targets_are_the_bounds_per_target_grouped(monkeypatch, elements):
    """bounds.possible_all (D_1 first, the other tests on the rows left; rows a memory-bounded
    chunk at a time) is possible()'s answer for every group of targets: families of real
    shapes, at the poses' targets stacked."""
    from modc.design import bounds, grid, prefix, space

    if elements is not None:  # a few rows at a time: a 25-pose cell's refine once took 24 GB
        monkeypatch.setattr(bounds, "ELEMENTS", elements)
    p = problem()
    specs = _specs(p)[::6]
    xyz = np.concatenate([s.targets.xyz for s in specs])
    tol = np.concatenate([s.targets.tol_p for s in specs])
    starts = np.cumsum([0] + [len(s.targets.xyz) for s in specs[:-1]])
    rng = np.random.default_rng(2)
    seen = set()
    for shape in [s for n in (2, 3) for s in space.shapes(p, n)][::7]:
        lv = grid._options(specs[0], shape)
        U = prefix.tails(lv)
        for k in range(1, len(lv) + 1):
            pick = [rng.integers(len(level.t), size=500) for level in lv[:k]]
            f = bounds.Frames(np.stack([lv[j].R[pick[j]] for j in range(k)], 1),
                              np.stack([lv[j].t[pick[j]] for j in range(k)], 1))
            tail = U[k - 1] if k < len(lv) else None
            each = bounds.possible(f, xyz, tol, tail)
            want = np.logical_and.reduceat(each, starts, axis=1)
            assert np.array_equal(bounds.possible_all(f, xyz, tol, tail, starts), want)
            assert np.array_equal(bounds.possible_all(f, xyz, tol, tail)[:, 0], each.all(-1))
            seen |= {bool(want.any()), bool((~want).any())}
    assert seen == {True, False}
