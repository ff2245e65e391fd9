"""The exact reach test of 2- and 3-joint chains (modc.design.bounds_exact) is sound - a target
some joint vector reaches, moved within its tolerance, is never excluded, checked against forward
kinematics written here from docs/conventions.md's formula - and tight: every pair a dense scan of
the joint angles puts more than MARGIN (plus the scan's own error) beyond the tolerance is
excluded. The numba kernel and the numpy walk give the same answer, and the design search
returns the same ranking with the test on and off."""
from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import THREE_TARGETS

from modc.compiler import check_text

PIVOTS = np.radians(np.arange(-90.0, 90.1, 15.0))
PORTS = np.radians(np.arange(-180.0, 180.0, 15.0))
TOOL = np.array([0.02, -0.01, 0.06])


def _rot(axis: int, a: np.ndarray) -> np.ndarray:
    """Rotations (..., 3, 3) about x, y or z by the angles a (...)."""
    c, s = np.cos(a), np.sin(a)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    R = np.zeros(np.shape(a) + (3, 3))
    R[..., axis, axis] = 1.0
    R[..., i, i], R[..., j, j], R[..., i, j], R[..., j, i] = c, c, -s, s
    return R


def _fk(units, pivots, ports, q):
    """tool0 (..., 3) and joint 1's origin and axis: prod_i A_t1(pivot_i) A_J(theta_i) A_t2(port_i),
    then the tool; A_t1 = (Ry(pivot), (x01, 0, z01)), A_J = (Rz(theta), (0, 0, z12)), A_t2 =
    (Rx(port), (x23, 0, 0)). pivots, ports (C, n); q (C, ..., n)."""
    extra = q.ndim - 2
    shape = q.shape[:-1]
    R = np.broadcast_to(np.eye(3), shape + (3, 3))
    p = np.zeros(shape + (3,))
    axis = origin = None
    for i, u in enumerate(units):

        def at(a: np.ndarray) -> np.ndarray:
            return np.broadcast_to(a.reshape(a.shape + (1,) * extra), shape)

        p = p + R @ np.array([u.x01, 0.0, u.z01])
        R = R @ _rot(1, at(pivots[:, i]))
        if i == 0:
            origin, axis = p.copy(), R[..., :, 2].copy()
        R = R @ _rot(2, q[..., i])
        p = p + R @ np.array([0.0, 0.0, u.z12])
        if u.link:
            R = R @ _rot(0, at(ports[:, i]))
            p = p + R @ np.array([u.x23, 0.0, 0.0])
    return p + R @ TOOL, origin, axis


def _library():
    c = check_text("design d {\n    target a at (0.3, 0, 0.2) m\n}\n", "d.mod")
    return c.design.problems[0].cell.library


def _settings(rng, n: int, C: int):
    from modc.design import bounds
    from modc.design.batch import geometry

    lib = _library()
    types = [lib.units[k] for k in rng.integers(1, 5, n)]
    piv = PIVOTS[rng.integers(len(PIVOTS), size=(C, n))]
    por = PORTS[rng.integers(len(PORTS), size=(C, n))] * np.array([t.link for t in types], float)
    g = geometry(types, piv, por, [t.x23 for t in types], tuple(TOOL), (0.0, 0.0, 0.0))
    return types, piv, por, bounds.frames(g)


def _pairs(f, x: np.ndarray, tol: float, compiled: bool) -> np.ndarray:
    """(C,): setting c against its own target x[c]."""
    from modc.design import bounds_exact as be

    n = f.t.shape[1] - 1
    P = be.params(f)
    rt, ht = be.circles(f, x)
    idx = np.arange(len(x))
    rt, ht = rt[idx, idx], ht[idx, idx]
    if compiled:
        from modc.design import bounds_exact_jit

        return np.array([bounds_exact_jit.reachable(P[c:c + 1], rt[c:c + 1, None], ht[c:c + 1, None],
                                                    np.array([tol]), n, np.zeros(1, np.int64), be.tables())[0]
                         for c in range(len(x))])
    return be._pairs_numpy(P, rt, ht, np.full(len(x), tol), n)


def _ways() -> list[bool]:
    try:
        import numba  # noqa: F401
    except ImportError:  # pragma: no cover
        return [False]
    return [False, True]


@pytest.mark.parametrize("n", [2, 3])
@pytest.mark.parametrize("compiled", _ways())
def test_a_reached_point_moved_within_its_tolerance_is_never_excluded(n, compiled):
    rng = np.random.default_rng(7 + n)
    C = 400
    for trial, tol in enumerate((0.0, 1e-3, 0.01)):
        types, piv, por, f = _settings(rng, n, C)
        q = rng.uniform(-math.pi, math.pi, (C, n))
        x, _, _ = _fk(types, piv, por, q)
        step = rng.normal(size=(C, 3))
        x = x + tol * 0.999 * step / np.linalg.norm(step, axis=-1, keepdims=True)
        ok = _pairs(f, x, tol, compiled)
        assert ok.all(), (n, trial, np.flatnonzero(~ok)[:5])


def _scan_min(types, piv, por, x: np.ndarray, N: int) -> np.ndarray:
    """(C,) the least distance from x[c] to the circle tool0 sweeps about joint 1's axis, over an
    N x N grid of (theta_2, theta_3) (N samples of theta_2 for two joints)."""
    n = len(types)
    th = np.arange(N) * (2 * math.pi / N) - math.pi
    grid = np.stack(np.meshgrid(th, th, indexing="ij"), -1).reshape(-1, 2) if n == 3 else th[:, None]
    out = []
    for a in range(0, len(x), 4):  # a few settings at a time: (settings, samples, 3, 3) arrays
        s = slice(a, a + 4)
        q = np.zeros((len(x[s]), len(grid), n))
        q[..., 1:] = grid
        tool, p1, z1 = _fk(types, piv[s], por[s], q)
        rel, xr = tool - p1, x[s][:, None] - p1
        h, ht = (rel * z1).sum(-1), (xr * z1).sum(-1)
        rho = np.linalg.norm(rel - h[..., None] * z1, axis=-1)
        rt = np.linalg.norm(xr - ht[..., None] * z1, axis=-1)
        out.append(np.hypot(rho - rt, h - ht).min(-1))
    return np.concatenate(out)


@pytest.mark.parametrize("n", [2, 3])
def test_it_excludes_every_pair_a_dense_scan_finds_out_of_reach(n):
    from modc.design import bounds, bounds_exact

    rng = np.random.default_rng(20 + n)
    C, tol = 80, 2e-3
    types, piv, por, f = _settings(rng, n, C)
    # targets near the workspace (a 3-joint chain's is a solid, a 2-joint chain's a surface), in and out
    x, p1, _ = _fk(types, piv, por, rng.uniform(-math.pi, math.pi, (C, n)))
    if n == 3:
        x = p1 + (x - p1) * rng.uniform(0.6, 1.3, (C, 1)) + rng.normal(scale=0.05, size=(C, 3))
    else:
        x = x + rng.normal(scale=0.006, size=(C, 3))
    N = 240 if n == 3 else 8000
    scan = _scan_min(types, piv, por, x, N)
    # the scan's own error: no point of the torus is farther than a half-step's chord from a sample
    r = np.linalg.norm(f.t[:, 2:], axis=-1).sum(-1)
    err = r * 2 * math.sin(math.pi / N / 2) * (2 if n == 3 else 1)
    ok = _pairs(f, x, tol, False)
    out = scan - err > tol + bounds_exact.MARGIN
    assert out.sum() > 0.3 * C and (~out).sum() > 0.1 * C  # both kinds of pairs
    assert not ok[out].any()  # tight: nothing a margin out of reach is kept
    assert ok[scan <= tol].all()  # sound on the scan's own reachable pairs
    loose = np.diag(bounds.possible(f, x, np.full(C, tol)))
    truly_out = scan - err > tol
    assert (~ok[truly_out]).mean() > 0.9  # 1.0 for both on these seeds (the rest would lie within MARGIN)
    # the interval bounds (bounds.possible) alone keep a good share of those
    assert (loose & ~ok).sum() > 0.2 * out.sum()  # 17 of 51, 29 of 61 here


@pytest.mark.parametrize("n", [2, 3])
def test_the_kernel_and_the_numpy_walk_agree(n):
    pytest.importorskip("numba")
    from modc.design import bounds_exact as be

    rng = np.random.default_rng(40 + n)
    C = 600
    types, piv, por, f = _settings(rng, n, C)
    x, p1, _ = _fk(types, piv, por, rng.uniform(-math.pi, math.pi, (C, n)))
    x = p1 + (x - p1) * rng.uniform(0.8, 1.2, (C, 1)) + rng.normal(scale=0.02, size=(C, 3))
    kept = 0
    for tol in (0.0, 1e-3, 5e-3):
        a, b = _pairs(f, x, tol, False), _pairs(f, x, tol, True)
        assert (a == b).all()
        kept += a.sum()
    assert 0 < kept < 3 * C
    # every target at once (shared targets, the failing one moved to the front): the same answer
    xyz, tol_t = x[:5], np.array([0.004, 0.0, 0.01, 0.002, 0.003])
    a, b = be.reachable(f, xyz, tol_t, compiled=False), be.reachable(f, xyz, tol_t, compiled=True)
    assert (a == b).all()
    each = np.stack([_pairs(f, np.repeat(xyz[j:j + 1], C, 0), tol_t[j], False) for j in range(5)], -1)
    assert (a == each.all(-1)).all()


def _problem(text: str):
    checked = check_text(text, "cell.mod")
    assert checked.ok, [d.message for d in checked.diagnostics]
    return checked.design.problems[0]


CELL = THREE_TARGETS.removesuffix("}\n")  # the design benchmark's cell, its block left open


def _ranking(o) -> list[tuple]:
    return [(d.chain(), tuple(round(v, 9) for v in d.verified.robot.base.xyz), round(d.mass, 9), round(d.margin, 6))
            for d in o.designs]


@pytest.mark.parametrize("grid", [
    "",
    "    base within box size (0.1, 0.1, 0) m at (0, 0, 0) m step 50 mm\n",
])
def test_the_exact_test_changes_no_ranking(monkeypatch, grid):
    from modc.design import bounds_exact, run, search

    calls = []
    real = bounds_exact.reachable

    def counted(f, xyz, tol, compiled=None):
        out = real(f, xyz, tol, compiled)
        calls.append((out.size, int((~out).sum())))
        return out

    monkeypatch.setattr(bounds_exact, "reachable", counted)
    p = _problem(CELL + grid + "}\n")
    on = run.design(p, top=1)
    assert on.designs and sum(c[1] for c in calls) > 0  # it ran and excluded settings
    monkeypatch.setattr(search, "EXACT", False)
    off = run.design(p, top=1)
    assert _ranking(on) == _ranking(off)
    assert on.excluded > off.excluded


def test_prune_tests_the_rest_of_a_block_only_when_its_sample_says_it_pays():
    from modc.design import bounds_exact as be

    rng = np.random.default_rng(60)
    C = 400
    types, piv, por, f = _settings(rng, 3, C)
    x, p1, _ = _fk(types, piv, por, rng.uniform(-math.pi, math.pi, (C, 3)))
    seen = set()
    # a point out of most settings' reach; one most reach (a wide tolerance)
    for xyz, tol in (((p1[0] + (x[0] - p1[0]) * 1.5)[None], np.array([0.003])), (x[3:4], np.array([0.3]))):
        every = be.reachable(f, xyz, tol, compiled=False)
        got = be.prune(f, xyz, tol, compiled=False)
        sample = np.zeros(C, bool)
        sample[::be.SAMPLE] = True
        assert (got[sample] == every[sample]).all()
        pays = (~every[sample]).mean() >= be.PAYS
        seen.add(pays)
        assert (got == every).all() if pays else got[~sample].all()
    assert seen == {True, False}


def test_the_kernels_file_names_the_shared_code_it_compiles():
    """numba keys a cached kernel on its own file: bounds_exact_jit.SHARED must change with
    bounds_exact.py (box, newton, the constants), or a cache would keep the old code."""
    import hashlib
    from pathlib import Path

    from modc.design import bounds_exact

    text = Path(bounds_exact.__file__).read_bytes()
    source = Path(bounds_exact.__file__).with_name("bounds_exact_jit.py").read_text(encoding="utf-8")
    assert f'SHARED = "{hashlib.sha256(text).hexdigest()}"' in source, \
        "bounds_exact.py changed: put its sha256 in bounds_exact_jit.SHARED"
