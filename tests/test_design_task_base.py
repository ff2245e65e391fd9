"""`base within` in `modc design`: the base pose is a design variable, the cell given in the frame
of the base's box; each design states its `base at` and the same cell around it."""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from conftest import modc_design

from modc.compiler import check_file, check_text

ROOT = Path(__file__).resolve().parent.parent

# target a lies 0.78 m from the origin, beyond any 3-unit H1/L3 arm there (about 0.70 m), and
# 0.59 m from a base at x = 0.2 m: only a shifted base reaches it
SHIFTED = """design shifted {
    box post size (0.05, 0.05, 0.3) m at (0.45, -0.25, 0.15) m
    target a at (0.75, 0.05, 0.20) m
    target b at (0.55, -0.10, 0.35) m
    units 3
    modules H1, L3
    base within box size (0.4, 0, 0) m at (0, 0, 0) m step 100 mm
}
"""


def problem(text: str = SHIFTED):
    checked = check_text(text, "cell.mod")
    assert checked.ok, [d.message for d in checked.diagnostics]
    return checked.design.problems[0]


def test_the_cell_is_written_in_the_frame_of_each_base_pose():
    from modc.design.placement import cell_at
    from modc.kinematics import rpy_matrix, transform
    from modc.model import Transform

    cell = problem(SHIFTED.replace("(0.75, 0.05, 0.20) m", "(0.75, 0.05, 0.20) m rpy (10, 90, 20) deg")).cell
    pose = Transform(xyz=(0.1, -0.2, 0.05), rpy=(0.0, 0.0, math.radians(30)))
    moved = cell_at(cell, pose)
    assert moved.base == pose
    T = transform(pose.xyz, pose.rpy)
    for before, after in zip(cell.targets, moved.targets, strict=True):  # the same place in the cell frame
        assert np.allclose(T[:3, :3] @ after.xyz + T[:3, 3], before.xyz, atol=1e-12)
    a0, a1 = cell.targets[0], moved.targets[0]
    assert np.allclose(T[:3, :3] @ rpy_matrix(a1.rpy), rpy_matrix(a0.rpy), atol=1e-12)
    o0, o1 = cell.obstacles[0], moved.obstacles[0]
    assert np.allclose(T @ transform(o1.origin.xyz, o1.origin.rpy), transform(o0.origin.xyz, o0.origin.rpy))


def test_base_poses_beyond_reach_are_skipped_soundly_and_nearest_first():
    from modc.design import placement, run

    p = problem()
    longest = run.longest_reach(p, 3)
    kept, pruned, touching = placement.poses(p, longest)
    assert pruned == 1 and touching == 0 and [k.xyz[0] for k in kept] == pytest.approx([0.2, 0.1, 0.0, -0.1])
    # a pose is skipped only when a target is farther than the longest arm's reach bound from it
    far = p.base_grid.poses()[0]
    assert far.xyz[0] == pytest.approx(-0.2)
    assert np.linalg.norm(np.subtract(p.cell.targets[0].xyz, far.xyz)) - 0.005 > longest


# from the pose nearest the target (x = 0.3 m) it lies 0.35 m straight above the base, where no
# 2-unit H1/L3 arm reaches (a 3-unit one does); from x = 0.2 m a 2-unit arm reaches it
FARTHER = """design farther {
    target a at (0.3, 0, 0.35) m
    units 2 to 3
    modules H1, L3
    base within box size (0.1, 0, 0) m at (0.25, 0, 0) m step 100 mm
}
"""


def test_the_best_pose_wins_not_the_first_that_fits():
    """First fit (the nearest pose searched alone) returned a 3-module arm at x = 0.3 m (it fails
    with the first-fit search): the 2-module arm at x = 0.2 m ranks first."""
    from modc.design import placement, run

    p = problem(FARTHER)
    kept, _, _ = placement.poses(p, run.longest_reach(p, 3))
    assert [k.xyz[0] for k in kept] == pytest.approx([0.3, 0.2])  # nearest first
    fixed = FARTHER.replace("    base within box size (0.1, 0, 0) m at (0.25, 0, 0) m step 100 mm\n",
                            "    base at (0.3, 0, 0) m\n")
    assert not run.design(problem(fixed), top=1, max_units=2).designs  # the nearest pose needs 3 units
    o = run.design(p, top=1)
    assert len(o.designs) == 1 and o.designs[0].modules == 2
    assert o.designs[0].verified.robot.base.xyz == pytest.approx((0.2, 0.0, 0.0))


def test_every_pose_is_searched_at_once_fewest_units_first(monkeypatch):
    """Fewest modules first, a shape's settings at every pose at once (modc.design.grid); a
    greater number of units is not searched once the top designs are found, and the answer is as
    good on modules and mass as the best of every pose alone."""
    from modc.design import grid, placement, run

    three = FARTHER.replace("box size (0.1, 0, 0) m at (0.25, 0, 0) m", "box size (0.2, 0, 0) m at (0.2, 0, 0) m")
    calls = []
    real = grid.search_shapes

    def counted(specs, shapes, *a):
        calls.append((len(specs), {s.n for s in shapes}))
        return real(specs, shapes, *a)

    monkeypatch.setattr(grid, "search_shapes", counted)
    o = run.design(problem(three), top=1)
    monkeypatch.setattr(grid, "search_shapes", real)
    assert len(o.designs) == 1 and o.bases_searched == 3
    assert calls and all(c == (3, {2}) for c in calls)  # the three poses at once, 2 units only
    best = o.designs[0]
    each = []
    for x in (0.3, 0.2, 0.1):  # every pose alone, with the base as written there (more units cannot beat 2)
        p = problem(three)
        pose = next(k for k in p.base_grid.poses() if k.xyz[0] == pytest.approx(x))
        each += run.design(p.model_copy(update={"cell": placement.cell_at(p.cell, pose), "base_grid": None}),
                           top=1, max_units=2).designs
    assert (best.modules, round(best.mass, 9)) == min((d.modules, round(d.mass, 9)) for d in each)


def test_a_base_pose_inside_an_obstacle_is_skipped():
    from modc.design import placement, run
    from modc.model import Transform

    text = SHIFTED.replace("    units 3\n", "    box block size (0.2, 0.2, 0.2) m at (0.2, 0, 0.05) m\n    units 3\n")
    p = problem(text)
    assert placement.base_blocked(p, Transform(xyz=(0.2, 0.0, 0.0)))
    assert not placement.base_blocked(p, Transform(xyz=(-0.2, 0.0, 0.0)))
    kept, _pruned, touching = placement.poses(p, run.longest_reach(p, 3))
    assert touching == 2 and all(k.xyz[0] < 0.05 for k in kept)  # x = 0.1 and 0.2 sit in the block


def test_no_base_pose_in_reach_is_no_design_with_the_reason():
    from modc.design import run

    text = SHIFTED.replace("(0.75, 0.05, 0.20) m", "(1.75, 0.05, 0.20) m")
    o = run.design(problem(text), top=1)
    assert not o.designs and o.bases_searched == 0 and o.bases_pruned == 5
    assert "from every one of the 5 base poses some target lies beyond the reach" in o.why_none()
    assert "inf" not in o.why_none() and "nan" not in o.why_none()


@pytest.mark.slow
def test_only_a_shifted_base_reaches_and_its_file_places_the_same_cell(tmp_path):
    from modc.design import run
    from modc.kinematics import Chain, rpy_matrix, transform

    fixed = problem(SHIFTED.replace("    base within box size (0.4, 0, 0) m at (0, 0, 0) m step 100 mm\n", ""))
    assert not run.design(fixed, top=1).designs  # at the origin no arm of the bounds reaches a

    r = modc_design(tmp_path, SHIFTED, "--top", "2")
    assert r.returncode == 0, r.stderr
    ranking = json.loads((tmp_path / "out" / "ranking.json").read_text())
    bases = ranking["bases"]["shifted"]
    assert bases["poses"] == 5 and bases["pruned_by_reach"] == 1 and 1 <= bases["searched"] <= 4
    cell = problem().cell
    for d in ranking["designs"]:
        assert d["base"]["xyz_m"][0] > 0.05 and d["base"]["rpy_deg"] == [0.0, 0.0, 0.0]
        checked = check_file(tmp_path / "out" / d["file"])
        assert checked.ok, [x.message for x in checked.diagnostics]
        robot = checked.design.robots[0]
        assert list(robot.base.xyz) == pytest.approx(d["base"]["xyz_m"])
        T_world_base = transform(robot.base.xyz, robot.base.rpy)
        chain = Chain(robot)
        for t in cell.targets:  # re-measured in the cell frame, from the emitted file's own pose
            q = np.asarray(robot.pose(f"at_{t.name}").q)
            T = T_world_base @ chain.T_base_tool(q)
            assert np.linalg.norm(T[:3, 3] - np.asarray(t.xyz)) <= t.position_tolerance + 1e-9
            if t.rpy is not None:
                E = rpy_matrix(t.rpy) @ T[:3, :3].T
                angle = math.degrees(math.acos(np.clip((np.trace(E) - 1) / 2, -1, 1)))
                assert angle <= math.degrees(t.orientation_tolerance) + 1e-6
        # the obstacle stands where the cell put it
        post = next(o for o in robot.obstacles if o.name == "post")
        assert np.allclose(T_world_base[:3, :3] @ post.origin.xyz + T_world_base[:3, 3], (0.45, -0.25, 0.15))


def test_the_reference_arm_stands_at_a_base_pose_where_it_passes():
    """`compare with chain …` with `base within`: the reference is judged at the grid's poses too
    (nearest first), not only at the base as written, where no arm reaches target a."""
    from modc.design import placement, reference, run

    best = run.design(problem(), top=1).designs[0]
    p = problem(SHIFTED.replace("    base within", f"    compare with chain {best.chain()}\n    base within"))
    kept = placement.poses(p, run.longest_reach(p, 3))[0]
    r = reference.evaluate(p, seed=0, poses=kept)
    assert r is not None and r.feasible, r.fails if r else None
    assert r.verified is not None and r.verified.robot.base.xyz[0] > 0.05
    assert r.to_json("shifted")["base"]["xyz_m"] == pytest.approx(list(r.verified.robot.base.xyz))
    at_origin = reference.evaluate(p, seed=0)
    assert at_origin is not None and not at_origin.feasible and "'a'" in " ".join(at_origin.fails)


def test_a_searched_base_at_the_origin_is_stated():
    """Each robot file of a `base within` design states its `base at`, the origin included (the
    search chose it); a robot file of a block without a base grid writes none for the origin."""
    from modc.model.write import robot_file_text

    robot = check_text("robot r {\n    chain H1 - L3\n}\n", "r.mod").design.robots[0]
    assert "    base at (0, 0, 0) m\n" in robot_file_text(robot, state_base=True)
    assert "base at" not in robot_file_text(robot)
    again = check_text(robot_file_text(robot, state_base=True), "again.mod")
    assert again.ok and again.design.robots[0].base == robot.base
