"""The position-only IK of modc.design.reach.solve compiled with numba, when numba is installed
(batches with oriented targets: modc.design.reach_jit_pose, the same way).

The numpy path streams ~100 whole-batch array operations per iteration (0.7 µs per run and
iteration at 4,096 runs); here one run's iteration stays in registers. It is the same
algorithm operation for operation, in the same order (the products of forward_flat(local=True,
rotation=False), _cross, the einsum sums k = 0, 1, 2, _ldl_solve, the clip, the damping
updates), and it keeps the batch's bookkeeping that decides a run's fate: a run the stall rule
drops stays in the arrays (and takes steps again) until a compaction, which happens only when
fewer than 80 % of the rows are active. So q and the errors are bit for bit those of the numpy
path (tests/test_design_batch_jit.py compares them); reach.jit says when it runs.
"""
from __future__ import annotations

import numpy as np


def _cache_dir() -> str | None:
    """Where numba keeps the compiled kernel: NUMBA_CACHE_DIR when the user set it, else a
    folder of the user's cache shared by every modc cache (the kernel depends on modc's source and
    numba alone, and compiling it takes ~10 s); None with MODC_NO_CACHE. Never numba's default,
    a __pycache__ beside modc's own files (the source tree, or site-packages)."""
    import os

    if os.environ.get("MODC_NO_CACHE"):
        return None
    if os.environ.get("NUMBA_CACHE_DIR"):
        return os.environ["NUMBA_CACHE_DIR"]
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    path = os.path.join(base, "modc-numba")
    try:
        os.makedirs(path, exist_ok=True)
    except OSError:
        return None
    os.environ["NUMBA_CACHE_DIR"] = path  # read by numba's config when it is imported, below
    return path


_CACHE = _cache_dir()
_CACHED = _CACHE is not None
try:  # imported only by reach.solve (numba takes ~0.3 s to import)
    import numba
except ImportError:  # pragma: no cover - the numpy path
    numba = None  # type: ignore[assignment]
if numba is not None and _CACHE is not None and numba.config.CACHE_DIR != _CACHE:  # type: ignore[attr-defined]
    numba.config.CACHE_DIR = _CACHE  # type: ignore[attr-defined]  # numba imported before NUMBA_CACHE_DIR was set


def _jit(f):
    return numba.njit(cache=_CACHED, nogil=True)(f) if numba is not None else f


def _inline(f):
    # inlined into the kernel: a call passing arrays costs their reference counting, more than the
    # work (the kernel runs 1.7x faster; its first compile takes ~10 s instead of ~7, once: cached)
    return numba.njit(cache=_CACHED, nogil=True, inline="always")(f) if numba is not None else f


@_jit
def _s3(a, b, c, one):
    """a + b + c as numpy's einsum sums three terms: in order, but (a + c) + b when the batch has
    one run (its reduced axis is then the contiguous one, summed two lanes at a time)."""
    return (a + c) + b if one else (a + b) + c


@_inline
def _forward(K, q, p, z, t, n, R, R2, one):
    """forward_flat(local=True, rotation=False) of one run: K (n+1, 4, 4) the joint transforms,
    q (n,) -> p, z (n, 3), tool0 t (3,), in joint 1's frame."""
    cs, sn = np.cos(q[0]), np.sin(q[0])
    for a in range(3):
        p[0, a] = 0.0
        z[0, a] = 0.0
    z[0, 2] = 1.0
    for k in range(3):
        R[0, k] = cs * K[1, 0, k] - sn * K[1, 1, k]
        R[1, k] = sn * K[1, 0, k] + cs * K[1, 1, k]
        R[2, k] = K[1, 2, k]
    t0 = cs * K[1, 0, 3] - sn * K[1, 1, 3]
    t1 = sn * K[1, 0, 3] + cs * K[1, 1, 3]
    t2 = K[1, 2, 3]
    if n == 1:
        t[0], t[1], t[2] = t0, t1, t2
        return
    for i in range(1, n):
        cs, sn = np.cos(q[i]), np.sin(q[i])
        if i > 1:
            u0 = _s3(R[0, 0] * K[i, 0, 3], R[0, 1] * K[i, 1, 3], R[0, 2] * K[i, 2, 3], one)
            u1 = _s3(R[1, 0] * K[i, 0, 3], R[1, 1] * K[i, 1, 3], R[1, 2] * K[i, 2, 3], one)
            u2 = _s3(R[2, 0] * K[i, 0, 3], R[2, 1] * K[i, 1, 3], R[2, 2] * K[i, 2, 3], one)
            t0, t1, t2 = t0 + u0, t1 + u1, t2 + u2
            if i == n - 1:
                p[i, 0], p[i, 1], p[i, 2] = t0, t1, t2
                for a in range(3):
                    z[i, a] = R[a, 0] * K[i, 0, 2] + R[a, 1] * K[i, 1, 2] + R[a, 2] * K[i, 2, 2]
                # tool0 = t + R . (K_i . Rz(q_i) . t(K_n))
                v0 = cs * K[n, 0, 3] - sn * K[n, 1, 3]
                v1 = sn * K[n, 0, 3] + cs * K[n, 1, 3]
                v2 = K[n, 2, 3]
                w0 = _s3(K[i, 0, 0] * v0, K[i, 0, 1] * v1, K[i, 0, 2] * v2, one)
                w1 = _s3(K[i, 1, 0] * v0, K[i, 1, 1] * v1, K[i, 1, 2] * v2, one)
                w2 = _s3(K[i, 2, 0] * v0, K[i, 2, 1] * v1, K[i, 2, 2] * v2, one)
                t[0] = t0 + _s3(R[0, 0] * w0, R[0, 1] * w1, R[0, 2] * w2, one)
                t[1] = t1 + _s3(R[1, 0] * w0, R[1, 1] * w1, R[1, 2] * w2, one)
                t[2] = t2 + _s3(R[2, 0] * w0, R[2, 1] * w1, R[2, 2] * w2, one)
                return
            for a in range(3):
                for k in range(3):
                    R2[a, k] = R[a, 0] * K[i, 0, k] + R[a, 1] * K[i, 1, k] + R[a, 2] * K[i, 2, k]
            for a in range(3):
                for k in range(3):
                    R[a, k] = R2[a, k]
        elif i == n - 1:
            p[i, 0], p[i, 1], p[i, 2] = t0, t1, t2
            for a in range(3):
                z[i, a] = R[a, 2]
            v0 = cs * K[n, 0, 3] - sn * K[n, 1, 3]
            v1 = sn * K[n, 0, 3] + cs * K[n, 1, 3]
            v2 = K[n, 2, 3]
            t[0] = t0 + _s3(R[0, 0] * v0, R[0, 1] * v1, R[0, 2] * v2, one)
            t[1] = t1 + _s3(R[1, 0] * v0, R[1, 1] * v1, R[1, 2] * v2, one)
            t[2] = t2 + _s3(R[2, 0] * v0, R[2, 1] * v1, R[2, 2] * v2, one)
            return
        for a in range(3):
            x, y = R[a, 0], R[a, 1]
            R[a, 0] = cs * x + sn * y
            R[a, 1] = cs * y - sn * x
        p[i, 0], p[i, 1], p[i, 2] = t0, t1, t2
        for a in range(3):
            z[i, a] = R[a, 2]
    t[0], t[1], t[2] = t0, t1, t2  # not reached: the last joint returns above


@_inline
def _ldl_clip(A, rhs, n, qn, q, lo, hi, L, d, y):
    """qn = clip(q + dq, lo, hi) with A dq = rhs, A's upper triangle symmetric positive definite:
    reach._ldl_solve's element-wise LDL^T, then the clip (both kernels' last part of a step)."""
    for j in range(n):
        dj = A[j, j]
        for k in range(j):
            dj = dj - L[j, k] * L[j, k] * d[k]
        d[j] = dj
        for i in range(j + 1, n):
            a = A[j, i]
            for k in range(j):
                a = a - L[i, k] * L[j, k] * d[k]
            L[i, j] = a / dj
    for i in range(n):
        yi = rhs[i]
        for k in range(i):
            yi = yi - L[i, k] * y[k]
        y[i] = yi
    for i in range(n - 1, -1, -1):
        xi = y[i] / d[i]
        for k in range(i + 1, n):
            xi = xi - L[k, i] * qn[k]
        qn[i] = xi
    for i in range(n):
        v = qn[i] + q[i]
        if v < lo[i]:  # np.maximum then np.minimum; a NaN stays NaN as there
            v = lo[i]
        if v > hi[i]:
            v = hi[i]
        qn[i] = v


@_inline
def _step(p, z, t, e, lam, n, qn, q, lo, hi, J, A, rhs, L, d, y, one):
    """qn = clip(q + dq) with (J^T J + lam I) dq = J^T e: reach._step's order of operations."""
    for i in range(n):
        b0, b1, b2 = t[0] - p[i, 0], t[1] - p[i, 1], t[2] - p[i, 2]
        J[i, 0] = z[i, 1] * b2 - z[i, 2] * b1
        J[i, 1] = z[i, 2] * b0 - z[i, 0] * b2
        J[i, 2] = z[i, 0] * b1 - z[i, 1] * b0
    for i in range(n):
        for j in range(i, n):
            A[i, j] = _s3(J[i, 0] * J[j, 0], J[i, 1] * J[j, 1], J[i, 2] * J[j, 2], one)
        A[i, i] = A[i, i] + lam
        rhs[i] = _s3(J[i, 0] * e[0], J[i, 1] * e[1], J[i, 2] * e[2], one)
    _ldl_clip(A, rhs, n, qn, q, lo, hi, L, d, y)


@_jit
def _solve_position(joints, c_idx, t_idx, xyz, give_up, q, lo, hi, iterations, stall_every, stall_gain,
                    lambda0):
    """joints (C, n+1, 4, 4), c_idx, t_idx (B,), xyz (T, 3) targets in the base frame, give_up (B,)
    m, q (n, B) the starts -> q (n, B) where each run ended and its position error ep (B,)."""
    n, B = q.shape
    xl = np.empty((B, 3))
    for r in range(B):
        K0 = joints[c_idx[r], 0]
        d0 = xyz[t_idx[r], 0] - K0[0, 3]
        d1 = xyz[t_idx[r], 1] - K0[1, 3]
        d2 = xyz[t_idx[r], 2] - K0[2, 3]
        for k in range(3):
            xl[r, k] = K0[0, k] * d0 + K0[1, k] * d1 + K0[2, k] * d2
    qc = np.ascontiguousarray(q.T)
    R, R2 = np.empty((3, 3)), np.empty((3, 3))  # scratch: an allocation per run and step costs more than the step
    J, A, L = np.empty((n, 3)), np.empty((n, n)), np.zeros((n, n))
    rhs, d, y = np.empty(n), np.empty(n), np.empty(n)
    q_out = np.empty((n, B))
    ep_out = np.empty(B)
    P = np.empty((B, n, 3))
    Z = np.empty((B, n, 3))
    Tt = np.empty((B, 3))
    E = np.empty((B, 3))
    cost = np.empty(B)
    for r in range(B):
        _forward(joints[c_idx[r]], qc[r], P[r], Z[r], Tt[r], n, R, R2, B == 1)
        for a in range(3):
            E[r, a] = xl[r, a] - Tt[r, a]
        cost[r] = _s3(E[r, 0] * E[r, 0], E[r, 1] * E[r, 1], E[r, 2] * E[r, 2], B == 1)
    lam = np.full(B, lambda0)
    ref = np.full(B, np.inf)
    live = np.arange(B)
    size = B
    active = np.zeros(B, np.bool_)
    ep = np.empty(B)
    qn = np.empty(n)
    pn = np.empty((n, 3))
    zn = np.empty((n, 3))
    tn = np.empty(3)
    for it in range(iterations + 1):
        left = 0
        for j in range(size):
            r = live[j]
            ep[r] = np.sqrt(cost[r])
            act = ep[r] > 1e-7 and lam[r] < 1e4
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
                    ep_out[r] = ep[r]
            size = k
        if left == 0:
            break
        one = size == 1
        for j in range(size):
            r = live[j]
            if not active[r]:
                lam[r] = lam[r] * 4.0
                continue
            _step(P[r], Z[r], Tt[r], E[r], lam[r], n, qn, qc[r], lo, hi, J, A, rhs, L, d, y, one)
            _forward(joints[c_idx[r]], qn, pn, zn, tn, n, R, R2, one)
            e0, e1, e2 = xl[r, 0] - tn[0], xl[r, 1] - tn[1], xl[r, 2] - tn[2]
            cn = _s3(e0 * e0, e1 * e1, e2 * e2, one)
            if cn < cost[r]:
                for i in range(n):  # element by element: numba compiles a slice assignment slowly
                    qc[r, i] = qn[i]
                    for a in range(3):
                        P[r, i, a] = pn[i, a]
                        Z[r, i, a] = zn[i, a]
                for a in range(3):
                    Tt[r, a] = tn[a]
                E[r, 0], E[r, 1], E[r, 2] = e0, e1, e2
                cost[r] = cn
                lam[r] = max(lam[r] / 3.0, 1e-9)
            else:
                lam[r] = lam[r] * 4.0
    return q_out, ep_out


def matches_numpy() -> bool:
    """Whether numpy's cos and sin are the C library's (which numba calls) and its einsum sums as
    _s3 and reach_jit_pose._dot assume (in order over a batch; two lanes, (a + c) + b, for a batch
    of one, as its SIMD kernels of 2, 4 or 8 lanes do for three terms; two lanes for six terms
    too; two lanes over a batch stored batch-major, as reach's rotation residual is): else the
    kernels would not return numpy's bits, and reach.jit keeps the numpy path."""
    import math

    rng = np.random.default_rng(0)
    for size in (1, 3, 8, 67, 1000):  # cos and sin: the C library's, as numba calls them (not numpy's SIMD)
        a = rng.uniform(-4.0, 4.0, size)
        if not (np.array_equal(np.cos(a), [math.cos(v) for v in a])
                and np.array_equal(np.sin(a), [math.sin(v) for v in a])):
            return False

    def lanes(t):
        return sum(t[2::2], t[0]) + sum(t[3::2], t[1])

    for B in (1, 2, 5):
        for _ in range(16):
            J, e = rng.normal(size=(3, 3, B)), rng.normal(size=(3, B))
            x = J[:, 0] * e[0], J[:, 1] * e[1], J[:, 2] * e[2]
            want = (x[0] + x[2]) + x[1] if B == 1 else (x[0] + x[1]) + x[2]
            sq = e[0] * e[0], e[1] * e[1], e[2] * e[2]
            want_sq = (sq[0] + sq[2]) + sq[1] if B == 1 else (sq[0] + sq[1]) + sq[2]
            if not (np.array_equal(np.einsum("ikb,kb->ib", J, e), want)
                    and np.array_equal(np.einsum("ib,ib->b", e, e), want_sq)):
                return False
            J6, e6 = rng.normal(size=(2, 6, B)), rng.normal(size=(6, B))
            t = [J6[0, k] * J6[1, k] for k in range(6)]
            u = [J6[:, k] * e6[k] for k in range(6)]
            et = np.moveaxis(np.ascontiguousarray(e.T), -1, 0)  # (3, B), the batch outermost in memory
            if not (np.array_equal(np.einsum("ikb,jkb->ijb", J6, J6)[0, 1], lanes(t) if B == 1 else sum(t[1:], t[0]))
                    and np.array_equal(np.einsum("ikb,kb->ib", J6, e6), lanes(u) if B == 1 else sum(u[1:], u[0]))
                    and np.array_equal(np.einsum("ib,ib->b", et, et), (sq[0] + sq[2]) + sq[1])):
                return False
    return True


def solve_position(joints: np.ndarray, c_idx: np.ndarray, t_idx: np.ndarray, xyz: np.ndarray, give_up: np.ndarray,
                   q: np.ndarray, lo: np.ndarray, hi: np.ndarray, iterations: int, stall_every: int,
                   stall_gain: float, lambda0: float):
    return _solve_position(np.ascontiguousarray(joints, float), np.ascontiguousarray(c_idx, np.int64),
             np.ascontiguousarray(t_idx, np.int64), np.ascontiguousarray(xyz, float),
             np.ascontiguousarray(give_up, float), np.ascontiguousarray(q, float),
             np.ascontiguousarray(lo, float).ravel(), np.ascontiguousarray(hi, float).ravel(), iterations,
             stall_every, stall_gain, lambda0)
