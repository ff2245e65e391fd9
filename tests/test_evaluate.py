"""The design search's fast path (modc.physical.evaluate) agrees with the slow, independent ones:
tool pose with the paper's kinematics (numpy), gravity torques with the statics (numpy), and
collisions with the planner's checker (pinocchio on the emitted URDF and meshes)."""
from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT

from modc.compiler import build, check_file, check_text
from modc.kinematics import Chain
from modc.physical.evaluate import Candidate, evaluate
from modc.physical.statics import Statics

pytest.importorskip("pinocchio")


def _robot(stem):
    (r,) = check_file(ROOT / "examples" / f"{stem}.mod").design.robots
    return r


@pytest.mark.parametrize("stem", ["example_b", "farm", "table3_raven"])
def test_tool_pose_and_gravity_agree_with_the_kinematics_and_the_statics(stem):
    robot = _robot(stem)
    chain, statics = Chain(robot), Statics(robot)
    lo, hi = np.array([robot.joint_range(i) for i in range(1, robot.dof + 1)]).T
    for q in np.random.default_rng(3).uniform(lo, hi, size=(20, robot.dof)):
        e = evaluate(robot, q)
        assert np.allclose(e.T_base_tool, chain.T_base_tool(q), rtol=0, atol=1e-12)
        # the statics leave out tool0's placeholder inertial (1 mg): up to 1e-5 N·m on these arms
        assert np.allclose(e.tau_gravity, statics.torques(q), rtol=0, atol=2e-5)


def test_a_tilted_base_turns_gravity():
    text = "robot r {\n    chain H1 - H3 - L1\n    base at (0, 0, 0) m rpy (90, 0, 0) deg\n}\n"
    (robot,) = check_text(text, "t.mod").design.robots
    upright = robot.model_copy(update={"base": type(robot.base)()})
    q = np.array([0.3, 0.4, 0.5])
    assert not np.allclose(Candidate(robot).gravity(q), Candidate(upright).gravity(q))
    # on its side, the first joint's axis is horizontal: it holds the arm now
    assert abs(Candidate(robot).gravity(q)[0]) > 0.1 > abs(Candidate(upright).gravity(q)[0])


@pytest.mark.parametrize("stem", ["farm", "cellarm", "example_b"])
def test_collisions_agree_with_the_planners_checker(stem):
    from modc.plan.collision import CollisionChecker

    path = ROOT / "examples" / f"{stem}.mod"
    checked = check_file(path)
    (robot,) = checked.design.robots
    checker = CollisionChecker(robot, build(checked, ["urdf", "meshes"]))  # read from the emitted files
    assert not any(p.reason == "Always" for p in checker.matrix.disabled)  # else the two count other pairs
    arm = Candidate(robot)
    seen = set()
    for q in np.random.default_rng(5).uniform(checker.lower, checker.upper, size=(150, robot.dof)):
        expected = bool(checker.contacts(q, 0.0))
        assert arm.collides(q) == expected, q
        seen.add(expected)
    assert seen == {True, False}  # both answers occurred: the comparison is not vacuous
