"""A region's box turned (`turned (r, p, y) deg`), and `base within … yaw` with a region: a yawed
base turns the region's box in the base frame each design's robot file states its cell in."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest
from conftest import modc_design

from modc.compiler import check_file, check_text

REGION = "region tray box size (0.2, 0.1, 0) m at (0.3, 0, 0.1) m{turn} grid 3 x 2 x 1"


def _robot(statement: str):
    checked = check_text(f"robot r {{\n    chain H1 - L3\n    {statement}\n}}\n", "r.mod")
    assert checked.ok, [d.message for d in checked.diagnostics]
    return checked.design.robots[0]


def _points(robot) -> dict[str, np.ndarray]:
    return {p.name: np.asarray(p.xyz) for r in robot.regions for p in r.points()}


def test_a_turned_box_turns_its_points_about_its_centre():
    plain = _points(_robot(REGION.format(turn="")))
    turned = _robot(REGION.format(turn=" turned (0, 0, 90) deg"))
    assert turned.regions[0].turned == pytest.approx((0.0, 0.0, math.pi / 2))
    points = _points(turned)
    assert list(points) == list(plain)  # the same names, in the same order
    # tray[0,0,0] lies at (-0.1, -0.05, 0) from the centre along the box's axes: x turned to y
    assert points["tray[0,0,0]"] == pytest.approx((0.35, -0.1, 0.1), abs=1e-12)
    assert points["tray[2,1,0]"] == pytest.approx((0.25, 0.1, 0.1), abs=1e-12)
    for name, p in plain.items():  # every point as far from the centre as before
        assert np.linalg.norm(points[name] - (0.3, 0, 0.1)) == pytest.approx(np.linalg.norm(p - (0.3, 0, 0.1)))


def test_no_turn_is_the_axis_aligned_box_bit_for_bit():
    zero = _robot(REGION.format(turn=" turned (0, 0, 0) deg"))
    assert zero.regions[0].turned is None
    plain = _points(_robot(REGION.format(turn="")))
    assert all(np.array_equal(p, plain[n]) for n, p in _points(zero).items())


def test_a_turn_without_an_angle_unit_is_a_diagnostic():
    checked = check_text("robot r {\n    chain H1 - L3\n    " + REGION.format(turn=" turned (0, 0, 90) m") + "\n}\n",
                         "r.mod")
    assert not checked.ok
    d = next(d for d in checked.diagnostics if d.is_error)
    assert d.span.line == 3 and "turn of the box of region 'tray'" in d.message


def test_the_written_robot_and_the_yaml_form_hold_the_same_turned_points(tmp_path):
    from modc.model.write import task_lines

    robot = _robot(REGION.format(turn=" turned (10, 20, 30) deg") + " pointing (0, 0, -1)")
    [line] = task_lines(robot)
    assert "turned (10, 20, 30) deg grid 3 x 2 x 1" in line
    again = _robot(line.strip())
    assert all(np.allclose(p, _points(robot)[n], atol=1e-12) for n, p in _points(again).items())
    yaml = tmp_path / "r.yaml"
    yaml.write_text("robots:\n  - name: r\n    chain: [H1, L3]\n    regions:\n      tray:\n"
                    "        size: (0.2, 0.1, 0) m\n        at: (0.3, 0, 0.1) m\n        turned: (10, 20, 30) deg\n"
                    "        grid: 3 x 2 x 1\n        pointing: (0, 0, -1)\n")
    checked = check_file(yaml)
    assert checked.ok, [d.message for d in checked.diagnostics]
    yaml_region, region = checked.design.robots[0].regions[0], robot.regions[0]
    assert (yaml_region.turned, yaml_region.pointing) == (region.turned, region.pointing)
    assert [p.xyz for p in yaml_region.points()] == [p.xyz for p in region.points()]


def test_a_yawed_base_turns_the_region_in_its_frame_and_keeps_its_points():
    from modc.design.placement import cell_at
    from modc.kinematics import rpy_matrix, transform
    from modc.model import Transform

    cell = _robot(REGION.format(turn=" turned (0, 0, 20) deg") + " rpy (0, 90, 0) deg")
    for yaw in (0.0, 45.0, 90.0, -135.0):
        pose = Transform(xyz=(0.1, -0.2, 0.05), rpy=(0.0, 0.0, math.radians(yaw)))
        moved = cell_at(cell, pose)
        T = transform(pose.xyz, pose.rpy)
        before, after = cell.regions[0].points(), moved.regions[0].points()
        for a, b in zip(before, after, strict=True):  # the same place and orientation in the cell frame
            assert a.name == b.name
            assert np.allclose(T[:3, :3] @ b.xyz + T[:3, 3], a.xyz, atol=1e-12)
            assert np.allclose(T[:3, :3] @ rpy_matrix(b.rpy), rpy_matrix(a.rpy), atol=1e-12)
    # at yaw -20 the base's axes are the box's: the region is written axis-aligned again
    assert cell_at(cell, Transform(xyz=(0, 0, 0), rpy=(0, 0, math.radians(20)))).regions[0].turned is None


# one yaw only (90 deg): every design stands turned, and its file states the region turned by -90 deg
YAWED = """design yawed {
    payload 100 g
    target plant at (0.25, 0.10, 0.25) m
    region tray box size (0.1, 0.05, 0) m at (0.3, -0.15, 0.2) m grid 2 x 2 x 1
    task serve { visit plant, tray }
    units 3
    modules H1, L3
    base within box size (0, 0, 0) m at (0, 0, 0) m step 50 mm yaw 90 to 90 deg step 45 deg
}
"""


@pytest.mark.slow
def test_a_yawed_base_with_a_region_gives_designs_that_serve_the_same_points(tmp_path):
    """Was refused (`design-unsupported`): a region's box could not be written in a turned base frame."""
    from modc import trajectory
    from modc.kinematics import Chain, transform

    r = modc_design(tmp_path, YAWED, "--top", "1")
    assert r.returncode == 0, r.stderr
    out = tmp_path / "out"
    ranking = json.loads((out / "ranking.json").read_text())
    [d] = ranking["designs"]
    assert d["base"]["rpy_deg"] == pytest.approx([0.0, 0.0, 90.0])
    checked = check_file(out / d["file"])
    assert checked.ok, [x.message for x in checked.diagnostics]
    robot = checked.design.robots[0]
    assert robot.regions[0].turned == pytest.approx((0.0, 0.0, -math.pi / 2))
    cell = check_text(YAWED, "cell.mod").design.problems[0].cell
    T_world_base = transform(robot.base.xyz, robot.base.rpy)
    chain = Chain(robot)
    want = {p.name: p for p in cell.regions[0].points()}
    for p in robot.regions[0].points():  # the file's region is the cell's, in the world
        assert np.allclose(T_world_base[:3, :3] @ p.xyz + T_world_base[:3, 3], want[p.name].xyz, atol=1e-9)
    for name, t in want.items():  # the design's own joint values reach the cell's points
        T = T_world_base @ chain.T_base_tool(np.asarray(d["targets"][name]["q"]))
        assert np.linalg.norm(T[:3, 3] - np.asarray(t.xyz)) <= t.position_tolerance + 1e-9
    traj, problems = trajectory.load(out / d["traj"])  # and its task was planned through them
    assert traj is not None and problems == [] and trajectory.validate_for(traj, robot) == []
