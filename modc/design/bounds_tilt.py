"""Exact reach of a 2- or 3-joint chain with an orientation: whether some joint vector brings
tool0 within tol of an oriented target's position AND turns a tool-fixed vector within eps of
the target's tilt at once, decided by branch and bound over (theta_2, theta_3).

modc.design.bounds_exact decides the position alone; modc.design.bounds tests the tilt (the
angle between joint 1's axis and a vector fixed in the tool, independent of theta_1) over its
whole range. Each alone is necessary; together, at the same joint vector, they are much
stronger: a 3-joint arm that must point its tool down meets the tilt only on a band of
(theta_2, theta_3), and tool0 must reach the target from that band. (In the 40 first screen
calls of a 3 x 2 pointing tray, 96 % of the (setting, point) pairs both tests keep fail the
pair, against 23 % for the position alone.)

In bounds_exact's notation, for a tool-fixed vector w (e_x for `pointing`; e_x and e_z for a full
`rpy`, each against R_t w), the vector in J_1 is

    u(theta_2, theta_3) = R(K_1) Rz(theta_2) y(theta_3),   y = R(K_2) Rz(theta_3) R(K_3) w
                                                         (n = 2: y = R(K_2) w),

and its tilt to joint 1's axis is arccos(u_z); the target's is arccos(z_1 . R_t w) (base
frame). Turning joint 2 by at most delta_2 and joint 3 by at most delta_3 turns u by at most
delta_2 + delta_3 (a rotation by a turns any unit vector by at most |a|), so over a box the tilt
stays within delta_2 + delta_3 of its value at the centre. A box is

- met when the centre meets both: d <= tol and every vector's tilt within eps;
- excluded when bounds_exact.box's lower bound of d exceeds tol, or some vector's tilt at the
  centre lies farther than eps + delta_2 + delta_3 from the target's;
- undecided (the pair possible: sound) when both bounds are finer than MARGIN and TILT_MARGIN,
  or a level reaches LEVELS; else split along the angle whose terms are the larger.

The pair is possible iff some box is met or undecided. Numpy, level by level, every pair at once
(like bounds_exact's numpy walk; the oriented IK it spares costs far more than the walk).
"""
from __future__ import annotations

import numpy as np

from .bounds import Frames
from .bounds_exact import LEVELS, MARGIN, SLACK, box, circles, grid, params, split, tables

TILT_MARGIN = 1e-2  # rad: a box whose tilt bound is finer than this is not split for it
TILT_SLACK = 1e-9  # rad: rounding never excludes a target at the edge of its tolerance


def _vectors(tg, j: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """Target j's (tool-fixed vector w, the direction R_t w it must take) pairs."""
    ex, ez = np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0])
    if len(tg.pointed) and tg.pointed[j]:
        return [(ex, np.asarray(tg.axis[j], float))]
    return [(ex, tg.R[j] @ ex), (ez, tg.R[j] @ ez)]


def _turn_params(f: Frames, w: np.ndarray) -> np.ndarray:
    """(C, 12) per setting: R(K_1)'s last row, then y(theta_3) = m + A cos + B sin (m, A, B)."""
    C, k = f.t.shape[:2]
    out = np.zeros((C, 12))
    out[:, 0:3] = f.R[:, 1, 2, :]
    if k == 3:  # n = 2: y = R(K_2) w
        out[:, 3:6] = f.R[:, 2] @ w
        return out
    q = f.R[:, 3] @ w  # R(K_3) w
    R2 = f.R[:, 2]
    out[:, 3:6] = R2[:, :, 2] * q[:, 2:3]
    out[:, 6:9] = R2[:, :, 0] * q[:, 0:1] + R2[:, :, 1] * q[:, 1:2]
    out[:, 9:12] = R2[:, :, 1] * q[:, 0:1] - R2[:, :, 0] * q[:, 1:2]
    return out


def _tilt(Q: np.ndarray, c2, s2, c3, s3) -> np.ndarray:
    """arccos(u_z) at the angles (cos, sin) for the rows of Q (K, 12)."""
    yx = Q[:, 3] + Q[:, 6] * c3 + Q[:, 9] * s3
    yy = Q[:, 4] + Q[:, 7] * c3 + Q[:, 10] * s3
    yz = Q[:, 5] + Q[:, 8] * c3 + Q[:, 11] * s3
    uz = Q[:, 0] * (c2 * yx - s2 * yy) + Q[:, 1] * (s2 * yx + c2 * yy) + Q[:, 2] * yz
    return np.arccos(np.clip(uz, -1.0, 1.0))


def _pairs(P: np.ndarray, Qs: list[np.ndarray], rt, ht, tilts: list[np.ndarray], tol: float, eps: float,
           n: int) -> np.ndarray:
    """(K,) the tree's answer for K settings against one target: P (K, 22) bounds_exact.params,
    Qs per vector (K, 12), rt, ht (K,), tilts per vector the target's tilt (K,)."""
    tab = tables()
    K = len(P)
    pair, boxes, k2, k3 = grid(K, n, tab)
    out = np.zeros(K, bool)
    first = True
    while len(pair):
        c2, s2, c3, s3 = boxes.T
        h2, h3 = tab[5, k2], (tab[5, k3] if n == 3 else np.zeros(len(pair)))
        d, e2, e3, low = box(P[pair].T, rt[pair], ht[pair], c2, s2, c3, s3, tab[0, k2], tab[0, k3], h2, h3)
        if first:  # the grid's boxes: the first-order bound alone (as bounds_exact's walks)
            low = d - (e2 + e3)
            first = False
        met = d <= tol
        out_ = low > tol + SLACK
        for Q, t in zip(Qs, tilts, strict=True):
            dev = np.abs(_tilt(Q[pair], c2, s2, c3, s3) - t[pair])
            met &= dev <= eps
            out_ |= dev - (h2 + h3) > eps + TILT_SLACK
        fine = ((e2 + e3 < MARGIN) & (h2 + h3 < TILT_MARGIN)) | (k2 == LEVELS) | (k3 == LEVELS)
        out[pair[met | (~out_ & fine)]] = True
        keep = ~out[pair] & ~out_ & ~fine
        pair, boxes, k2, k3 = pair[keep], boxes[keep], k2[keep], k3[keep]
        e2, e3, h2, h3 = e2[keep], e3[keep], h2[keep], h3[keep]
        along3 = (e3 / MARGIN + h3 / TILT_MARGIN > e2 / MARGIN + h2 / TILT_MARGIN) & (n == 3)
        pair, boxes, k2, k3 = split(pair, boxes, k2, k3, along3, tab)
    return out


def _inputs(f: Frames, tg, idx: np.ndarray):
    """Per oriented target of idx: (Qa, Qb) per vector (T', C, 12), their count (T'), the
    targets' tilts (C, T') per vector (the second 0 for `pointing`)."""
    C = len(f.t)
    z1 = f.R[:, 0, :, 2]
    T = len(idx)
    Qa, Qb = np.zeros((T, C, 12)), np.zeros((T, C, 12))
    ta, tb = np.zeros((C, T)), np.zeros((C, T))
    nv = np.zeros(T, np.int64)
    cache: dict[bytes, np.ndarray] = {}
    for i, j in enumerate(idx):
        vec = _vectors(tg, int(j))
        nv[i] = len(vec)
        for v, (w, target) in enumerate(vec):
            key = w.tobytes()
            if key not in cache:
                cache[key] = _turn_params(f, w)
            (Qa if v == 0 else Qb)[i] = cache[key]
            (ta if v == 0 else tb)[:, i] = np.arccos(np.clip(z1 @ target, -1.0, 1.0))
    return Qa, Qb, nv, ta, tb


def posed(f: Frames, tg, idx: np.ndarray, compiled: bool | None = None) -> np.ndarray:
    """(C,) False where, for some oriented target of idx (a reach.Targets' indices), no joint
    vector (limits or not) of a 2- or 3-joint setting of f meets its position within tol_p and its
    orientation's tilts within tol_r at once (other chains, no such target: all True).
    compiled: the numba kernel (True), the numpy walk (False), or the kernel once reach.jit says
    so (None). The same answer either way."""
    C, k = f.t.shape[:2]
    idx = np.asarray(idx, np.int64)
    if k not in (3, 4) or C == 0 or idx.size == 0:
        return np.ones(C, bool)
    n = k - 1
    P = params(f)
    rt, ht = circles(f, np.asarray(tg.xyz[idx], float))
    Qa, Qb, nv, ta, tb = _inputs(f, tg, idx)
    tol = np.asarray(tg.tol_p[idx], float)
    eps = np.minimum(np.asarray(tg.tol_r[idx], float), np.pi)
    # farthest target first (from the settings' mean base): most settings that fail, fail it
    order = np.argsort(-np.linalg.norm(tg.xyz[idx] - f.t[:, 0].mean(0), axis=-1), kind="stable")
    if compiled is None:
        from . import reach

        compiled = reach.jit(C * len(idx))
    if compiled and not _BROKEN:
        try:
            from . import bounds_tilt_jit

            if bounds_tilt_jit.numba is not None:
                return bounds_tilt_jit.posed(P, Qa, Qb, nv, rt, ht, ta, tb, tol, eps, n, order, tables())
        except Exception:  # noqa: BLE001 - a numba that cannot compile the kernel: the numpy walk, same answer
            _BROKEN.append(True)
    alive = np.arange(C)
    for i in order:
        if alive.size == 0:
            break
        Qs = [Qa[i, alive]] + ([Qb[i, alive]] if nv[i] == 2 else [])
        tilts = [ta[alive, i]] + ([tb[alive, i]] if nv[i] == 2 else [])
        alive = alive[_pairs(P[alive], Qs, rt[alive, i], ht[alive, i], tilts, float(tol[i]), float(eps[i]), n)]
    out = np.zeros(C, bool)
    out[alive] = True
    return out


_BROKEN: list[bool] = []

__all__ = ["posed"]
