"""`modc plan`'s target-unreachable says why (modc/plan/advice.py): too far, too close, orientation,
joint limits; obstacles are target-in-collision. The numbers are checked independently with
modc.kinematics.Chain (docs/conventions.md) and random poses, not with the planner's pinocchio.
"""
from __future__ import annotations

import math
import re

import numpy as np
import pytest

from modc.compiler import check_file
from modc.kinematics import Chain, rpy_matrix
from modc.plan import PlanError, plan

FARM = """robot farm {
    chain H1 - L4(pivot=-90deg, port=45deg) - L3(link=180mm)
    tool at (0.06, 0, 0) m
    pose home (0, 0, 0) deg
    target far at (1.2, 0, 0.3) m
    target near at (0, 0, 0.16) m
    target tilted at (0.3, 0, 0.3) m rpy (0, 180, 0) deg
    target behind at (-0.3, 0, 0.3) m
}
"""
NOT_FINITE = re.compile(r"\b(inf|nan)\b", re.IGNORECASE)


def _number(text: str, before: str, unit: str = " m") -> float:
    return float(text.split(before)[1].split(unit)[0])


@pytest.fixture(scope="module")
def cell(tmp_path_factory):
    path = tmp_path_factory.mktemp("advice") / "cell.mod"
    path.write_text(FARM, encoding="utf-8")
    robot = check_file(path).design.robots[0]
    chain = Chain(robot)
    rng = np.random.default_rng(3)
    lo = np.array([robot.joint_range(i)[0] for i in range(1, 4)])
    hi = np.array([robot.joint_range(i)[1] for i in range(1, 4)])
    tools = np.array([chain.T_base_tool(lo + (hi - lo) * rng.random(3))[:3, 3] for _ in range(4000)])
    return path, robot, chain, tools


def _error(path, target: str, text: str | None = None) -> PlanError:
    if text is not None:
        path.write_text(text, encoding="utf-8")
    with pytest.raises(PlanError) as e:
        plan(path, target)
    err = e.value
    assert err.code == "target-unreachable" and err.exit_code == 1
    assert not NOT_FINITE.search(err.message + err.hint), err.message
    return err


def test_too_far(cell):
    path, robot, chain, tools = cell
    err = _error(path, "far")
    assert err.message.startswith("target 'far' is out of reach, too far: tool0 gets no closer than ")
    origin = chain.joint_axes()[0][0]
    target = np.array([1.2, 0, 0.3])
    assert _number(err.message, "the target is ") == pytest.approx(np.linalg.norm(target - origin), abs=1e-3)
    gap = _number(err.message, "no closer than ")
    closest = np.linalg.norm(tools - target, axis=1).min()
    assert closest - 0.03 <= gap <= closest + 1e-3  # random poses get no closer than the reported gap
    reach = _number(err.message, "farther than ")
    assert np.linalg.norm(tools - origin, axis=1).max() <= reach  # the stated bound holds
    assert "move the target towards the arm" in err.hint


def test_too_close(cell):
    """Beside joint_1: the old advice said "move the target towards the arm"."""
    path, robot, chain, tools = cell
    err = _error(path, "near")
    assert "too close to the arm" in err.message and "towards the arm" not in err.hint
    assert "move the target away from the arm" in err.hint
    origin = chain.joint_axes()[0][0]
    target = np.array([0, 0, 0.16])
    assert _number(err.message, "the target is ") == pytest.approx(np.linalg.norm(target - origin), abs=1e-3)
    gap = _number(err.message, "no closer than ")
    assert gap <= np.linalg.norm(tools - target, axis=1).min() + 1e-3
    assert _number(err.message, "puts tool0 ") > _number(err.message, "the target is ")


def test_orientation(cell):
    """The position is reachable (it plans without the rpy): the orientation is what fails, in degrees."""
    path, robot, chain, tools = cell
    err = _error(path, "tilted")
    assert "in orientation: tool0 reaches the position" in err.message
    angle = _number(err.message, "turns no closer than ", "°")
    assert 2.0 < angle <= 180.0
    assert "tolerance 2.0°" in err.message and "rpy" in err.hint and "6 joints" in err.hint
    q = np.radians([float(v) for v in err.hint.split("joint angles (")[1].split(")")[0].split(", ")])
    T = chain.T_base_tool(q)
    assert np.linalg.norm(T[:3, 3] - [0.3, 0, 0.3]) <= 0.005  # the quoted pose is on the position
    R = rpy_matrix(np.radians([0, 180, 0])) @ T[:3, :3].T
    assert math.degrees(math.acos(np.clip((np.trace(R) - 1) / 2, -1, 1))) == pytest.approx(angle, abs=0.2)


def test_joint_limits(cell, tmp_path):
    path, robot, chain, tools = cell
    limited = tmp_path / "limited.mod"
    err = _error(limited, "behind", FARM.replace("    pose home", "    limit joint_1 (-30, 30) deg\n    pose home"))
    assert "outside the joint limits: tool0 reaches it only with joint_1 at " in err.message
    assert "(its range is -30.0..30.0°)" in err.message and "widen the `limit`" in err.hint
    needed = _number(err.message, "joint_1 at ", "°")
    assert abs(needed) > 30
    q = np.radians([float(v) for v in err.hint.split("joint angles that reach it: (")[1].split(")")[0].split(", ")])
    assert math.degrees(q[0]) == pytest.approx(needed, abs=0.1)
    assert np.linalg.norm(chain.T_base_tool(q)[:3, 3] - [-0.3, 0, 0.3]) <= 0.005  # it does reach, unlimited
    assert plan(path, "behind").tool_error < 1e-6  # and the same arm without the limit plans


def test_one_joint_arm_says_which(tmp_path):
    """A one-joint arm moves tool0 on a circle: inside it is too close, outside too far."""
    src = tmp_path / "one.mod"
    text = ("robot one {\n    allow first-variant\n    chain L4(link=200mm)\n"
            "    target out at (0.5, 0, 0.148) m\n    target in at (0.02, 0, 0.148) m\n}\n")
    assert "too far" in _error(src, "out", text).message
    assert "too close" in _error(src, "in").message


def test_obstacle_says_the_target_is_inside_it(tmp_path):
    """target-in-collision names the colliding links and, when the point itself is inside an
    obstacle, how deep (a tilted box: 0.05 m to its nearest face)."""
    src = tmp_path / "crate.mod"
    crate = "    box crate size (0.1, 0.3, 0.3) m at (0.3, 0, 0.3) m rpy (0, 0, 30) deg\n"
    src.write_text(FARM.replace("    target far", crate + "    target boxed at (0.3, 0, 0.3) m\n    target far"),
                   encoding="utf-8")
    with pytest.raises(PlanError) as e:
        plan(src, "boxed")
    err = e.value
    assert err.code == "target-in-collision" and "box 'crate'" in err.message
    assert "the target lies 0.050 m inside box 'crate': move it out" in err.hint
    assert re.search(r"all \d+ arm pose\(s\)", err.hint)


def test_off_to_the_side(tmp_path):
    """Two coaxial joints sweep tool0 round one circle 0.248 m from joint_1: a target straight above
    joint_1 at that distance is neither too far nor too close, it is off to the side."""
    src = tmp_path / "flat.mod"
    err = _error(src, "up", "robot flat {\n    chain H1 - L3(link=200mm)\n    target up at (0, 0, 0.395) m\n}\n")
    assert "off to the side of what the arm sweeps" in err.message
    assert _number(err.message, "no closer than ") == pytest.approx(math.hypot(0.2, 0.101), abs=2e-3)
    assert _number(err.message, "the target is ") == pytest.approx(0.248, abs=1e-3)
    assert "two joints move tool0 over a surface" in err.hint
