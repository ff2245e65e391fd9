"""One home pose (Robot.home) for every backend and analysis.

Home is the file's `pose home`, else MoveIt's default joint values: 0, or the middle of a joint
range (narrowed by `limit`) that excludes 0. A `limit joint_2 (10, 90) deg` without a `pose home`
used to put joint_2 at 0 in the SRDF and the ROS initial positions, outside its limits.
"""
from __future__ import annotations

import json
import math
import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest
import yaml
from conftest import checked_ok

from modc.compiler import build, check_text
from modc.kinematics import Chain

LIMITED = """robot farm {
    chain H1 - L4(port=45deg) - L1
    limit joint_2 (10, 90) deg
}
"""
EXPECTED = (0.0, math.radians(50.0), 0.0)  # joint_2 mid-range; the others keep 0


@pytest.fixture(scope="module")
def limited():
    c = checked_ok(LIMITED)
    return c, build(c, collision_samples=50)


@pytest.mark.slow
def test_home_is_inside_the_limits(limited):
    c, _ = limited
    r = c.design.robots[0]
    assert r.home() == pytest.approx(EXPECTED, abs=1e-15)
    for i, q in enumerate(r.home(), start=1):
        lo, hi = r.joint_range(i)
        assert lo <= q <= hi


def test_backends_emit_that_home(limited, tmp_path):
    c, files = limited
    r = c.design.robots[0]
    init = yaml.safe_load(files["config/initial_positions.yaml"])["initial_positions"]
    assert [init[f"joint_{i}"] for i in (1, 2, 3)] == pytest.approx(EXPECTED, abs=1e-11)
    assert "MoveIt's default values" in files["config/initial_positions.yaml"]
    srdf = files[f"config/{r.file_stem}.srdf"]
    state = ET.fromstring(srdf).find("group_state[@name='home']")
    assert [float(j.get("value")) for j in state.findall("joint")] == pytest.approx(EXPECTED, abs=1e-11)
    # (the ros2_control xacro reads its initial_value from that YAML: test_ros_package expands it)
    report = json.loads(files["report.json"])
    tool = report["robots"][0]["tool0_at_home"]
    assert tool == pytest.approx(Chain(r).T_base_tool(EXPECTED)[:3, 3], abs=1e-11)
    # a real consumer of the SRDF: pinocchio's reference configurations
    pin = pytest.importorskip("pinocchio")
    (tmp_path / "a.urdf").write_text(files[f"urdf/{r.file_stem}.urdf"], encoding="utf-8")
    (tmp_path / "a.srdf").write_text(srdf, encoding="utf-8")
    model = pin.buildModelFromUrdf(str(tmp_path / "a.urdf"))
    pin.loadReferenceConfigurations(model, str(tmp_path / "a.srdf"))
    home = model.referenceConfigurations["home"]
    assert np.allclose(home, EXPECTED, atol=1e-11)
    assert np.all(home >= model.lowerPositionLimit - 1e-12) and np.all(home <= model.upperPositionLimit + 1e-12)


def test_analyses_start_from_that_home(limited):
    c, _ = limited
    r = c.design.robots[0]
    from modc.plan import start_pose
    from modc.sim.render import pose_of

    assert start_pose(r, None)[:2] == ("home", r.home())
    assert r.named_poses()[0] == ("home", r.home())
    assert pose_of(r, None) == r.home()


def test_declared_home_wins_and_must_fit():
    ok = checked_ok(LIMITED.replace("}", "    pose home (0, 20, 0) deg\n}"))
    assert ok.design.robots[0].home() == pytest.approx((0.0, math.radians(20.0), 0.0))
    bad = check_text(LIMITED.replace("}", "    pose home (0, 0, 0) deg\n}"), "t.mod")
    errors = [d for d in bad.diagnostics if d.is_error]
    assert [d.code for d in errors] == ["pose-out-of-limits"]
    assert "pose 'home'" in errors[0].message and errors[0].span.line == 4


def test_without_limits_home_stays_zero():
    r = checked_ok("robot farm { chain H1 - L4(port=45deg) - L1 }").design.robots[0]
    assert r.home() == (0.0, 0.0, 0.0)


def test_home_then_the_named_poses_is_one_list():
    """The SRDF's group states, the MJCF keyframes, the smoke test and the viewer all take
    ResolvedRobot.named_poses: home first (declared anywhere in the file), then the others in order."""
    c = checked_ok(LIMITED.replace("}", "    pose a (0, 10, 0) deg\n    pose home (0, 20, 0) deg\n"
                                        "    pose b (0, 30, 0) deg\n}"))
    r = c.design.resolved_robots()[0]
    assert [n for n, _ in r.named_poses()] == ["home", "a", "b"]
    assert r.named_poses()[0][1] == r.home() == pytest.approx((0.0, math.radians(20.0), 0.0))

    srdf = build(c, only=["srdf"])[f"config/{r.file_stem}.srdf"]
    assert re.findall(r'group_state name="([^"]+)"', srdf) == ["home", "a", "b"]


def test_a_picture_of_several_robots_shows_home_then_every_pose_name():
    """sim.render.file_poses: home first, then each pose name any robot has, in file order; a
    robot without that pose stays at its home (both read ResolvedRobot.named_poses)."""
    from modc.sim.render import file_poses

    c = checked_ok("robot a {\n    chain H1 - L1\n    pose x (10, 0) deg\n}\n"
                   "robot b {\n    chain H1 - L1\n    pose y (0, 20) deg\n    pose x (0, 30) deg\n}\n")
    a, b = c.design.resolved_robots()
    frames = file_poses([a, b])
    assert len(frames) == 3
    assert frames[0] == {"a": a.home(), "b": b.home()}
    assert frames[1] == {"a": a.pose("x").q, "b": b.pose("x").q}
    assert frames[2] == {"a": a.home(), "b": b.pose("y").q}
