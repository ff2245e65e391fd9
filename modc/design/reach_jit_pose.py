"""The IK of modc.design.reach.solve for batches with oriented targets (`rpy`: 6 rows; `pointing`:
position and tool0's x axis), compiled with numba like modc.design.reach_jit's position-only kernel.

The same algorithm operation for operation as the numpy path (forward_flat(rotation=True,
local=False), _residual with _rotation_error / batch.rotation_error / axis_error, rotation_rows,
_step's 6-row normal equations, _ldl_solve, the clip, the damping and stall rules, the
compactions), so q and both errors are bit for bit numpy's. Where numpy's order of summation
depends on an array's memory layout, the kernel follows the layout numpy's arrays have at that
point (matches_numpy checks the orders on this machine's numpy):
- einsum over a batch of one sums two lanes at a time: (a0 + a2 + ...) + (a1 + a3 + ...) (_s3, _dot);
- the rotation residual e_r is always a transposed view (batch axis outermost in memory), so
  _sq(e_r) sums in lanes; the position residual kept between iterations becomes one after the first
  compaction (boolean indexing of the last axis), so its norm sums in order before and in lanes after;
- every other sum of three (einsum's matrix products, ufunc sums, norms, traces) is in order.
"""
from __future__ import annotations

import numpy as np

from .reach_jit import _inline, _jit, _ldl_clip, _s3


@_inline
def _dot(a, b, m, one):
    """sum_k a[k] * b[k] over k < m as np.einsum sums it: in order over a batch, two lanes for one run."""
    if one:
        s0, s1 = a[0] * b[0], a[1] * b[1]
        for k in range(2, m, 2):
            s0 = s0 + a[k] * b[k]
            if k + 1 < m:
                s1 = s1 + a[k + 1] * b[k + 1]
        return s0 + s1
    s = a[0] * b[0]
    for k in range(1, m):
        s = s + a[k] * b[k]
    return s


@_inline
def _forward(K, q, p, z, Rt, t, n, R, R2, one):
    """forward_flat(rotation=True, local=False) of one run: K (n+1, 4, 4), q (n,) -> p, z (n, 3),
    tool0's rotation Rt (3, 3) and position t (3,) in the base frame."""
    for a in range(3):
        for k in range(3):
            R[a, k] = K[0, a, k]
    t0, t1, t2 = K[0, 0, 3], K[0, 1, 3], K[0, 2, 3]
    for i in range(n):
        cs, sn = np.cos(q[i]), np.sin(q[i])
        if i > 0:
            u0 = _s3(R[0, 0] * K[i, 0, 3], R[0, 1] * K[i, 1, 3], R[0, 2] * K[i, 2, 3], one)
            u1 = _s3(R[1, 0] * K[i, 0, 3], R[1, 1] * K[i, 1, 3], R[1, 2] * K[i, 2, 3], one)
            u2 = _s3(R[2, 0] * K[i, 0, 3], R[2, 1] * K[i, 1, 3], R[2, 2] * K[i, 2, 3], one)
            t0, t1, t2 = t0 + u0, t1 + u1, t2 + u2
            for a in range(3):
                for k in range(3):
                    R2[a, k] = R[a, 0] * K[i, 0, k] + R[a, 1] * K[i, 1, k] + R[a, 2] * K[i, 2, k]
            for a in range(3):
                for k in range(3):
                    R[a, k] = R2[a, k]
        for a in range(3):
            x, y = R[a, 0], R[a, 1]
            R[a, 0] = cs * x + sn * y
            R[a, 1] = cs * y - sn * x
        p[i, 0], p[i, 1], p[i, 2] = t0, t1, t2
        for a in range(3):
            z[i, a] = R[a, 2]
    for a in range(3):
        for k in range(3):
            Rt[a, k] = R[a, 0] * K[n, 0, k] + R[a, 1] * K[n, 1, k] + R[a, 2] * K[n, 2, k]
    t[0] = t0 + _s3(R[0, 0] * K[n, 0, 3], R[0, 1] * K[n, 1, 3], R[0, 2] * K[n, 2, 3], one)
    t[1] = t1 + _s3(R[1, 0] * K[n, 0, 3], R[1, 1] * K[n, 1, 3], R[1, 2] * K[n, 2, 3], one)
    t[2] = t2 + _s3(R[2, 0] * K[n, 0, 3], R[2, 1] * K[n, 1, 3], R[2, 2] * K[n, 2, 3], one)


@_inline
def _rotation(G, Rt, oriented, er, E):
    """reach._rotation_error(G, Rt) * oriented into er (3,): batch.rotation_error of G . Rt^T."""
    for i in range(3):
        for j in range(3):
            E[i, j] = G[i, 0] * Rt[j, 0] + G[i, 1] * Rt[j, 1] + G[i, 2] * Rt[j, 2]
    v0 = 0.5 * (E[2, 1] - E[1, 2])
    v1 = 0.5 * (E[0, 2] - E[2, 0])
    v2 = 0.5 * (E[1, 0] - E[0, 1])
    cos = (E[0, 0] + E[1, 1] + E[2, 2] - 1.0) / 2.0
    if cos < -1.0:  # np.clip: maximum, then minimum
        cos = -1.0
    if cos > 1.0:
        cos = 1.0
    angle = np.arccos(cos)
    sin = np.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
    scale = angle / max(sin, 1e-12) if sin > 1e-9 else 1.0
    v0, v1, v2 = v0 * scale, v1 * scale, v2 * scale
    if cos < -0.999 and sin < 1e-3:  # at 180°: the axis from the symmetric part (E + I) / 2
        k = 0
        for j in range(1, 3):
            if (E[j, j] + 1.0) / 2.0 > (E[k, k] + 1.0) / 2.0:
                k = j
        a0 = (E[0, k] + (1.0 if k == 0 else 0.0)) / 2.0
        a1 = (E[1, k] + (1.0 if k == 1 else 0.0)) / 2.0
        a2 = (E[2, k] + (1.0 if k == 2 else 0.0)) / 2.0
        nrm = np.sqrt(a0 * a0 + a1 * a1 + a2 * a2)
        v0, v1, v2 = a0 / nrm * angle, a1 / nrm * angle, a2 / nrm * angle
    er[0], er[1], er[2] = v0 * oriented, v1 * oriented, v2 * oriented


@_inline
def _axis(Rt, d, er):
    """reach.axis_error of tool0's x axis (Rt's first column) and d (3,) into er (3,)."""
    x0, x1, x2 = Rt[0, 0], Rt[1, 0], Rt[2, 0]
    v0, v1, v2 = x1 * d[2] - x2 * d[1], x2 * d[0] - x0 * d[2], x0 * d[1] - x1 * d[0]
    s = np.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
    angle = np.arctan2(s, x0 * d[0] + x1 * d[1] + x2 * d[2])
    if not s > 1e-12:  # opposite axes: the cross product with (1, 0, 0) or (0, 1, 0), as written there
        if np.abs(x0) < 0.9:
            u0, u1, u2 = 1.0, 0.0, 0.0
        else:
            u0, u1, u2 = 0.0, 1.0, 0.0
        v0, v1, v2 = x1 * u2 - x2 * u1, x2 * u0 - x0 * u2, x0 * u1 - x1 * u0
    f = angle / max(np.sqrt(v0 * v0 + v1 * v1 + v2 * v2), 1e-300)
    er[0], er[1], er[2] = v0 * f, v1 * f, v2 * f


@_inline
def _residual(xyz, G, oriented, pointed, d, Rt, t, ep, er, E, w2, one):
    """reach._residual of one run: ep, er (3,) and the cost |ep|^2 + w^2 |er|^2."""
    for a in range(3):
        ep[a] = xyz[a] - t[a]
    if pointed:  # numpy computes the rotation error too and drops it
        _axis(Rt, d, er)
    else:
        _rotation(G, Rt, oriented, er, E)
    return (_s3(ep[0] * ep[0], ep[1] * ep[1], ep[2] * ep[2], one)
            + w2 * _s3(er[0] * er[0], er[1] * er[1], er[2] * er[2], True))


@_inline
def _step(p, z, Rt, t, ep, er, oriented, pointed, w, lam, n, qn, q, lo, hi, J, e, A, rhs, L, d, y, one):
    """qn = clip(q + dq) with (J^T J + lam I) dq = J^T e for J (n, 6) and e (6,): reach._step."""
    x0, x1, x2 = Rt[0, 0], Rt[1, 0], Rt[2, 0]
    for i in range(n):
        b0, b1, b2 = t[0] - p[i, 0], t[1] - p[i, 1], t[2] - p[i, 2]
        J[i, 0] = z[i, 1] * b2 - z[i, 2] * b1
        J[i, 1] = z[i, 2] * b0 - z[i, 0] * b2
        J[i, 2] = z[i, 0] * b1 - z[i, 1] * b0
        r0, r1, r2 = z[i, 0] * oriented, z[i, 1] * oriented, z[i, 2] * oriented
        if pointed:  # rotation_rows: without the part about tool0's x axis
            s = r0 * x0 + r1 * x1 + r2 * x2
            r0, r1, r2 = r0 - x0 * s, r1 - x1 * s, r2 - x2 * s
        J[i, 3], J[i, 4], J[i, 5] = w * r0, w * r1, w * r2
    for a in range(3):
        e[a] = ep[a]
        e[3 + a] = w * er[a]
    for i in range(n):
        for j in range(i, n):
            A[i, j] = _dot(J[i], J[j], 6, one)
        A[i, i] = A[i, i] + lam
        rhs[i] = _dot(J[i], e, 6, one)
    _ldl_clip(A, rhs, n, qn, q, lo, hi, L, d, y)


@_jit
def _solve(joints, c_idx, t_idx, xyz, G, oriented, pointed, axis, give_up, q, lo, hi, iterations, stall_every,
           stall_gain, lambda0, w):
    """joints (C, n+1, 4, 4), c_idx, t_idx (B,), the targets xyz (T, 3), G (T, 3, 3), oriented (T,)
    1.0 / 0.0, pointed (T,), axis (T, 3), give_up (B,) m, q (n, B) the starts -> q (n, B) where each
    run ended, its position error (B,) m and orientation error (B,) rad."""
    n, B = q.shape
    w2 = w * w
    qc = np.ascontiguousarray(q.T)
    R, R2, E3 = np.empty((3, 3)), np.empty((3, 3)), np.empty((3, 3))  # scratch, as in reach_jit
    J, e, A, L = np.empty((n, 6)), np.empty(6), np.empty((n, n)), np.zeros((n, n))
    rhs, d, y = np.empty(n), np.empty(n), np.empty(n)
    q_out, ep_out, er_out = np.empty((n, B)), np.empty(B), np.zeros(B)
    P, Z, RT = np.empty((B, n, 3)), np.empty((B, n, 3)), np.empty((B, 3, 3))
    Tt, EP, ER = np.empty((B, 3)), np.empty((B, 3)), np.empty((B, 3))
    cost = np.empty(B)
    for r in range(B):
        g = t_idx[r]
        _forward(joints[c_idx[r]], qc[r], P[r], Z[r], RT[r], Tt[r], n, R, R2, B == 1)
        cost[r] = _residual(xyz[g], G[g], oriented[g], pointed[g], axis[g], RT[r], Tt[r], EP[r], ER[r], E3, w2,
                            B == 1)
    lam = np.full(B, lambda0)
    ref = np.full(B, np.inf)
    live = np.arange(B)
    size = B
    compacted = False  # numpy's kept residuals lie batch-major in memory from the first compaction on
    active = np.zeros(B, np.bool_)
    ep, er = np.empty(B), np.empty(B)
    qn, pn, zn = np.empty(n), np.empty((n, 3)), np.empty((n, 3))
    Rn, tn, epn, ern = np.empty((3, 3)), np.empty(3), np.empty(3), np.empty(3)
    for it in range(iterations + 1):
        left = 0
        lanes = compacted or size == 1
        for j in range(size):
            r = live[j]
            ep[r] = np.sqrt(_s3(EP[r, 0] * EP[r, 0], EP[r, 1] * EP[r, 1], EP[r, 2] * EP[r, 2], lanes))
            er[r] = np.sqrt(_s3(ER[r, 0] * ER[r, 0], ER[r, 1] * ER[r, 1], ER[r, 2] * ER[r, 2], True))
            act = (ep[r] > 1e-7 or er[r] > 1e-6) and lam[r] < 1e4
            if it == iterations:
                act = False
            if it % stall_every == 0:
                if it >= 2 * stall_every and cost[r] > stall_gain * ref[r] and ep[r] > give_up[r]:
                    act = False
                ref[r] = cost[r]
            active[r] = act
            left += act
        if left < 0.8 * size or left == 0:  # the numpy path's compaction: the rows gone are final
            k = 0
            for j in range(size):
                r = live[j]
                if active[r]:
                    live[k] = r
                    k += 1
                else:
                    for i in range(n):
                        q_out[i, r] = qc[r, i]
                    ep_out[r], er_out[r] = ep[r], er[r]
            size = k
            compacted = True
        if left == 0:
            break
        one = size == 1
        for j in range(size):
            r = live[j]
            if not active[r]:
                lam[r] = lam[r] * 4.0
                continue
            g = t_idx[r]
            _step(P[r], Z[r], RT[r], Tt[r], EP[r], ER[r], oriented[g], pointed[g], w, lam[r], n, qn, qc[r], lo, hi,
                  J, e, A, rhs, L, d, y, one)
            _forward(joints[c_idx[r]], qn, pn, zn, Rn, tn, n, R, R2, one)
            cn = _residual(xyz[g], G[g], oriented[g], pointed[g], axis[g], Rn, tn, epn, ern, E3, w2, one)
            if cn < cost[r]:
                for i in range(n):  # element by element: numba compiles a slice assignment slowly
                    qc[r, i] = qn[i]
                    for a in range(3):
                        P[r, i, a] = pn[i, a]
                        Z[r, i, a] = zn[i, a]
                for a in range(3):
                    Tt[r, a], EP[r, a], ER[r, a] = tn[a], epn[a], ern[a]
                    for k in range(3):
                        RT[r, a, k] = Rn[a, k]
                cost[r] = cn
                lam[r] = max(lam[r] / 3.0, 1e-9)
            else:
                lam[r] = lam[r] * 4.0
    return q_out, ep_out, er_out


_MATCHES: list[bool] = []


def matches_numpy() -> bool:
    """Whether numpy's arccos and arctan2 here are the C library's, which the kernel calls: not
    where numpy runs its own SIMD versions (builds for AVX-512). Else batches with oriented targets
    keep the numpy path (reach.solve asks; reach_jit.matches_numpy checks the sums and cos, sin)."""
    if not _MATCHES:
        import math

        rng = np.random.default_rng(0)
        ok = True
        for size in (1, 3, 8, 67, 1000):
            x, y = rng.uniform(-1.0, 1.0, size), np.abs(rng.normal(size=size))
            ok &= np.array_equal(np.arccos(x), [math.acos(v) for v in x])
            ok &= np.array_equal(np.arctan2(y, x), [math.atan2(a, b) for a, b in zip(y, x, strict=True)])
        _MATCHES.append(bool(ok))
    return _MATCHES[0]


def solve(joints: np.ndarray, c_idx: np.ndarray, t_idx: np.ndarray, tg, give_up: np.ndarray, q: np.ndarray,
          lo: np.ndarray, hi: np.ndarray, iterations: int, stall_every: int, stall_gain: float, lambda0: float,
          w: float):
    """reach.solve's runs for targets tg (reach.Targets, some oriented): q (n, B), ep (B,), er (B,)."""
    T = len(tg.names)
    pointed = tg.pointed if tg.pointed.size else np.zeros(T, bool)
    axis = tg.axis if tg.axis.size else np.zeros((T, 3))
    f = np.ascontiguousarray
    return _solve(f(joints, float), f(c_idx, np.int64), f(t_idx, np.int64), f(tg.xyz, float), f(tg.R, float),
                  f(tg.oriented, float), f(pointed, np.bool_), f(axis, float), f(give_up, float), f(q, float),
                  f(lo, float).ravel(), f(hi, float).ravel(), iterations, stall_every, stall_gain, lambda0, float(w))
