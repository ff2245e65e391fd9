"""Position and orientation at one joint vector (modc.design.bounds_tilt): sound - a pose some
joint vector of a 2- or 3-joint setting reaches, moved within its tolerances (position and
`pointing` axis or full `rpy`), is never excluded, checked against the batched forward kinematics
(tested equal to modc.kinematics elsewhere) - and strong: pairs each test alone keeps are
excluded. The numba kernel and the numpy walk give the same answer, and the design search
returns the same ranking with the test on and off."""
from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pytest

from modc.compiler import check_text

PIVOTS = np.radians(np.arange(-90.0, 90.1, 15.0))
PORTS = np.radians(np.arange(-180.0, 180.0, 15.0))


def _library():
    return check_text("design d {\n    target a at (0.3, 0, 0.2) m\n}\n", "d.mod").design.problems[0].cell.library


def _turn(v: np.ndarray) -> np.ndarray:
    """The rotation by the rotation vector v (Rodrigues)."""
    a = float(np.linalg.norm(v))
    k = v / a
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + np.sin(a) * K + (1 - np.cos(a)) * K @ K


def _setting(rng, n: int, C: int):
    from modc.design import bounds
    from modc.design.batch import geometry

    lib = _library()
    types = [lib.units[k] for k in rng.integers(1, 5, n)]
    piv = PIVOTS[rng.integers(len(PIVOTS), size=(C, n))]
    por = PORTS[rng.integers(len(PORTS), size=(C, n))] * np.array([t.link for t in types], float)
    g = geometry(types, piv, por, [t.x23 for t in types], (0.02, -0.01, 0.06), tuple(rng.uniform(-1, 1, 3)))
    return g, bounds.frames(g)


def _target(R: np.ndarray, x: np.ndarray, tol_p: float, tol_r: float, pointed: bool):
    from modc.design import reach

    return reach.Targets(x[None], R[None], np.array([True]), np.array([tol_p]), np.array([tol_r]), ("t",),
                         R[:, 0][None], np.array([pointed]))


@pytest.mark.parametrize("compiled", [False, True])
def test_a_pose_the_arm_reaches_is_never_excluded(compiled):
    from modc.design import bounds, bounds_tilt
    from modc.design.batch import forward

    rng = np.random.default_rng(1)
    for _ in range(16):
        n = int(rng.integers(2, 4))
        g, f = _setting(rng, n, 24)
        q = rng.uniform(-np.pi, np.pi, (24, 1, 1, n))
        T = forward(g, q)[2][:, 0, 0]
        for c in range(24):
            tol_p, tol_r = [(0.005, np.radians(5)), (0.0005, np.radians(0.5)), (0.02, np.radians(20))][c % 3]
            off = rng.normal(size=3)
            off *= 0.999 * tol_p * rng.random() / np.linalg.norm(off)
            v = rng.normal(size=3)
            v *= 0.999 * tol_r * rng.random() / np.linalg.norm(v)
            tg = _target(_turn(v) @ T[c, :3, :3], T[c, :3, 3] + off, tol_p, tol_r, bool(c % 2))
            one = bounds.Frames(f.R[c:c + 1], f.t[c:c + 1])
            assert bounds_tilt.posed(one, tg, np.array([0]), compiled=compiled)[0], (n, c)


def test_the_kernel_and_the_numpy_walk_agree_and_the_test_is_strong():
    """On targets each test alone keeps (position in reach, tilt in range), the pair test
    excludes most, the same settings either way."""
    from modc.design import bounds, bounds_exact, bounds_tilt, reach

    rng = np.random.default_rng(4)
    kept = excluded = 0
    for _ in range(6):
        g, f = _setting(rng, 3, 600)
        R = np.linalg.qr(rng.normal(size=(3, 3)))[0]
        R *= np.sign(np.linalg.det(R))
        x = rng.uniform(-0.35, 0.35, 3)
        tg = reach.Targets(x[None], R[None], np.array([True]), np.array([0.005]), np.array([np.radians(5)]), ("t",),
                           np.array([[0.0, 0.0, -1.0]]), np.array([True]))
        alone = bounds.posed(f, tg, every=True) & bounds_exact.reachable(f, tg.xyz, tg.tol_p, compiled=False)
        a = bounds_tilt.posed(f, tg, np.array([0]), compiled=False)
        b = bounds_tilt.posed(f, tg, np.array([0]), compiled=True)
        np.testing.assert_array_equal(a, b)
        assert not (a & ~alone).any()  # never keeps what a test alone excludes (both sound, this one stronger)
        kept += int(alone.sum())
        excluded += int((alone & ~a).sum())
    assert kept > 100 and excluded > kept // 2, (kept, excluded)


def test_the_kernels_file_names_the_shared_code_it_compiles():
    from modc.design import bounds_exact, bounds_tilt, bounds_tilt_jit

    text = Path(bounds_exact.__file__).read_bytes()
    assert bounds_tilt_jit.SHARED == hashlib.sha256(text).hexdigest(), \
        "bounds_exact.py changed: put its sha256 in bounds_tilt_jit.SHARED"
    ours = (bounds_tilt_jit.TILT_MARGIN, bounds_tilt_jit.TILT_SLACK)
    assert ours == (bounds_tilt.TILT_MARGIN, bounds_tilt.TILT_SLACK)


CELL = """design t {
    target a at (0.30, 0.0, 0.15) m pointing (0, 0, -1) within 5 mm, 5 deg
    target b at (0.25, 0.10, 0.25) m
    units 3
    modules H1, L3, L4
}
"""


@pytest.mark.slow
def test_the_search_ranks_the_same_with_the_test_on_and_off(monkeypatch):
    from modc.design import run, search

    p = check_text(CELL, "t.mod").design.problems[0]
    rows = {}
    for flag in (True, False):
        monkeypatch.setattr(search, "TILTED", flag)
        o = run.design(p, top=3, seed=0)
        rows[flag] = ([(d.chain(), round(d.mass, 9), round(d.margin, 9)) for d in o.designs], o.evaluated, o.excluded)
    assert rows[True][0] == rows[False][0] and len(rows[True][0]) == 3
    assert rows[True][1] == rows[False][1] and rows[True][2] > rows[False][2]  # same settings, more excluded
