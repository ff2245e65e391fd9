"""`pointing (x, y, z)` on targets and regions: only tool0's x axis (the approach) is constrained,
the turn about it is free. The language (.mod and YAML), the written robot, the design search's
batched IK and exact check, and the planner's IK."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from modc.compiler import check_text

ROOT = Path(__file__).resolve().parent.parent


def _angle(x, d) -> float:
    return float(np.degrees(np.arccos(np.clip(np.dot(x, d) / np.linalg.norm(d), -1.0, 1.0))))


def test_pointing_is_lowered_normalised_and_written_back():
    from modc.model.write import robot_file_text

    text = """robot r {
    chain H1 - L3 - L3
    target a at (0.3, 0, 0.2) m pointing (0, 0, -2) within 5 mm, 5 deg
    region tray box size (0.1, 0.05, 0) m at (0.3, 0, 0.1) m grid 2 x 2 x 1 pointing (1, 1, 0)
}
"""
    checked = check_text(text, "r.mod")
    assert checked.ok, [d.message for d in checked.diagnostics]
    r = checked.design.robots[0]
    assert r.targets[0].pointing == (0.0, 0.0, -1.0) and r.targets[0].rpy is None
    assert r.regions[0].points()[3].pointing == pytest.approx((2 ** -0.5, 2 ** -0.5, 0.0))
    again = check_text(robot_file_text(r), "again.mod")
    assert again.ok
    t0, t1 = r.targets[0], again.design.robots[0].targets[0]
    assert (t1.xyz, t1.pointing) == (t0.xyz, t0.pointing)
    assert t1.orientation_tolerance == pytest.approx(t0.orientation_tolerance)
    assert again.design.robots[0].regions[0].pointing == pytest.approx(r.regions[0].pointing)


@pytest.mark.parametrize("vector, code", [("(0, 0, 0)", "nonpositive-size"), ("(0, 0, -1) m", "wrong-unit"),
                                          ("(0, -1)", "vector-arity")])
def test_a_bad_direction_is_a_diagnostic(vector, code):
    checked = check_text(f"robot r {{\n    chain H1 - L3\n    target a at (0.3, 0, 0.2) m pointing {vector}\n}}\n",
                         "r.mod")
    assert not checked.ok and [d.code for d in checked.diagnostics if d.is_error] == [code]
    assert all(d.span.line == 3 for d in checked.diagnostics)


def test_rpy_and_pointing_together_do_not_parse():
    checked = check_text("robot r {\n    chain H1 - L3\n    target a at (0.3, 0, 0.2) m rpy (0, 0, 0) deg "
                         "pointing (0, 0, -1)\n}\n", "r.mod")
    assert not checked.ok


def test_yaml_pointing():
    text = """robots:
  - name: r
    chain: [H1, L3]
    targets:
      a: {at: "(0.3, 0, 0.2) m", pointing: "(0, 0, -1)", within: "5 mm, 5 deg"}
    regions:
      tray: {size: "(0.1, 0.05, 0) m", at: "(0.3, 0, 0.1) m", grid: "2 x 2 x 1", pointing: "(0, 0, -1)"}
"""
    checked = check_text(text, "r.yaml")
    assert checked.ok, [d.message for d in checked.diagnostics]
    r = checked.design.robots[0]
    assert r.targets[0].pointing == (0.0, 0.0, -1.0) and r.regions[0].pointing == (0.0, 0.0, -1.0)
    both = check_text(text.replace('pointing: "(0, 0, -1)", within', 'rpy: "(0, 0, 0) deg", pointing: "(0, 0, -1)", '
                                   'within'), "r.yaml")
    assert not both.ok and "rpy or pointing, not both" in both.diagnostics[0].message


def _farm():
    from modc import api

    return api.load(ROOT / "examples" / "farm.mod")


def test_batch_ik_meets_an_axis_and_leaves_the_turn_about_it_free():
    from modc.design import reach
    from modc.design.batch import geometry
    from modc.kinematics import Chain
    from modc.model import Target

    r = _farm()
    T = Chain(r).T_base_tool(np.radians([30.0, -40.0, 70.0]))
    # the direction tool0's x axis has there, and the z axis, which a full pose would also fix
    goal = Target(name="g", xyz=tuple(T[:3, 3]), pointing=tuple(T[:3, 0]), orientation_tolerance=np.radians(1.0))
    g = geometry([r.library.units[u.kind] for u in r.units], np.array([[u.pivot for u in r.units]]),
                 np.array([[u.port for u in r.units]]), [r.link_length(u) for u in r.units], r.tool.xyz, r.tool.rpy)
    lim = np.radians(170.0) * np.ones(3)
    q, ep, er = reach.solve(g, reach.Targets.of([goal]), reach.seeds(3, 8, -lim, lim, 0), -lim, lim)
    ok = (ep[0, 0] < 1e-6) & (er[0, 0] < 1e-5)
    assert ok.any()
    for s in np.flatnonzero(ok):  # re-measured with modc.kinematics
        Ts = Chain(r).T_base_tool(q[0, 0, s])
        assert np.linalg.norm(Ts[:3, 3] - T[:3, 3]) < 1e-5 and _angle(Ts[:3, 0], T[:3, 0]) < 1e-3
    # the error the IK reports for a pose off the axis is the angle between the axes
    from modc.design.reach import axis_error

    e = axis_error(np.array([[1.0], [0.0], [0.0]]), np.array([[0.0], [0.0], [-1.0]]))
    assert np.linalg.norm(e) == pytest.approx(np.pi / 2) and e[0, 0] == 0.0


def test_plan_ik_meets_an_axis():
    from modc.kinematics import Chain
    from modc.plan import ik
    from modc.plan.collision import CollisionChecker

    r = _farm()
    T = Chain(r).T_base_tool(np.radians([-20.0, 50.0, 100.0]))
    checker = CollisionChecker(r)
    solver = ik.PositionIK(checker.model, checker.data, checker.tool_frame, checker.lower, checker.upper,
                           None, T[:3, 0])
    sols, _ = ik.solve(solver, T[:3, 3], np.zeros(3), 24, 0, tolerance=(1e-4, np.radians(0.5)))
    assert sols
    for s in sols:
        Ts = Chain(r).T_base_tool(s.q)
        assert np.linalg.norm(Ts[:3, 3] - T[:3, 3]) < 1e-4 and _angle(Ts[:3, 0], T[:3, 0]) < 0.5
