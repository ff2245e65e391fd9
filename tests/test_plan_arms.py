"""`modc plan` on arms other than the farm: nothing to collision-check, one joint, random valid
chains, and every design `modc design` proposes for the examples. Whatever the arm, the answer
is a plan that reaches the target or a diagnostic (never a traceback, never inf or nan).

Reached is checked with modc.kinematics.Chain (docs/conventions.md), not with the planner's pinocchio.
"""
from __future__ import annotations

import math
import os
import random
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT, random_units

from modc.compiler import check_file
from modc.kinematics import Chain, matrix_rpy
from modc.plan import Plan, PlanError, plan

NOT_FINITE = re.compile(r"\b(inf|nan)\b", re.IGNORECASE)


def _env() -> dict[str, str]:
    return dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))


def _cli_plan(path: Path, target: str) -> subprocess.CompletedProcess:
    # the planner's wall-clock timeout only as a hang guard: its max_checks bound decides, not the load
    return subprocess.run([sys.executable, "-m", "modc", "plan", str(path), "--to", target, "--timeout", "300"],
                          capture_output=True, text=True, env=_env())


def _outcome(path: Path, target: str, **options) -> Plan | PlanError:
    """The plan, or the PlanError; anything else propagates (a crash fails the test)."""
    try:
        result = plan(path, target, **options)
    except PlanError as e:
        for d in e.diagnostics:
            assert d.hint and not NOT_FINITE.search(d.message + d.hint), d
        return e
    assert not NOT_FINITE.search(result.summary()), result.summary()
    return result


def _assert_reached(result: Plan, robot, target) -> None:
    T = Chain(robot).T_base_tool(np.asarray(result.q[-1]))
    assert np.linalg.norm(T[:3, 3] - np.asarray(target.xyz)) <= target.position_tolerance + 1e-9
    lo = [robot.joint_range(i)[0] for i in range(1, robot.dof + 1)]
    hi = [robot.joint_range(i)[1] for i in range(1, robot.dof + 1)]
    assert all(a - 1e-9 <= v <= b + 1e-9 for q in result.q for v, a, b in zip(q, lo, hi, strict=True))


ONE_JOINT = """robot one {
    allow first-variant
    chain L4(link=200mm)
    target side at (-0.0297, 0.2, 0.148) m
    target posed at (-0.0297, 0.2, 0.148) m rpy (0, 0, 90) deg
}
"""


def test_an_arm_with_nothing_to_check_plans(tmp_path):
    """One module, no obstacle: the SRDF disables the only pair (base_link, link_1), so the planner
    has no pair to check (this crashed with IndexError in CollisionChecker.clearance)."""
    from modc.plan.collision import CollisionChecker

    src = tmp_path / "one.mod"
    src.write_text(ONE_JOINT, encoding="utf-8")
    checked = check_file(src)
    assert checked.ok
    robot = checked.design.robots[0]
    checker = CollisionChecker(robot)
    assert checker.pairs == [] and checker.static_pairs == []
    assert checker.clearance(np.zeros(1)) == (math.inf, None)
    result = _outcome(src, "side")
    assert isinstance(result, Plan)
    _assert_reached(result, robot, robot.targets[0])
    assert result.min_clearance is None and "nothing to check" in result.summary()
    r = _cli_plan(src, "side")
    assert r.returncode == 0 and "Traceback" not in r.stderr, r.stderr


def test_a_one_joint_arm_reaches_a_full_pose(tmp_path):
    """6-D IK on a one-joint arm: pinocchio hands its 6 x 1 Jacobian back flat (this crashed
    with a broadcasting ValueError in ik.py)."""
    src = tmp_path / "one.mod"
    src.write_text(ONE_JOINT, encoding="utf-8")
    robot = check_file(src).design.robots[0]
    result = _outcome(src, "posed")
    assert isinstance(result, Plan)
    _assert_reached(result, robot, robot.targets[1])
    assert math.degrees(result.q[-1][0]) == pytest.approx(90.0, abs=2.0)


def _random_arm(rng: random.Random) -> str:
    units = random_units(rng, lambda i, n: rng.choice("HL"), 400)
    allow = "".join(f"    allow {c}\n" for c in ("first-variant", "last-variant", "illegal-succession",
                                                  "epsilon-exceeded"))
    return f"robot r {{\n{allow}    chain {' - '.join(units)}\n"


@pytest.mark.parametrize("seed", [2, 1, 7, 9, 5, pytest.param(19, marks=pytest.mark.slow)])  # 1 … 6 modules
def test_random_arms_plan_or_say_why(tmp_path, seed):
    """Random valid chains of 1-6 modules and random twists; targets where tool0 really is (with
    and without its orientation), far away, and beside the base: a plan that reaches, or a
    diagnostic with a hint."""
    rng = random.Random(seed)
    nrng = np.random.default_rng(seed)
    head = _random_arm(rng)
    src = tmp_path / "r.mod"
    src.write_text(head + "}\n", encoding="utf-8")
    checked = check_file(src)
    assert checked.ok, [d.message for d in checked.diagnostics if d.is_error]
    robot = checked.design.robots[0]
    lo = np.array([robot.joint_range(i)[0] for i in range(1, robot.dof + 1)])
    hi = np.array([robot.joint_range(i)[1] for i in range(1, robot.dof + 1)])
    T = Chain(robot).T_base_tool(lo + (hi - lo) * nrng.random(robot.dof))
    x, y, z = (float(v) for v in T[:3, 3])
    r, p, w = (math.degrees(a) for a in matrix_rpy(T[:3, :3]))
    src.write_text(head + f"    target fk at ({x!r}, {y!r}, {z!r}) m\n"
                          f"    target pose at ({x!r}, {y!r}, {z!r}) m rpy ({r!r}, {p!r}, {w!r}) deg\n"
                          "    target far at (3, 0, 0.2) m\n    target base at (0, 0, 0.01) m\n}\n", encoding="utf-8")
    robot = check_file(src).design.robots[0]
    outcomes = {t.name: _outcome(src, t.name, timeout=300.0) for t in robot.targets}
    for t in robot.targets:
        if isinstance(outcomes[t.name], Plan):
            _assert_reached(outcomes[t.name], robot, t)
    assert isinstance(outcomes["far"], PlanError) and outcomes["far"].code == "target-unreachable"
    # the position alone is always reachable: the planner finds it, or says what is in the way
    assert isinstance(outcomes["fk"], Plan) or outcomes["fk"].code in ("target-in-collision", "start-in-collision",
                                                                      "no-path")


@pytest.fixture(scope="module")
def designed(tmp_path_factory) -> list[Path]:
    """The robot files `modc design` writes for every example with a design block (top 2)."""
    files: list[Path] = []
    for example in sorted((ROOT / "examples").glob("*.mod")):
        if not re.search(r"^design\s", example.read_text(encoding="utf-8"), re.MULTILINE):
            continue
        out = tmp_path_factory.mktemp(example.stem) / "designs"
        r = subprocess.run([sys.executable, "-m", "modc", "design", str(example), "-o", str(out), "--top", "2",
                            "--no-render"], capture_output=True, text=True, env=_env())
        assert r.returncode == 0 and "Traceback" not in r.stderr, r.stderr
        found = sorted(p for p in out.glob("*.mod"))
        assert found, r.stderr
        files += found
    assert files
    return files


@pytest.mark.slow
def test_plan_every_target_of_every_design(designed):
    """What a new user does next: plan to each target of each proposed design."""
    for path in designed:
        checked = check_file(path)
        assert checked.ok, path
        robot = checked.design.robots[0]
        assert robot.targets, path
        for t in robot.targets:
            r = _cli_plan(path, t.name)
            assert r.returncode in (0, 1) and "Traceback" not in r.stderr, (path, t.name, r.stderr)
            assert not NOT_FINITE.search(r.stdout + r.stderr)
            if r.returncode == 1:  # a clean diagnostic at the target, with its hint
                assert f"{path}:" in r.stderr and "= hint:" in r.stderr
            else:
                assert f"target '{t.name}'" in r.stdout
