"""The orientation bounds (modc.design.bounds.posed) are sound: a pose some joint vector reaches,
moved anywhere within the target's tolerances, is never excluded - checked against forward
kinematics written here from docs/conventions.md's formula, on random settings, joint vectors,
tools and tolerances - and they do exclude: a 3-joint arm meets a 6-D pose only on a 3-D set."""
from __future__ import annotations

import math

import numpy as np
import pytest

from modc.compiler import check_text
from modc.kinematics import rpy_matrix

PIVOTS = np.radians(np.arange(-90.0, 90.1, 15.0))
PORTS = np.radians(np.arange(-180.0, 180.0, 15.0))


def _axis_angle(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Rotations (..., 3, 3) about unit axes (..., 3) by angles (...): Rodrigues."""
    k = np.zeros(axis.shape[:-1] + (3, 3))
    k[..., 0, 1], k[..., 0, 2], k[..., 1, 2] = -axis[..., 2], axis[..., 1], -axis[..., 0]
    k = k - np.swapaxes(k, -1, -2)
    a = angle[..., None, None]
    return np.eye(3) + np.sin(a) * k + (1 - np.cos(a)) * (k @ k)


def _fk(units, pivots, ports, q, tool_xyz, tool_R):
    """tool0's pose (position (C, 3), rotation (C, 3, 3)): T = prod_i A_t1(pivot_i) A_J(theta_i)
    A_t2(port_i), then the tool; A_t1 = (Ry(pivot), (x01, 0, z01)), A_J = (Rz(theta), (0, 0, z12)),
    A_t2 = (Rx(port), (x23, 0, 0))."""
    ex, ey, ez = np.eye(3)
    C = len(q)
    R = np.broadcast_to(np.eye(3), (C, 3, 3))
    p = np.zeros((C, 3))
    for i, u in enumerate(units):
        p = p + R @ np.array([u.x01, 0.0, u.z01])
        R = R @ _axis_angle(np.broadcast_to(ey, (C, 3)), pivots[:, i])
        R = R @ _axis_angle(np.broadcast_to(ez, (C, 3)), q[:, i])
        p = p + R @ np.array([0.0, 0.0, u.z12])
        if u.link:
            R = R @ _axis_angle(np.broadcast_to(ex, (C, 3)), ports[:, i])
            p = p + R @ np.array([u.x23, 0.0, 0.0])
    return p + R @ tool_xyz, R @ tool_R


def _perpendicular(rng, v: np.ndarray) -> np.ndarray:
    """Random unit vectors perpendicular to the unit vectors v (C, 3)."""
    r = rng.normal(size=v.shape)
    r -= (r * v).sum(-1, keepdims=True) * v
    return r / np.linalg.norm(r, axis=-1, keepdims=True)


def _library():
    c = check_text("design d {\n    target a at (0.3, 0, 0.2) m\n}\n", "d.mod")
    return c.design.problems[0].cell.library


@pytest.mark.parametrize("n", [1, 2, 3, 4, 6])
def test_a_reached_pose_moved_within_its_tolerances_is_never_excluded(n):
    from modc.design import bounds
    from modc.design.batch import geometry
    from modc.design.reach import Targets

    lib = _library()
    rng = np.random.default_rng(100 + n)
    C = 300
    for trial in range(3):
        kinds = rng.integers(1, 5, n)
        types = [lib.units[k] for k in kinds]
        piv = PIVOTS[rng.integers(len(PIVOTS), size=(C, n))]
        por = PORTS[rng.integers(len(PORTS), size=(C, n))] * np.array([t.link for t in types], float)
        q = rng.uniform(-math.pi, math.pi, (C, n))
        tool_xyz = rng.uniform(-0.08, 0.08, 3)
        tool_rpy = tuple(rng.uniform(-math.pi, math.pi, 3))
        x, R = _fk(types, piv, por, q, tool_xyz, rpy_matrix(tool_rpy))
        tol_p = rng.uniform(0.0, 0.01, C) * (trial > 0)
        tol_r = rng.uniform(0.0, math.radians(10.0), C) * (trial > 0)
        # each target: its setting's pose moved to the edge of its tolerances
        step = rng.normal(size=(C, 3))
        xt = x + tol_p[:, None] * 0.999 * step / np.linalg.norm(step, axis=-1, keepdims=True)
        axis = rng.normal(size=(C, 3))
        turn = _axis_angle(axis / np.linalg.norm(axis, axis=-1, keepdims=True), tol_r * 0.999)
        Rt = turn @ R
        d = np.einsum("cij,cj->ci", _axis_angle(_perpendicular(rng, R[:, :, 0]), tol_r * 0.999), R[:, :, 0])
        g = geometry(types, piv, por, [t.x23 for t in types], tuple(tool_xyz), tool_rpy)
        f = bounds.frames(g)
        for pointed in (False, True):
            tg = Targets(xt, Rt, np.ones(C, bool), tol_p, tol_r, tuple(f"t{i}" for i in range(C)), d,
                         np.full(C, pointed))
            ok = bounds.posed(f, tg)
            assert np.diag(ok).all(), (n, trial, pointed, np.flatnonzero(~np.diag(ok))[:5])
            # every target at once, each test on the settings the cheaper ones left: the same answer
            some = tg.take(np.arange(0, C, 37))
            assert (bounds.posed(f, some, every=True) == bounds.posed(f, some).all(-1)).all()
            # targets sharing a rotation (a region's points) are tested once: the same columns
            twice = bounds.posed(f, tg.take(np.array([3, 5, 3, 3])))
            assert (twice[:, 0] == twice[:, 2]).all() and (twice[:, :2] == ok[:, [3, 5]]).all()
            if n <= 3 and not pointed:
                assert (~ok).mean() > 0.5  # a 6-D pose is out of most settings' reach


def test_targets_without_an_orientation_are_left_to_the_position_bounds():
    from modc.design import bounds
    from modc.design.batch import geometry
    from modc.design.reach import Targets

    lib = _library()
    types = [lib.units[k] for k in (1, 3)]
    g = geometry(types, np.zeros((4, 2)), np.zeros((4, 2)), [t.x23 for t in types], (0.0, 0.0, 0.0), (0, 0, 0))
    tg = Targets(np.full((2, 3), 5.0), np.stack([np.eye(3)] * 2), np.zeros(2, bool), np.zeros(2), np.zeros(2),
                 ("a", "b"), np.zeros((2, 3)), np.zeros(2, bool))
    assert bounds.posed(bounds.frames(g), tg).all()
