"""The orientation (tilt and wrist) bounds per family of settings (modc.design.prefix.fits) are sound: a
pose some setting reaches, moved within the target's tolerances, never excludes the families
that hold that setting - at any depth, with any cap - checked against the chain's product
K_0 Rz(q_1) K_1 … Rz(q_n) K_n over random shapes, settings and joint vectors; and a posed cell
ranks the same with the family bound off."""
from __future__ import annotations

import math

import numpy as np
import pytest

from modc.compiler import check_text

PIVOTS = np.radians(np.arange(-90.0, 90.1, 30.0))
PORTS = np.radians(np.arange(-180.0, 180.0, 30.0))


def _rz(q: np.ndarray) -> np.ndarray:
    c, s = np.cos(q), np.sin(q)
    R = np.zeros(q.shape + (3, 3))
    R[..., 0, 0], R[..., 0, 1], R[..., 1, 0], R[..., 1, 1], R[..., 2, 2] = c, -s, s, c, 1.0
    return R


def _turn(rng, angle: np.ndarray) -> np.ndarray:
    """Rotations by the angles (C,) about random axes (Rodrigues)."""
    a = rng.normal(size=(len(angle), 3))
    a /= np.linalg.norm(a, axis=-1, keepdims=True)
    k = np.zeros((len(angle), 3, 3))
    k[:, 0, 1], k[:, 0, 2], k[:, 1, 2] = -a[:, 2], a[:, 1], -a[:, 0]
    k = k - np.swapaxes(k, -1, -2)
    s = angle[:, None, None]
    return np.eye(3) + np.sin(s) * k + (1 - np.cos(s)) * (k @ k)


def _setup(rng, n: int):
    from modc.design import prefix
    from modc.kinematics import rpy_matrix

    c = check_text("design d {\n    target a at (0.3, 0, 0.2) m\n}\n", "d.mod")
    lib = c.design.problems[0].cell.library
    types = [lib.units[k] for k in rng.integers(1, 5, n)]
    tool = np.eye(4)
    tool[:3, :3] = rpy_matrix(tuple(rng.uniform(-math.pi, math.pi, 3)))
    tool[:3, 3] = rng.uniform(-0.08, 0.08, 3)
    # a few twist values: narrow hulls over the free levels, so that their bounds are tested too
    pivots = np.sort(rng.choice(PIVOTS, 3, replace=False))
    ports = np.sort(rng.choice(PORTS, 3, replace=False))
    return prefix.levels(types, [t.x23 for t in types], pivots, ports, [bool(t.link) for t in types], tool)


def _posed_targets(rng, lv, C: int, pointed: bool):
    """C settings (level indices (C, n+1)) and Targets at their poses, each moved within its
    tolerances."""
    from modc.design.reach import Targets

    n = len(lv) - 1
    idx = np.stack([rng.integers(len(level.t), size=C) for level in lv], 1)
    q = rng.uniform(-math.pi, math.pi, (C, n))
    R, p = lv[0].R[idx[:, 0]], lv[0].t[idx[:, 0]]
    for j in range(1, n + 1):
        R = R @ _rz(q[:, j - 1])
        p = p + np.einsum("cij,cj->ci", R, lv[j].t[idx[:, j]])
        R = R @ lv[j].R[idx[:, j]]
    tol_r = rng.uniform(0.0, math.radians(10.0), C) * rng.integers(0, 2, C)
    Rt = _turn(rng, tol_r * 0.999) @ R
    axis = np.einsum("cij,cj->ci", _turn(rng, tol_r * 0.999), R[:, :, 0])  # within tol_r of tool0's x
    tg = Targets(p, Rt, np.ones(C, bool), np.full(C, 0.01), tol_r, tuple(f"t{i}" for i in range(C)),
                 axis / np.linalg.norm(axis, axis=-1, keepdims=True), np.full(C, pointed))
    return idx, tg


@pytest.mark.parametrize("n", [1, 2, 3, 4])
def test_a_reached_pose_never_excludes_the_families_of_its_setting(n):
    from modc.design import prefix

    rng = np.random.default_rng(300 + n)
    for trial in range(6):
        lv = _setup(rng, n)
        for pointed in (False, True):
            idx, tg = _posed_targets(rng, lv, 200, pointed)
            excluded = 0
            for k in range(1, n + 2):  # the family fixing K_0 … K_(k-1), every level after free
                R = np.stack([lv[j].R[idx[:, j]] for j in range(k)], 1)
                t = np.stack([lv[j].t[idx[:, j]] for j in range(k)], 1)
                ok = np.array([prefix.fits(lv, R[c:c + 1], t[c:c + 1], prefix._keys(tg.take(np.array([c]))))[0]
                               for c in range(len(R))])
                assert ok.all(), (n, trial, pointed, k, np.flatnonzero(~ok)[:5])
                # the same families against other settings' targets: some are excluded
                other = np.array([prefix.fits(lv, R[c:c + 1], t[c:c + 1],
                                              prefix._keys(tg.take(np.array([(c + 1) % len(R)]))))[0]
                                  for c in range(len(R))])
                excluded += int((~other).sum())
            if not pointed:
                assert excluded > 0
            # refine, at any cap, keeps the family that holds each setting
            sizes = [len(level.t) for level in lv]
            number = np.ravel_multi_index(tuple(idx.T), sizes)
            for c in range(0, len(idx), 40):
                one = tg.take(np.array([c]))
                for cap in (5, 500, 10**6):
                    fam = prefix.refine(lv, one.xyz, one.tol_p, cap, tg=one)
                    assert number[c] // fam.per in set(fam.alive.tolist()), (n, c, cap)
                many = prefix.refine_many(lv, [(one.xyz, one.tol_p)] * 2, 500, tgs=[one, None])
                assert [f.alive.tolist() for f in many] == [
                    fam.alive.tolist() for fam in (prefix.refine(lv, one.xyz, one.tol_p, 500, tg=one),
                                                   prefix.refine(lv, one.xyz, one.tol_p, 500))]


def _cell(kind: str) -> str:
    """Two targets an H1 - L3 arm reaches with its own twists, posed or pointing."""
    from modc.design.batch import forward, geometry
    from modc.kinematics import matrix_rpy

    c = check_text("design d {\n    target a at (0.3, 0, 0.2) m\n}\n", "d.mod")
    lib = c.design.problems[0].cell.library
    types = [lib.units[k] for k in (1, 3)]
    g = geometry(types, np.radians([[0.0, 45.0]]), np.radians([[0.0, 30.0]]), [t.x23 for t in types],
                 (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    _, _, T, _ = forward(g, np.array([[0.3, -0.8], [1.2, 0.6]])[None, :, None, :])
    lines = []
    for k in range(2):
        x, R = T[0, k, 0, :3, 3], T[0, k, 0, :3, :3]
        r = np.degrees(matrix_rpy(R))
        how = (f"rpy ({r[0]:.4f}, {r[1]:.4f}, {r[2]:.4f}) deg" if kind == "rpy"
               else f"pointing ({R[0, 0]:.6f}, {R[1, 0]:.6f}, {R[2, 0]:.6f})")
        lines.append(f"    target t{k} at ({x[0]:.6f}, {x[1]:.6f}, {x[2]:.6f}) m {how} within 15 mm, 12 deg\n")
    return "design posed {\n" + "".join(lines) + "    units 1 to 2\n    modules H1, L3, L4\n}\n"


@pytest.mark.parametrize("kind", ["rpy", "pointing"])
def test_the_family_tilt_bound_changes_no_ranking(monkeypatch, kind):
    from modc.design import prefix, run

    checked = check_text(_cell(kind), "cell.mod")
    assert checked.ok, [d.message for d in checked.diagnostics]
    p = checked.design.problems[0]
    calls = []
    real = prefix.tilted

    def counted(lv, R, keys):
        out = real(lv, R, keys)
        calls.append(int((~out).sum()))
        return out

    monkeypatch.setattr(prefix, "tilted", counted)
    on = run.design(p, top=5)
    assert on.designs and sum(calls) > 0  # the family bound ran and excluded families
    monkeypatch.setattr(prefix, "POSED", False)
    off = run.design(p, top=5)
    assert [(d.chain(), round(d.mass, 9)) for d in on.designs] == [(d.chain(), round(d.mass, 9)) for d in off.designs]
