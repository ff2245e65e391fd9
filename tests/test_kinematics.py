"""The paper's three-frame kinematics (docs/conventions.md), checked against the equations as printed."""
from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import ROOT, checked_ok

from modc.compiler import check_file
from modc.kinematics import A_J, A_t1, A_t2, Chain, matrix_rpy, rpy_matrix


def paper_eq4(a, x01, z01):  # eq. (4), entries as printed
    return np.array(
        [[math.cos(a), 0, math.sin(a), x01], [0, 1, 0, 0], [-math.sin(a), 0, math.cos(a), z01], [0, 0, 0, 1]]
    )


def paper_eq5(t, z12):
    return np.array([[math.cos(t), -math.sin(t), 0, 0], [math.sin(t), math.cos(t), 0, 0], [0, 0, 1, z12], [0, 0, 0, 1]])


def paper_eq6(a, x23):
    return np.array([[1, 0, 0, x23], [0, math.cos(a), -math.sin(a), 0], [0, math.sin(a), math.cos(a), 0], [0, 0, 0, 1]])


@pytest.mark.parametrize("angle", [0.0, 0.3, -1.2, math.pi / 2, 2.5])
def test_frame_matrices_are_the_papers(angle):
    assert np.allclose(A_t1(angle, -0.0297, 0.075), paper_eq4(angle, -0.0297, 0.075), atol=1e-15)
    assert np.allclose(A_J(angle, 0.073), paper_eq5(angle, 0.073), atol=1e-15)
    assert np.allclose(A_t2(angle, 0.22), paper_eq6(angle, 0.22), atol=1e-15)


def test_product_of_units_is_eq3():
    """T_base_tool = prod_i A_t1 A_J (A_t2 for units 3/4), with Table-free numbers from section 3.1."""
    r = checked_ok(
        "robot r { chain H1 - H4(pivot=-90deg, port=45deg) - L3(pivot=30deg, link=150mm) - L2 }"
    ).design.robots[0]
    q = np.array([0.1, -0.7, 1.3, 2.0])
    d = math.radians
    expected = (
        paper_eq4(0, 0, 0.074) @ paper_eq5(q[0], 0.073)
        @ paper_eq4(d(-90), -0.0297, 0.075) @ paper_eq5(q[1], 0.073) @ paper_eq6(d(45), 0.22)
        @ paper_eq4(d(30), 0, 0.074) @ paper_eq5(q[2], 0.073) @ paper_eq6(0, 0.15)
        @ paper_eq4(0, -0.0297, 0.075) @ paper_eq5(q[3], 0.073)
    )
    assert np.abs(Chain(r).T_base_tool(q) - expected).max() < 1e-14


def test_tool_offset_follows_the_last_frame():
    r = checked_ok("robot r { chain H1 - L3 tool at (0.05, 0, 0.01) m rpy (0, 90, 0) deg }").design.robots[0]
    ch = Chain(r)
    q = np.array([0.4, -0.2])
    T_flange = ch.T_base_flange(q)
    T_tool = np.eye(4)
    T_tool[:3, :3] = rpy_matrix((0, math.pi / 2, 0))
    T_tool[:3, 3] = (0.05, 0, 0.01)
    assert np.allclose(ch.T_base_tool(q), T_flange @ T_tool, atol=1e-15)


def test_planar_example_axes_are_parallel():
    """Table 3 I(a), H3-L4: both axes vertical, 0.22 m + x01 apart, as the paper's planar arm."""
    r = check_file(ROOT / "examples" / "table3_planar.mod").design.robots[0]
    (p1, z1), (p2, z2) = Chain(r).joint_axes()
    assert np.allclose(z1, z2) and np.allclose(z1, [0, 0, 1])
    assert np.isclose(np.linalg.norm((p2 - p1)[:2]), 0.22 - 0.0297)


def test_raven_example_has_a_remote_centre_of_motion():
    """Table 3 III(e): axes meet at 75° and 45°, all three through one point."""
    r = check_file(ROOT / "examples" / "table3_raven.mod").design.robots[0]
    axes = Chain(r).joint_axes()

    def gap(i, j):
        (p, u), (s, v) = axes[i], axes[j]
        n = np.cross(u, v)
        return abs((s - p) @ n) / np.linalg.norm(n)

    assert max(gap(0, 1), gap(1, 2), gap(0, 2)) < 1e-6

    def angle(i, j):
        return math.degrees(math.acos(abs(axes[i][1] @ axes[j][1])))

    assert angle(0, 1) == pytest.approx(75) and angle(1, 2) == pytest.approx(45)


def test_skew_example_twist_is_45_degrees_between_axes_2_and_3():
    r = check_file(ROOT / "examples" / "table3_skew.mod").design.robots[0]
    axes = Chain(r).joint_axes(np.array([0.3, -0.5, 0.9]))
    cos = abs(axes[1][1] @ axes[2][1])
    assert math.degrees(math.acos(cos)) == pytest.approx(45)


@pytest.mark.parametrize("rpy", [(0.1, 0.2, 0.3), (0.3, math.pi / 2, 0.2), (0, -math.pi / 2, 1.0),
                                 (1, math.pi / 2 - 1e-8, 2), (-2, -math.pi / 2 + 1e-11, 3)])
def test_rpy_round_trip_is_exact_even_at_gimbal_lock(rpy):
    R = rpy_matrix(rpy)
    assert np.abs(rpy_matrix(matrix_rpy(R)) - R).max() < 1e-12


def test_frames_api_names_every_frame():
    r = checked_ok("robot r { chain H1 - H4(pivot=-90deg) - L4 }").design.robots[0]
    frames = Chain(r).frames(np.zeros(3))
    assert [sorted(f) for f in frames] == [["T_base_end", "T_base_joint", "T_base_twist1", "T_base_unit"]] * 3
    assert np.allclose(frames[0]["T_base_joint"][:3, 3], [0, 0, 0.147])
    with pytest.raises(ValueError):
        Chain(r).frames(np.zeros(2))


def test_python_api_loads_and_computes():
    import modc
    from modc.api import ModcError

    robot = modc.load(ROOT / "examples" / "farm.mod")
    T = modc.chain(robot).T_base_tool([0, 0, 0])
    assert T.shape == (4, 4) and robot.file_stem == "mod3_farm"
    with pytest.raises(ModcError) as e:
        modc.load(ROOT / "examples" / "no-such-arm.mod")
    assert "file-not-found" in str(e.value.diagnostics[0].code)
