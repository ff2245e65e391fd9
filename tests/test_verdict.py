"""The smoke test's verdicts without an engine (modc.sim.verdict): what any simulator measures at a
pose, judged into the same checks and messages `modc sim` prints."""
from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import checked_ok

from modc.dynamics.model import Dynamics
from modc.kinematics import Chain
from modc.sim.contacts import Contact
from modc.sim.verdict import TRACK_TOL, Hold, Measured, RobotResult, describe, judge_pose

pytest.importorskip("pinocchio")


@pytest.fixture(scope="module")
def farm():
    r = checked_ok(
        "robot farm {\n    chain H1 - H4(pivot=-90deg) - L3(port=45deg)\n    pose ready (0, 30, -45) deg\n}\n"
    ).design.robots[0]
    return r, Chain(r), Dynamics(r)


def _held(dyn, q, error=0.0, effort=6.8):
    """A hold that ends at q + error on joint_2 with exactly the gravity torques applied."""
    q_end = np.array(q, float)
    q_end[1] += error
    tau = dyn.gravity(q_end)
    worst = np.array([0.0, abs(error), 0.0])
    return Hold(worst=worst, peak=worst, max_velocity=0.0, diverged=None, applied=tau, q_end=q_end, tau_end=tau,
                efforts=(30.5, effort, 30.5))


def test_a_faithful_measurement_passes(farm):
    r, chain, dyn = farm
    q = r.pose("ready").q
    m = Measured("ready", q, chain.T_base_tool(np.array(q)), [], [], _held(dyn, q))
    res = judge_pose(r, m, chain, dyn, engine="MuJoCo")
    assert res.failures == [] and res.torque_error == pytest.approx(0.0, abs=1e-12)
    assert describe(RobotResult(r.name, r.sequence, [res]))[1].startswith("  pose ready: ok; held to")


def test_each_check_speaks_for_the_engine(farm):
    r, chain, dyn = farm
    q = r.pose("ready").q
    T = chain.T_base_tool(np.array(q))
    T[0, 3] += 1e-3  # the engine puts tool0 1 mm away
    touching = [Contact("link_1", "link_3", -0.004)]
    m = Measured(
        "ready", q, T, touching, [Contact("link_2", "shelf", -0.002)], _held(dyn, q, error=3 * TRACK_TOL, effort=0.01)
    )
    assert abs(dyn.gravity(np.array(q))[1]) > 0.01  # joint_2 needs more than the actuator gives
    res = judge_pose(r, m, chain, dyn, engine="MuJoCo")
    kinds = [f.kind for f in res.failures]
    assert kinds == ["fk", "self-collision", "environment", "sag"]
    fk, selfc, env, sag = (f.message for f in res.failures)
    assert fk.startswith("robot farm, pose ready: MuJoCo puts tool0 0.001 m")
    assert selfc == "robot farm, pose ready: link_1 and link_3 collide (4.0 mm deep)"
    assert env == "robot farm, pose ready: link_2 is inside obstacle shelf (2.0 mm deep)"
    assert sag.startswith(f"robot farm, pose ready: joint_2 sags 0.03 rad ({math.degrees(0.03):.1f}°)")
    assert "it cannot hold the arm" in sag and res.failures[-1].joint == "joint_2"


def test_a_diverged_hold_is_only_unstable(farm):
    r, chain, dyn = farm
    q = r.home()
    h = _held(dyn, q)
    h = Hold(**{**h.__dict__, "diverged": "joint_3 reached 80 rad/s after 0.120 s"})
    res = judge_pose(r, Measured("home", q, chain.T_base_tool(np.array(q)), [], [], h), chain, dyn)
    assert [f.message for f in res.failures] == [
        "robot farm, pose home: the simulation diverged: joint_3 reached 80 rad/s after 0.120 s"]
