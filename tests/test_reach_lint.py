"""Reach at lint time (modc/passes/check_reach.py, warning target-out-of-reach).

The bound is checked against modc.kinematics.Chain (numpy, docs/conventions.md), which the pass does
not use: the pass's joint origins agree with Chain's, and in random poses of random arms tool0
stays inside the shell the pass computes, so the warning never fires on a reachable target.
"""
from __future__ import annotations

import json
import math
import os
import random
import subprocess
import sys

import numpy as np
import pytest
from conftest import ROOT, random_units

from modc.compiler import check_file, check_text
from modc.kinematics import Chain
from modc.passes.check_reach import chain_points, reach_shell

CODE = "target-out-of-reach"


def _random_chain(rng: random.Random) -> str:
    units = random_units(rng, lambda i, n: "H" if i < n - 1 else "L", 500)
    tool = f"({rng.uniform(-0.1, 0.1):.3f}, {rng.uniform(-0.1, 0.1):.3f}, {rng.uniform(0, 0.15):.3f}) m"
    return (f"robot r {{\n    allow epsilon-exceeded\n    allow first-variant\n    chain {' - '.join(units)}\n"
            f"    tool at {tool} rpy (10, 20, 30) deg\n")


def _robot(text: str):
    checked = check_text(text, "r.mod")
    assert checked.ok, [d.message for d in checked.diagnostics if d.is_error]
    return checked


def _reach_warnings(checked) -> list:
    return [d for d in checked.diagnostics if d.code == CODE]


def test_the_shell_contains_every_pose_of_random_arms():
    rng = random.Random(21)
    nrng = np.random.default_rng(21)
    for _ in range(40):
        robot = _robot(_random_chain(rng) + "}\n").design.robots[0]
        chain = Chain(robot)
        # the pass's plain-Python frames are the paper's frames (joint origins and tool0 at q = 0)
        want = [p for p, _ in chain.joint_axes()] + [chain.T_base_tool(np.zeros(robot.dof))[:3, 3]]
        assert np.allclose(chain_points(robot), want, atol=1e-12)
        origin, r_min, r_max, _ = reach_shell(robot)
        lo = np.array([robot.joint_range(i)[0] for i in range(1, robot.dof + 1)])
        hi = np.array([robot.joint_range(i)[1] for i in range(1, robot.dof + 1)])
        d = [float(np.linalg.norm(chain.T_base_tool(lo + (hi - lo) * nrng.random(robot.dof))[:3, 3] - origin))
             for _ in range(200)]
        assert r_min - 1e-12 <= min(d) and max(d) <= r_max + 1e-12


def test_reachable_targets_of_random_arms_never_warn():
    """Targets put where tool0 really is (FK at random joint angles, tolerance 1 µm) get no warning."""
    rng = random.Random(5)
    nrng = np.random.default_rng(5)
    for _ in range(25):
        text = _random_chain(rng)
        robot = _robot(text + "}\n").design.robots[0]
        chain = Chain(robot)
        lines = []
        for k in range(6):
            q = nrng.uniform(-math.pi, math.pi, robot.dof)
            x, y, z = (float(v) for v in chain.T_base_tool(q)[:3, 3])
            lines.append(f"    target t{k} at ({x!r}, {y!r}, {z!r}) m within 0.001 mm, 2 deg\n")
        assert _reach_warnings(_robot(text + "".join(lines) + "}\n")) == []


def test_one_joint_arm_reaches_exactly_its_circle():
    """One unit: tool0 stays at one distance from joint_1, so the shell is that sphere."""
    base = "robot one {\n    allow first-variant\n    chain L4(link=200mm)\n"
    robot = _robot(base + "}\n").design.robots[0]
    origin, r_min, r_max, _ = reach_shell(robot)
    assert r_min == pytest.approx(r_max) and r_max == pytest.approx(0.2)
    on = f"    target on at ({origin[0] + 0.2!r}, {origin[1]!r}, {origin[2]!r}) m\n"
    inside = f"    target inside at ({origin[0] + 0.1}, {origin[1]}, {origin[2]}) m\n"
    outside = f"    target outside at ({origin[0] + 0.3}, {origin[1]}, {origin[2]}) m\n"
    warned = _reach_warnings(_robot(base + on + inside + outside + "}\n"))
    assert [d.message.split("'")[1] for d in warned] == ["inside", "outside"]
    assert "at least 0.200 m" in warned[0].message and "within 0.200 m" in warned[1].message


def test_a_target_2_m_from_a_half_metre_arm_is_a_lint_warning(tmp_path):
    """The issue's case: lint and the compile both say it, at the target, with the numbers."""
    src = tmp_path / "arm.mod"
    src.write_text("robot arm {\n    chain H1 - L3(link=350mm)\n    target near at (0.3, 0, 0.3) m\n"
                   "    target far at (2, 0, 0) m\n}\n", encoding="utf-8")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    r = subprocess.run([sys.executable, "-m", "modc", "lint", str(src), "--format", "json"],
                       capture_output=True, text=True, env=env)
    assert r.returncode == 0, r.stderr  # a warning: lint still passes
    (d,) = json.loads(r.stdout)["diagnostics"]
    assert d["code"] == CODE and d["severity"] == "warning"
    assert (d["line"], d["col"]) == (4, 5)
    assert d["message"] == ("target 'far' is out of reach: it is 2.005 m from joint_1, "
                            "and tool0 is always within 0.497 m of it")
    assert "0.497 m" in d["hint"] and "lengthen the arm" in d["hint"]
    checked = check_file(src, analyses=frozenset({"torque"}))  # the compile's check
    assert [w.code for w in checked.diagnostics if not w.is_error] == [CODE]


def test_no_example_and_no_corpus_case_of_another_code_warns():
    """Sound means silent on every file the project ships (examples, editor tests, corpus)."""
    files = sorted([*(ROOT / "examples").glob("*.mod"), *(ROOT / "editors").rglob("*.mod"),
                    *(ROOT / "tests" / "diagnostics").glob("*.mod")])
    assert len(files) > 20
    for f in files:
        if f.name.startswith(CODE):
            continue
        assert _reach_warnings(check_file(f)) == [], f
