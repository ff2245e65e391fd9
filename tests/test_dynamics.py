"""Dynamics (pinocchio) and the worst-case torque check, against independent calculations."""
from __future__ import annotations

import json
import re
import subprocess
import sys

import numpy as np
import pytest
from conftest import ROOT, checked_ok, compile_text

from modc.compiler import COMPILE_ANALYSES, check_text
from modc.dynamics.model import Dynamics
from modc.dynamics.worst import worst_case
from modc.kinematics import Chain
from modc.physical.assembly import describe

G = 9.81
ARMS = [
    "robot r { chain H1 - H4(pivot=-90deg, port=45deg) - L3(pivot=30deg, link=150mm) - L2 "
    "payload 0.4 kg at (0.01, 0, 0.02) m }",
    "robot r { chain H3(pivot=60deg) - H4(port=-105deg) - L4 - L1 tool at (0.05, 0, 0.02) m base rpy (20, 0, 0) deg }",
]


def newton_euler(robot, q, qd, qdd, g_base):
    """Recursive Newton-Euler written from the paper's frames (Chain.frames) and the link
    inertials (mass, COM, inertia in each joint frame): the textbook algorithm, in base_link."""
    ch = Chain(robot)
    frames = ch.frames(q)
    links = {link.name: link for link in describe(robot).links}
    n = robot.dof
    # inertial of body i = link_i plus what is rigidly fixed to the last link (tool0, payload)
    bodies = []
    for i in range(n):
        parts = [(links[f"link_{i + 1}"].inertial, np.eye(4))]
        if i == n - 1:
            T_last_tool = ch.T_last_tool()
            for name in ("tool0", "payload"):
                if name in links:
                    T = T_last_tool.copy()
                    if name == "payload":
                        T[:3, 3] += T_last_tool[:3, :3] @ np.array(robot.payload.com)
                    parts.append((links[name].inertial, T))
        bodies.append(parts)
    w = np.zeros(3)
    wd = np.zeros(3)
    acc = -np.asarray(g_base)  # base acceleration trick: gravity as an upward acceleration
    p_prev = np.zeros(3)
    fwd = []
    for i in range(n):
        T = frames[i]["T_base_joint"]
        z, p = T[:3, 2], T[:3, 3]
        # linear acceleration of the joint origin from the previous one (rigid parent body)
        r = p - p_prev
        acc = acc + np.cross(wd, r) + np.cross(w, np.cross(w, r))
        wd = wd + qdd[i] * z + np.cross(w, qd[i] * z)
        w = w + qd[i] * z
        fwd.append((T, z, p, w.copy(), wd.copy(), acc.copy()))
        p_prev = p
    f_next = np.zeros(3)
    n_next = np.zeros(3)
    p_next = None
    tau = np.zeros(n)
    for i in reversed(range(n)):
        T, z, p, w_i, wd_i, a_i = fwd[i]
        F, N = np.zeros(3), np.zeros(3)
        for inert, T_part in bodies[i]:
            R = T[:3, :3] @ T_part[:3, :3]
            c = T[:3, :3] @ (T_part[:3, :3] @ inert.com + T_part[:3, 3]) + p
            inertia = R @ inert.inertia @ R.T
            rc = c - p
            a_c = a_i + np.cross(wd_i, rc) + np.cross(w_i, np.cross(w_i, rc))
            Fi = inert.mass * a_c
            F += Fi
            N += inertia @ wd_i + np.cross(w_i, inertia @ w_i) + np.cross(rc, Fi)
        if p_next is not None:
            F += f_next
            N += n_next + np.cross(p_next - p, f_next)
        tau[i] = N @ z
        f_next, n_next, p_next = F, N, p
    return tau


@pytest.mark.parametrize("src", ARMS)
def test_rnea_matches_an_independent_newton_euler(src):
    robot = checked_ok(src).design.robots[0]
    dyn = Dynamics(robot)
    g_base = np.array(dyn.model.gravity.linear)
    rng = np.random.default_rng(3)
    for _ in range(5):
        q, qd, qdd = rng.uniform(-2, 2, (3, robot.dof))
        assert np.allclose(dyn.rnea(q, qd, qdd), newton_euler(robot, q, qd, qdd, g_base), atol=1e-9)
        assert np.allclose(dyn.gravity(q), newton_euler(robot, q, 0 * q, 0 * q, g_base), atol=1e-9)


@pytest.mark.parametrize("src", ARMS)
def test_mass_matrix_and_rnea_are_consistent(src):
    robot = checked_ok(src).design.robots[0]
    dyn = Dynamics(robot)
    q, qdd = np.random.default_rng(4).uniform(-1, 1, (2, robot.dof))
    M = dyn.mass_matrix(q)
    assert np.allclose(M, M.T) and np.linalg.eigvalsh(M).min() > 0
    assert np.allclose(M @ qdd + dyn.gravity(q), dyn.rnea(q, 0 * q, qdd), atol=1e-12)


def test_rnea_matches_pybullet_inverse_dynamics(tmp_path):
    import pybullet as pb

    robot = checked_ok(ARMS[0]).design.robots[0]
    dyn = Dynamics(robot)
    compile_text(ARMS[0], tmp_path / "out")
    path = tmp_path / "out" / "urdf" / "mod4_r.urdf"
    cid = pb.connect(pb.DIRECT)
    try:
        pb.setGravity(0, 0, -9.81, physicsClientId=cid)
        body = pb.loadURDF(str(path), useFixedBase=True, flags=pb.URDF_USE_INERTIA_FROM_FILE, physicsClientId=cid)
        rng = np.random.default_rng(5)
        for _ in range(5):
            q, qd, qdd = rng.uniform(-1.5, 1.5, (3, robot.dof))
            ours = dyn.rnea(q, qd, qdd)
            theirs = np.array(pb.calculateInverseDynamics(body, list(q), list(qd), list(qdd), physicsClientId=cid))
            # PyBullet's pip build is single precision: agree to float32 rounding
            assert np.allclose(ours, theirs, rtol=1e-4, atol=1e-4), (ours, theirs)
    finally:
        pb.disconnect(cid)


def test_horizontal_two_module_arm_matches_the_hand_calculation():
    """H3 - L3 with the base rolled 90°: both joint axes horizontal, the links horizontal at
    q = 0. Holding torque = g * sum(mass * lever arm), lever arms read off the part layout:
    H link bar centred at 0.11 m; L3's twist unit, input casing and actuator on axis 2 at 0.22 m;
    L output casing at 0.22 m; L link bar centred at 0.33 m (masses from libraries/mark2.yaml)."""
    robot = checked_ok("robot r { chain H3 - L3 base rpy (90, 0, 0) deg }").design.robots[0]
    m_h_link, m_l_link = 0.40 * 0.22, 0.30 * 0.22
    m_l_unit_input = 0.050 + 0.060 + 0.357  # twist unit + input casing + KA-58
    m_l_out = 0.030
    tau_1 = G * (m_h_link * 0.11 + (m_l_unit_input + m_l_out) * 0.22 + m_l_link * 0.33)
    tau_2 = G * (m_l_link * 0.11)
    g = Dynamics(robot).gravity(np.zeros(2))
    assert g == pytest.approx([tau_1, tau_2], abs=1e-5)  # tool0's 1 mg placeholder is the slack
    worst = worst_case(Dynamics(robot))
    assert worst[0].tau == pytest.approx(tau_1, abs=1e-5) and worst[1].tau == pytest.approx(tau_2, abs=1e-5)
    assert np.allclose(worst[0].q, 0, atol=1e-3) or np.allclose(np.abs(worst[0].q), np.pi, atol=1e-3)


def test_worst_case_is_not_beaten_by_a_dense_grid():
    robot = checked_ok(
        "robot r { chain H3(pivot=-90deg) - H4(port=45deg) - L4(link=300mm) payload 0.2 kg }"
    ).design.robots[0]
    dyn = Dynamics(robot)
    found = worst_case(dyn)
    grid = np.linspace(dyn.lower, dyn.upper, 41)
    best = np.zeros(robot.dof)
    for a in grid[:, 0]:
        for b in grid[:, 1]:
            for c in grid[:, 2]:
                best = np.maximum(best, np.abs(dyn.gravity(np.array([a, b, c]))))
    assert all(f.tau >= b - 1e-9 for f, b in zip(found, best, strict=True)), ([f.tau for f in found], best)


def _modc(*args):
    return subprocess.run([sys.executable, "-m", "modc", *args], capture_output=True, text=True)


@pytest.mark.slow
def test_check_json_shape_and_exit_codes():
    r = _modc("check", str(ROOT / "examples" / "farm.mod"), "--json")
    assert r.returncode == 0, r.stderr
    joints = json.loads(r.stdout)["robots"][0]["joints"]
    assert [j["name"] for j in joints] == ["joint_1", "joint_2", "joint_3"]
    assert {"tau_gravity_max", "tau_nom", "tau_max"} <= set(joints[0])
    assert joints[1]["tau_nom"] == 3.6 and joints[1]["tau_max"] == 6.8


@pytest.mark.slow
def test_payload_over_capacity_fails_naming_joint_and_pose():
    r = _modc("check", str(ROOT / "examples" / "farm.mod"), "--payload", "3kg")
    assert r.returncode == 1
    assert "error[torque-over-peak]: joint_2 (L4) must hold" in r.stderr and "at q = (0, -73, -12) deg" in r.stderr


@pytest.mark.slow
@pytest.mark.parametrize("bad", ["abc", "-1kg", "5 lb", "nan"])
def test_bad_payload_gets_a_diagnostic(bad):
    r = _modc("check", str(ROOT / "examples" / "farm.mod"), "--payload", bad)
    assert r.returncode == 2 and "error[bad-payload]" in r.stderr and "Traceback" not in r.stderr


@pytest.mark.slow
def test_compile_refuses_an_overloaded_arm_unless_told(tmp_path):
    src = tmp_path / "heavy.mod"
    src.write_text("robot heavy {\n    chain H1 - L4(pivot=-90deg, link=450mm) - L4(link=450mm)\n    payload 1 kg\n}\n")
    r = _modc(str(src), "-o", str(tmp_path / "out"))
    assert r.returncode == 1 and "torque-over-peak" in r.stderr and not (tmp_path / "out").exists()
    r = _modc(str(src), "-o", str(tmp_path / "out"), "--torque", "warning")
    assert r.returncode == 0 and "warning[torque-over-peak]" in r.stderr
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    assert report["robots"][0]["torque"][1]["status"] == "over-peak"


def test_epsilon_and_torque_disagreement_is_told():
    c = check_text(
        "robot tower { chain H1 - H1 - H1 - H1 - L1 allow epsilon-exceeded }", "t.mod", analyses=COMPILE_ANALYSES
    )
    assert [d.code for d in c.diagnostics] == ["epsilon-disagrees"]
    c = check_text("robot reach { chain H1 - L4(pivot=-90deg, link=450mm) - L4(link=450mm) payload 1 kg }", "t.mod",
                   analyses=COMPILE_ANALYSES)
    over = [d for d in c.diagnostics if d.code == "torque-over-peak"]
    assert over and "obeys the paper's ε rule, but the physics says no" in over[0].hint


# --- the dynamic check: torques along a trajectory ------------------------------------------------

def test_a_trajectory_at_rest_needs_exactly_the_gravity_torques():
    from modc.dynamics.along import torques

    robot = checked_ok(ARMS[0]).design.robots[0]
    dyn = Dynamics(robot)
    q = np.array([0.3, -0.8, 1.1, 0.4])
    tau = torques(dyn, [0.0, 0.5, 1.0], [q, q, q])
    assert np.allclose(tau, [dyn.gravity(q)] * 3, atol=1e-12)


@pytest.mark.slow
def test_check_along_a_planned_motion(tmp_path):
    """plan -> check --traj: the planned motion (rated speeds) is within the actuators' torques,
    and the same path ten times faster is not; the failure names the joint and the time."""
    farm = str(ROOT / "examples" / "farm.mod")
    r = _modc("plan", farm, "--to", "plant", "--json")
    assert r.returncode == 0, r.stderr
    traj = tmp_path / "t.json"
    traj.write_text(r.stdout)
    r = _modc("check", farm, "--traj", str(traj), "--json")
    assert r.returncode == 0, r.stderr
    along = json.loads(r.stdout)["robots"][0]["trajectory"]["joints"]
    assert [j["name"] for j in along] == ["joint_1", "joint_2", "joint_3"] and all(j["status"] == "ok" for j in along)
    doc = json.loads(traj.read_text())
    for p in doc["points"]:
        p["t"] /= 25.0
    fast = tmp_path / "fast.json"
    fast.write_text(json.dumps(doc))
    r = _modc("check", farm, "--traj", str(fast))
    assert r.returncode == 1
    assert "Traceback" not in r.stderr
    assert re.search(
        r"^modc check: joint_\d \([HL]\d\) needs [\d.]+ N·m at t = [\d.]+ s of .*fast.json, above its peak",
        r.stderr,
        re.M,
    ), r.stderr
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"joint_names": ["joint_1"], "points": [{"t": 0, "q": [0]}]}))
    r = _modc("check", farm, "--traj", str(bad))
    assert r.returncode == 1 and f"{bad}:1:1: error[traj-invalid]" in r.stderr
