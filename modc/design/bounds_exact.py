"""Exact reach of a 2- or 3-joint chain, position only (up to MARGIN): whether some joint vector
brings tool0 within tol of each target, decided by branch and bound over (theta_2, theta_3).

In modc.design.bounds' notation (K_0 … K_n, J_j, v_j, p_1 = t(K_0), z_1 = R(K_0) e_z), for n = 3

    v_1(theta_2, theta_3) = t(K_1) + R(K_1) Rz(theta_2) w(theta_3),
    w(theta_3) = t(K_2) + R(K_2) Rz(theta_3) t(K_3)        (n = 2: w = t(K_2), no theta_3),

and tool0 - p_1 = R(K_0) Rz(theta_1) v_1. Turning theta_1 keeps v_1's height h = e_z . v_1 and
its distance rho = |v_1,xy| from the axis: tool0 runs on a circle about z_1. With the target x
at h_t, rho_t (x - p_1 written in J_1 at theta_1 = 0: y = R(K_0)^T (x - p_1), h_t = y_z,
rho_t = |y_xy|), the closest tool0 comes to x over theta_1 is the distance between v_1 and the
target's circle {(rho_t cos a, rho_t sin a, h_t)}:

    d(theta_2, theta_3) = sqrt((rho - rho_t)^2 + (h - h_t)^2),

the distance from a point to a set: 1-Lipschitz in v_1. The setting serves x (joint limits
aside: they only shrink the set, so ignoring them is sound) iff min d <= tol.

A box of angles with centre c and half-widths delta_2, delta_3 (<= pi): any (theta_2, theta_3)
in it is reached from c by turning joint 2 at theta_3 = c_3, then joint 3 at theta_2. Turning a
point by an angle |a| <= delta about an axis at distance r moves it by the chord 2 r sin(|a|/2)
<= r S(delta), S(delta) = 2 sin(delta / 2). Joint 2 at theta_3 = c_3 turns tool0 about its axis
at distance r_2 = |w(c_3)_xy|; joint 3 at any theta_2 turns it about its axis at distance
r_3 = |t(K_3)_xy|, the same for every theta_2. So |v_1(theta) - v_1(c)| <= B = r_2 S(delta_2)
+ r_3 S(delta_3), and d(theta) >= d(c) - B on the whole box. A box is

- reachable when d(c) <= tol: the pair is possible;
- excluded when d(c) - B > tol + SLACK (SLACK covers rounding: 1e-9 m);
- undecided when B < MARGIN (or a level reaches LEVELS): the pair is called possible (sound:
  nothing is excluded that was not proven out of reach; a pair within MARGIN of reach may stay);
- else split in two along the angle whose term of B is larger (theta_2 on ties).

The search starts from a 4 x 4 grid of boxes (4 x 1 for n = 2, r_3 = 0). The pair is possible
iff some box of that tree is reachable or undecided: the answer does not depend on the order the
tree is walked, so the numba kernel (depth first, nearest box first, stopping at the first
reachable box, modc.design.bounds_exact_jit) and the numpy walk (level by level, every pair at
once, below) return the same answer. Both use the same arithmetic, + * and sqrt in the same
order, and the same tables (cos and sin of the centres by angle addition from numpy's tables,
never a trig call inside): the same bits, so the search's counts do not depend on which ran.
"""
from __future__ import annotations

import numpy as np

from .bounds import Frames

MARGIN = 5e-4  # m: a box whose bound is finer than this is not split further (the pair stays possible)
SLACK = 1e-9  # m: rounding never excludes a target at the edge of its tolerance
GRID = 4  # initial boxes per angle
LEVELS = 24  # splits per angle at most (pi / 4 / 2^24: far below MARGIN for any real arm)


def tables() -> np.ndarray:
    """(5, LEVELS + 1): per level k, S(delta_k) (chord factor), cos and sin of delta_k (the
    offset of a level-k box's centre from its parent's), and the initial centres' cos and sin
    (GRID of them, the rest zero); delta_0 = pi / GRID."""
    half = (np.pi / GRID) / 2.0 ** np.arange(LEVELS + 1)
    centres = -np.pi + (2 * np.arange(GRID) + 1) * (np.pi / GRID)
    out = np.zeros((5, LEVELS + 1))
    out[0] = 2.0 * np.sin(half / 2.0)
    out[1], out[2] = np.cos(half), np.sin(half)
    out[3, :GRID], out[4, :GRID] = np.cos(centres), np.sin(centres)
    return out


def params(f: Frames) -> np.ndarray:
    """(C, 22) per setting: t(K_1), R(K_1) (row major), then w(theta_3) = m + A cos + B sin
    (m, A, B) and r_3. n = 2: w = t(K_2) (A = B = 0, r_3 = 0)."""
    C, k = f.t.shape[:2]
    out = np.zeros((C, 22))
    out[:, 0:3] = f.t[:, 1]
    out[:, 3:12] = f.R[:, 1].reshape(C, 9)
    if k == 3:
        out[:, 12:15] = f.t[:, 2]
        return out
    R2, a3 = f.R[:, 2], f.t[:, 3]
    out[:, 12:15] = f.t[:, 2] + R2[:, :, 2] * a3[:, 2:3]
    out[:, 15:18] = R2[:, :, 0] * a3[:, 0:1] + R2[:, :, 1] * a3[:, 1:2]
    out[:, 18:21] = R2[:, :, 1] * a3[:, 0:1] - R2[:, :, 0] * a3[:, 1:2]
    out[:, 21] = np.sqrt(a3[:, 0] * a3[:, 0] + a3[:, 1] * a3[:, 1])
    return out


def circles(f: Frames, xyz: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The targets' rho_t, h_t (C, T): xyz (T, 3) written in J_1 at theta_1 = 0."""
    dx = xyz[None] - f.t[:, 0][:, None]
    y = np.einsum("cji,ctj->cti", f.R[:, 0], dx)  # R(K_0)^T (x - p_1)
    return np.sqrt(y[..., 0] * y[..., 0] + y[..., 1] * y[..., 1]), y[..., 2]


def evaluate(P, rt, ht, c2, s2, c3, s3):
    """d at a box's centre and r_2 = |w(c_3)_xy| (arrays or scalars: the kernel writes the same
    operations in the same order)."""
    wx = P[..., 12] + P[..., 15] * c3 + P[..., 18] * s3
    wy = P[..., 13] + P[..., 16] * c3 + P[..., 19] * s3
    wz = P[..., 14] + P[..., 17] * c3 + P[..., 20] * s3
    ux = c2 * wx - s2 * wy
    uy = s2 * wx + c2 * wy
    vx = P[..., 0] + P[..., 3] * ux + P[..., 4] * uy + P[..., 5] * wz
    vy = P[..., 1] + P[..., 6] * ux + P[..., 7] * uy + P[..., 8] * wz
    vz = P[..., 2] + P[..., 9] * ux + P[..., 10] * uy + P[..., 11] * wz
    dr = np.sqrt(vx * vx + vy * vy) - rt
    dh = vz - ht
    return np.sqrt(dr * dr + dh * dh), np.sqrt(wx * wx + wy * wy)


def _start(n: int, tab: np.ndarray) -> np.ndarray:
    """The initial boxes (c2, s2, c3, s3) of one pair: (GRID * GRID or GRID, 4)."""
    g3 = GRID if n == 3 else 1
    i2, i3 = np.repeat(np.arange(GRID), g3), np.tile(np.arange(g3), GRID)
    c3 = tab[3, i3] if n == 3 else np.ones(len(i3))
    s3 = tab[4, i3] if n == 3 else np.zeros(len(i3))
    return np.column_stack([tab[3, i2], tab[4, i2], c3, s3])


def _pairs_numpy(P: np.ndarray, rt: np.ndarray, ht: np.ndarray, tol: np.ndarray, n: int) -> np.ndarray:
    """(K,) the tree's answer for K pairs (P (K, 22), rt, ht, tol (K,)), level by level."""
    tab = tables()
    K = len(P)
    start = _start(n, tab)
    pair = np.repeat(np.arange(K), len(start))
    box = np.tile(start, (K, 1))
    k2 = np.zeros(len(pair), np.int64)
    k3 = np.zeros(len(pair), np.int64)
    out = np.zeros(K, bool)
    tolx = tol + SLACK
    while len(pair):
        d, r2 = evaluate(P[pair], rt[pair], ht[pair], box[:, 0], box[:, 1], box[:, 2], box[:, 3])
        e2, e3 = r2 * tab[0, k2], P[pair, 21] * tab[0, k3]
        bound = e2 + e3
        t = tol[pair]
        out[pair[(d <= t) | ((d - bound <= tolx[pair]) & ((bound < MARGIN) | (k2 == LEVELS) | (k3 == LEVELS)))]] = True
        keep = ~out[pair] & (d - bound <= tolx[pair])
        pair, box, k2, k3, e2, e3 = pair[keep], box[keep], k2[keep], k3[keep], e2[keep], e3[keep]
        along3 = e3 > e2
        pair = np.repeat(pair, 2)
        box = np.repeat(box, 2, axis=0)
        k2, k3, along3 = np.repeat(k2, 2), np.repeat(k3, 2), np.repeat(along3, 2)
        sign = np.tile([1.0, -1.0], len(pair) // 2)
        lv = np.where(along3, k3, k2) + 1
        cd, sd = tab[1, lv], tab[2, lv] * sign
        i = np.where(along3, 2, 0)
        rows = np.arange(len(pair))
        c, s = box[rows, i], box[rows, i + 1]
        box[rows, i], box[rows, i + 1] = c * cd - s * sd, s * cd + c * sd
        k2, k3 = np.where(along3, k2, lv), np.where(along3, lv, k3)
    return out


def _numpy(P, rt, ht, tol, n, order) -> np.ndarray:
    """(C,): every target possible, target by target on the settings still alive."""
    alive = np.arange(len(P))
    for j in order:
        if alive.size == 0:
            break
        alive = alive[_pairs_numpy(P[alive], rt[alive, j], ht[alive, j], np.full(alive.size, tol[j]), n)]
    out = np.zeros(len(P), bool)
    out[alive] = True
    return out


def reachable(f: Frames, xyz: np.ndarray, tol: np.ndarray, compiled: bool | None = None) -> np.ndarray:
    """(C,) False where no joint vector (limits or not) brings tool0 within tol (T,) of some
    target xyz (T, 3) for a setting of f (2 or 3 joints, no tail; other chains: all True).
    compiled: the numba kernel (True), the numpy walk (False), or the kernel
    once reach.jit says so (None: a short search never pays numba's import for it; MODC_JIT=0:
    never). The same answer either way."""
    C, k = f.t.shape[:2]
    if k not in (3, 4) or C == 0 or len(xyz) == 0:
        return np.ones(C, bool)
    n = k - 1
    P = params(f)
    rt, ht = circles(f, np.asarray(xyz, float))
    tol = np.asarray(tol, float)
    # farthest target first (from the settings' mean base): most settings that fail, fail it
    order = np.argsort(-np.linalg.norm(xyz - f.t[:, 0].mean(0), axis=-1), kind="stable")
    if compiled is None:
        from . import reach

        # a (setting, target) pair through the numpy walk costs about one numpy IK run: the pairs
        # count towards reach.JIT_AFTER, so a long search loads numba for both, a short one never
        compiled = reach.jit(C * len(xyz))
    if compiled:
        from . import bounds_exact_jit

        if bounds_exact_jit.numba is not None:
            return bounds_exact_jit.reachable(P, rt, ht, tol, n, order, tables())
    return _numpy(P, rt, ht, tol, n, order)
