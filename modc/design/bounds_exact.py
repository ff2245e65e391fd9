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
+ r_3 S(delta_3), and d(theta) >= d(c) - B on the whole box.

Second order (what makes small boxes near a tangency cheap): with F = (rho, h) and Delta = theta
- c, F(theta) = F(c) + DF(c) Delta + E. Along the straight path from c, v' = v_2 Delta_2 + v_3
Delta_3 with |v_2| = |w(theta_3)_xy| <= r_2m = r_2 + r_3 S(delta_3) and |v_3| = r_3, and |v''|
<= r_2m delta_2^2 + 2 r_3 delta_2 delta_3 + r_3 delta_3^2 = Q (the second derivatives of a point
turned about an axis have the norm of its distance from it). The map v -> (|v_xy|, v_z) has a
derivative of norm 1 and a second derivative of norm 1 / rho, and rho >= rho(c) - B on the box,
so |E| <= (Q + L^2 / (rho(c) - B)) / 2 with L = r_2m delta_2 + r_3 delta_3 (no bound when rho(c)
<= B). And |F(c) + DF Delta - F_t| >= d(c) - (|q . a| + |q . b|) / d(c), q = F_t - F(c), a and b
DF's columns times delta_2 and delta_3 (the support of the parallelogram DF Delta along q). The
box's lower bound is the larger of d(c) - B and that minus |E| (d(c) - B alone for the initial
grid's boxes, where |E| is of the arm's size). A box is

- reachable when d(c) <= tol: the pair is possible;
- excluded when its lower bound > tol + SLACK (SLACK covers rounding: 1e-9 m);
- undecided when B < MARGIN (or a level reaches LEVELS): the pair is called possible (sound:
  nothing is excluded that was not proven out of reach; a pair within MARGIN of reach may stay);
- else split in two along the angle whose term of B is larger (theta_2 on ties).

The search starts from a GRID x GRID grid of boxes (GRID x 1 for n = 2, r_3 = 0). The pair is possible
iff some box of that tree is reachable or undecided: the answer does not depend on the order the
tree is walked, so the numba kernel (depth first, nearest box first, stopping at the first
reachable box, modc.design.bounds_exact_jit) and the numpy walk (level by level, every pair at
once, below) return the same answer. Both use the same arithmetic, + * and sqrt in the same
order, and the same tables (cos and sin of the centres by angle addition from numpy's tables,
never a trig call inside): the same bits, so the search's counts do not depend on which ran.
Before the walk, a few Gauss-Newton steps from the two nearest grid centres look for a witness
(newton): it decides most possible pairs at once, and changes no answer.
"""
from __future__ import annotations

import numpy as np

from .bounds import Frames

MARGIN = 5e-4  # m: a box whose bound is finer than this is not split further (the pair stays possible)
SLACK = 1e-9  # m: rounding never excludes a target at the edge of its tolerance
GRID = 2  # initial boxes per angle (2 to 8 measured: 2 and 3 the fastest)
LEVELS = 24  # splits per angle at most (pi / GRID / 2^24: far below MARGIN for any real arm)
STEPS = 6  # Gauss-Newton steps of the witness search (newton)
SAMPLE = 16  # prune: every SAMPLE-th setting of a block tested first
PAYS = 0.6  # prune: the rest too when the sample has at least this share out of reach


def tables() -> np.ndarray:
    """(6, LEVELS + 1): per level k, S(delta_k) (chord factor), cos and sin of delta_k (the
    offset of a level-k box's centre from its parent's), the initial centres' cos and sin (GRID
    of them, the rest zero), delta_k; delta_0 = pi / GRID."""
    half = (np.pi / GRID) / 2.0 ** np.arange(LEVELS + 1)
    centres = -np.pi + (2 * np.arange(GRID) + 1) * (np.pi / GRID)
    out = np.zeros((6, LEVELS + 1))
    out[0] = 2.0 * np.sin(half / 2.0)
    out[1], out[2] = np.cos(half), np.sin(half)
    out[3, :GRID], out[4, :GRID] = np.cos(centres), np.sin(centres)
    out[5] = half
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


def box(p, rt, ht, c2, s2, c3, s3, S2, S3, h2, h3):
    """A box's centre and bounds, for arrays (p = P[rows].T, (22, K)) or one pair (p = P[c], the
    kernel: the same operations in the same order, no branch). Returns d at the centre, the terms
    of B (r_2 S(delta_2), r_3 S(delta_3)), and the lower bound of d over the box: the larger of
    d - B and the second-order bound (docstring)."""
    wx = p[12] + p[15] * c3 + p[18] * s3
    wy = p[13] + p[16] * c3 + p[19] * s3
    wz = p[14] + p[17] * c3 + p[20] * s3
    gx = p[18] * c3 - p[15] * s3  # dw / dtheta_3
    gy = p[19] * c3 - p[16] * s3
    gz = p[20] * c3 - p[17] * s3
    ux = c2 * wx - s2 * wy
    uy = s2 * wx + c2 * wy
    vx = p[0] + p[3] * ux + p[4] * uy + p[5] * wz
    vy = p[1] + p[6] * ux + p[7] * uy + p[8] * wz
    vz = p[2] + p[9] * ux + p[10] * uy + p[11] * wz
    ax = p[4] * ux - p[3] * uy  # dv / dtheta_2 = R(K_1) (e_z x u)
    ay = p[7] * ux - p[6] * uy
    az = p[10] * ux - p[9] * uy
    hx = c2 * gx - s2 * gy
    hy = s2 * gx + c2 * gy
    bx = p[3] * hx + p[4] * hy + p[5] * gz  # dv / dtheta_3 = R(K_1) Rz(theta_2) dw / dtheta_3
    by = p[6] * hx + p[7] * hy + p[8] * gz
    bz = p[9] * hx + p[10] * hy + p[11] * gz
    rho = np.sqrt(vx * vx + vy * vy)
    dr = rho - rt
    dh = vz - ht
    d = np.sqrt(dr * dr + dh * dh)
    r2 = np.sqrt(wx * wx + wy * wy)
    r3 = p[21]
    e2 = r2 * S2
    e3 = r3 * S3
    bound = e2 + e3
    # the linear part DF (c) Delta of (rho, h) moves it along q = (rho_t, h_t) - (rho, h) by at most
    # |q . a'| + |q . b'| over |q| (a', b' = DF's columns times delta_2, delta_3; |(vx a_x + vy a_y)
    # / rho| <= |a|: finite)
    inv = 1.0 / (rho + 1e-300)
    fa, ga = (vx * ax + vy * ay) * inv * h2, az * h2
    fb, gb = (vx * bx + vy * by) * inv * h3, bz * h3
    near = d - (np.abs(dr * fa + dh * ga) + np.abs(dr * fb + dh * gb)) / (d + 1e-300)
    r2m = r2 + e3
    lin = r2m * h2 + r3 * h3
    quad = r2m * h2 * h2 + 2.0 * r3 * h2 * h3 + r3 * h3 * h3
    rmin = np.maximum(rho - bound, 1e-300)
    low = np.maximum(d - bound, near - 0.5 * (quad + lin * lin / rmin))
    return d, e2, e3, low


def newton(p, rt, ht, c2, s2, c3, s3):
    """One damped Gauss-Newton step on (rho, h) = (rho_t, h_t) from the angles whose cos and sin
    are (c2, s2), (c3, s3) (arrays or one pair, as box): d there, and the next angles' cos and
    sin. A witness search: d <= tol at any (c, s) of unit length (each step turns them and
    normalises them, without trig) is a joint vector serving the pair - and the pair's tree
    says possible too (a box holding it has a lower bound <= its d): the answer is the same with
    or without it; it spares the walk down to a reachable box."""
    wx = p[12] + p[15] * c3 + p[18] * s3
    wy = p[13] + p[16] * c3 + p[19] * s3
    wz = p[14] + p[17] * c3 + p[20] * s3
    gx, gy, gz = p[18] * c3 - p[15] * s3, p[19] * c3 - p[16] * s3, p[20] * c3 - p[17] * s3
    ux, uy = c2 * wx - s2 * wy, s2 * wx + c2 * wy
    hx, hy = c2 * gx - s2 * gy, s2 * gx + c2 * gy
    vx = p[0] + p[3] * ux + p[4] * uy + p[5] * wz
    vy = p[1] + p[6] * ux + p[7] * uy + p[8] * wz
    vz = p[2] + p[9] * ux + p[10] * uy + p[11] * wz
    rho = np.sqrt(vx * vx + vy * vy)
    dr, dh = rho - rt, vz - ht
    inv = 1.0 / (rho + 1e-300)
    j00 = (vx * (p[4] * ux - p[3] * uy) + vy * (p[7] * ux - p[6] * uy)) * inv
    j01 = (vx * (p[3] * hx + p[4] * hy + p[5] * gz) + vy * (p[6] * hx + p[7] * hy + p[8] * gz)) * inv
    j10, j11 = p[10] * ux - p[9] * uy, p[9] * hx + p[10] * hy + p[11] * gz
    m00, m01, m11 = j00 * j00 + j10 * j10 + 1e-6, j00 * j01 + j10 * j11, j01 * j01 + j11 * j11 + 1e-6
    g0, g1 = j00 * dr + j10 * dh, j01 * dr + j11 * dh
    det = m00 * m11 - m01 * m01
    d2, d3 = (m01 * g1 - m11 * g0) / det, (m01 * g0 - m00 * g1) / det
    scale = 0.5 / np.maximum(np.maximum(np.abs(d2), np.abs(d3)), 0.5)  # at most 0.5 rad a step
    d2, d3 = d2 * scale, d3 * scale
    a2, a3 = 1.0 - 0.5 * d2 * d2, 1.0 - 0.5 * d3 * d3  # about cos and sin of the step
    n2, m2 = c2 * a2 - s2 * d2, s2 * a2 + c2 * d2
    n3, m3 = c3 * a3 - s3 * d3, s3 * a3 + c3 * d3
    k2, k3 = 1.0 / np.sqrt(n2 * n2 + m2 * m2), 1.0 / np.sqrt(n3 * n3 + m3 * m3)
    return np.sqrt(dr * dr + dh * dh), n2 * k2, m2 * k2, n3 * k3, m3 * k3


def _start(n: int, tab: np.ndarray) -> np.ndarray:
    """The initial boxes (c2, s2, c3, s3) of one pair: (GRID * GRID or GRID, 4)."""
    g3 = GRID if n == 3 else 1
    i2, i3 = np.repeat(np.arange(GRID), g3), np.tile(np.arange(g3), GRID)
    c3 = tab[3, i3] if n == 3 else np.ones(len(i3))
    s3 = tab[4, i3] if n == 3 else np.zeros(len(i3))
    return np.column_stack([tab[3, i2], tab[4, i2], c3, s3])


def grid(K: int, n: int, tab: np.ndarray):
    """The initial boxes of K pairs: their pairs, centres (cos, sin of both angles), levels."""
    start = _start(n, tab)
    pair = np.repeat(np.arange(K), len(start))
    return pair, np.tile(start, (K, 1)), np.zeros(len(pair), np.int64), np.zeros(len(pair), np.int64)


def _pairs_numpy(P: np.ndarray, rt: np.ndarray, ht: np.ndarray, tol: np.ndarray, n: int) -> np.ndarray:
    """(K,) the tree's answer for K pairs (P (K, 22), rt, ht, tol (K,)), level by level."""
    tab = tables()
    K = len(P)
    start = _start(n, tab)
    pair, boxes, k2, k3 = grid(K, n, tab)
    out = np.zeros(K, bool)
    tolx = tol + SLACK
    first = True
    while len(pair):
        d, e2, e3, low = box(P[pair].T, rt[pair], ht[pair], boxes[:, 0], boxes[:, 1], boxes[:, 2], boxes[:, 3],
                             tab[0, k2], tab[0, k3], tab[5, k2], tab[5, k3])
        t = tol[pair]
        if first:  # a witness from the two nearest centres of the grid spares most walks
            first = False
            low = d - (e2 + e3)  # the grid's boxes (delta = pi / GRID): first order only, as the kernel
            near = np.argsort(d.reshape(K, -1), axis=1, kind="stable")[:, :2] + np.arange(K)[:, None] * len(start)
            for col in range(2):
                c2, s2, c3, s3 = boxes[near[:, col]].T
                for _ in range(STEPS + 1):
                    dn, c2, s2, c3, s3 = newton(P.T, rt, ht, c2, s2, c3, s3)
                    out |= dn <= tol
        out[pair[(d <= t) | ((low <= tolx[pair]) & ((e2 + e3 < MARGIN) | (k2 == LEVELS) | (k3 == LEVELS)))]] = True
        keep = ~out[pair] & (low <= tolx[pair])
        pair, boxes, k2, k3, e2, e3 = pair[keep], boxes[keep], k2[keep], k3[keep], e2[keep], e3[keep]
        pair, boxes, k2, k3 = split(pair, boxes, k2, k3, e3 > e2, tab)
    return out


def split(pair, boxes, k2, k3, along3, tab):
    """Every box in two along theta_3 (along3) or theta_2: the pairs, centres (cos, sin of both
    angles) and levels of the children, each box's two in a row."""
    pair = np.repeat(pair, 2)
    boxes = np.repeat(boxes, 2, axis=0)
    k2, k3, along3 = np.repeat(k2, 2), np.repeat(k3, 2), np.repeat(along3, 2)
    sign = np.tile([1.0, -1.0], len(pair) // 2)
    lv = np.where(along3, k3, k2) + 1
    cd, sd = tab[1, lv], tab[2, lv] * sign
    i = np.where(along3, 2, 0)
    rows = np.arange(len(pair))
    c, s = boxes[rows, i], boxes[rows, i + 1]
    boxes[rows, i], boxes[rows, i + 1] = c * cd - s * sd, s * cd + c * sd
    return pair, boxes, np.where(along3, k2, lv), np.where(along3, lv, k3)


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
    if compiled and not _BROKEN:
        try:
            from . import bounds_exact_jit

            if bounds_exact_jit.numba is not None:
                return bounds_exact_jit.reachable(P, rt, ht, tol, n, order, tables())
        except Exception:  # noqa: BLE001 - a numba that cannot compile the kernel: the numpy walk, same answer
            _BROKEN.append(True)
    return _numpy(P, rt, ht, tol, n, order)


_BROKEN: list[bool] = []


def prune(f: Frames, xyz: np.ndarray, tol: np.ndarray, compiled: bool | None = None) -> np.ndarray:
    """reachable(), where it pays: it costs a few µs per (setting, target) (~20 for a pair just out of
    reach, whose tree is wide) and saves the IK of the settings it excludes (4 seeds, ~15-20 µs
    when they fail). Every SAMPLE-th setting of the block goes first; the rest only when at least
    PAYS of the sample is out of reach (most settings the interval bounds keep in
    benchmarks/bench_task_base.py's cell; a third in examples/farm_cell.mod's, whose targets lie
    just out of most settings' reach). A function of the block alone: the same settings give the
    same answer in any process."""
    C = len(f.t)
    if C < 8 * SAMPLE:
        return reachable(f, xyz, tol, compiled)
    first = np.zeros(C, bool)
    first[::SAMPLE] = True
    out = np.ones(C, bool)
    out[first] = reachable(Frames(f.R[first], f.t[first]), xyz, tol, compiled)
    if (~out[first]).mean() >= PAYS:
        out[~first] = reachable(Frames(f.R[~first], f.t[~first]), xyz, tol, compiled)
    return out
