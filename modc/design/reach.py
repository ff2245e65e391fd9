"""Inverse kinematics of many candidate chains at once: damped least squares (Levenberg-Marquardt,
a damping per run that shrinks on success and grows on failure), projected onto the joint limits,
from the same few seeds for every candidate. Position only, or 6-D for targets with an
orientation (the rotation error is weighted by ROTATION_WEIGHT metres per radian).

This is the search's screen: a run counts when it ends within the target's tolerances. The
chosen joint vectors are then checked exactly by modc.design.evaluate.verify.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .batch import Flat, Geometry, forward_flat, rotation_error

ROTATION_WEIGHT = 0.2  # m/rad: 1° of orientation error costs as much as 3.5 mm
ITERATIONS = 40
LAMBDA0 = 1e-2
STALL_EVERY, STALL_GAIN, STALL_FACTOR = 5, 0.5, 3.0


@dataclass(frozen=True)
class Targets:
    xyz: np.ndarray  # (T, 3) m
    R: np.ndarray  # (T, 3, 3)
    oriented: np.ndarray  # (T,) bool
    tol_p: np.ndarray  # (T,) m
    tol_r: np.ndarray  # (T,) rad
    names: tuple[str, ...]
    # (T, 3) unit vectors, (T,) bool: targets that constrain only tool0's x axis (`pointing`; oriented too)
    axis: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    pointed: np.ndarray = field(default_factory=lambda: np.zeros(0, bool))

    @classmethod
    def of(cls, targets) -> Targets:
        from ..kinematics import rpy_matrix

        return cls(np.array([t.xyz for t in targets], float).reshape(-1, 3),
                   np.array([rpy_matrix(t.rpy or (0.0, 0.0, 0.0)) for t in targets]).reshape(-1, 3, 3),
                   np.array([t.rpy is not None or _axis(t) is not None for t in targets], bool),
                   np.array([t.position_tolerance for t in targets], float),
                   np.array([t.orientation_tolerance for t in targets], float),
                   tuple(t.name for t in targets),
                   np.array([_axis(t) or (1.0, 0.0, 0.0) for t in targets], float).reshape(-1, 3),
                   np.array([_axis(t) is not None for t in targets], bool))

    def take(self, k) -> Targets:
        """The targets k (a slice or an index array)."""
        return Targets(self.xyz[k], self.R[k], self.oriented[k], self.tol_p[k], self.tol_r[k],
                       tuple(np.asarray(self.names, object)[k]), self.axis[k], self.pointed[k])


def _axis(t):
    return getattr(t, "pointing", None) if t.rpy is None else None


def axis_error(x, d):
    """Rotation vectors (3, B) of the shortest turn taking tool0's x axis x (3, B) onto d (3, B):
    the orientation error of a `pointing` target (angle = its norm; no part about the axis)."""
    v = np.cross(x, d, axis=0)
    s = np.sqrt((v ** 2).sum(0))
    angle = np.arctan2(s, (x * d).sum(0))
    # opposite axes: any perpendicular turn (the cross product vanishes; take one off x)
    alt = np.cross(x, np.where(np.abs(x[0:1]) < 0.9, np.array([[1.0], [0.0], [0.0]]), np.array([[0.0], [1.0], [0.0]])),
                   axis=0)
    v = np.where(s > 1e-12, v, alt)
    return v * (angle / np.maximum(np.sqrt((v ** 2).sum(0)), 1e-300))


def seeds(n: int, count: int, lower, upper, seed: int) -> np.ndarray:
    """(count, n): the zero pose (clipped to the limits), then uniform samples from default_rng(seed)."""
    rng = np.random.default_rng(seed)
    lower, upper = np.asarray(lower, float), np.asarray(upper, float)
    out = [np.clip(np.zeros(n), lower, upper)]
    out += list(lower + (upper - lower) * rng.random((count - 1, n)))
    return np.array(out)


def _rotation_error(Rt, R):
    """Rotation vectors (3, B) of Rt . R^T for stacks (3, 3, B): the turn that brings R onto Rt."""
    E = np.stack([np.stack([Rt[i, 0] * R[j, 0] + Rt[i, 1] * R[j, 1] + Rt[i, 2] * R[j, 2] for j in range(3)])
                  for i in range(3)])
    return np.moveaxis(rotation_error(np.eye(3), np.moveaxis(E, -1, 0).transpose(0, 2, 1)), -1, 0)


class _Runs:
    """The residuals of the live runs: position (3, B), weighted rotation (3, B), cost (B,)."""

    def __init__(self, tg: Targets, ti: np.ndarray):
        self.xyz = np.ascontiguousarray(tg.xyz[ti].T)
        self.R = np.ascontiguousarray(np.moveaxis(tg.R[ti], 0, -1))
        self.oriented = tg.oriented[ti].astype(float)
        self.any_oriented = bool(tg.oriented[ti].any())
        pointed = tg.pointed if tg.pointed.size else np.zeros(len(tg.names), bool)
        axis = tg.axis if tg.axis.size else np.zeros((len(tg.names), 3))
        self.pointed = pointed[ti]
        self.axis = np.ascontiguousarray(axis[ti].T)
        self.any_pointed = bool(self.pointed.any())

    def take(self, keep):
        out = object.__new__(_Runs)
        out.xyz, out.R, out.oriented = self.xyz[:, keep], self.R[..., keep], self.oriented[keep]
        out.pointed, out.axis = self.pointed[keep], self.axis[:, keep]
        out.any_oriented, out.any_pointed = self.any_oriented, self.any_pointed
        return out

    def rotation_rows(self, z, R_tool):
        """The rotation rows of J (n, 3, b): the joint axes z; for a `pointing` run without their
        part about tool0's x axis (turning about it changes nothing the target asks for)."""
        Jr = z * self.oriented
        if self.any_pointed:
            x = R_tool[:, 0]
            Jr = np.where(self.pointed, Jr - x[None] * (Jr * x[None]).sum(1, keepdims=True), Jr)
        return Jr


def _ldl_solve(A: dict, b: list, n: int) -> np.ndarray:
    """x (n, B) with A x = b for B symmetric positive definite n x n systems at once (A: the upper
    triangle, A[i, j] for i <= j, each (B,)): an LDL^T factorisation written out element-wise -
    A = J^T J + lam I has lam > 0, so no pivot is needed - a few dozen vector operations where a
    LAPACK call per system costs a microsecond each."""
    L: dict = {}
    d: list = []
    for j in range(n):
        dj = A[j, j]
        for k in range(j):
            dj = dj - L[j, k] * L[j, k] * d[k]
        d.append(dj)
        for i in range(j + 1, n):
            a = A[j, i]
            for k in range(j):
                a = a - L[i, k] * L[j, k] * d[k]
            L[i, j] = a / dj
    y: list = []
    for i in range(n):
        yi = b[i]
        for k in range(i):
            yi = yi - L[i, k] * y[k]
        y.append(yi)
    x = np.empty((n, len(d[0])))
    for i in range(n - 1, -1, -1):
        xi = y[i] / d[i]
        for k in range(i + 1, n):
            xi = xi - L[k, i] * x[k]
        x[i] = xi
    return x


def _step(J: np.ndarray, e: np.ndarray, lam: np.ndarray) -> np.ndarray:
    """The damped least-squares step dq (n, B): (J^T J + lam I) dq = J^T e, J (n, m, B), e (m, B)."""
    n = J.shape[0]
    JJ = np.einsum("ikb,jkb->ijb", J, J)
    A = {(i, j): JJ[i, j] for i in range(n) for j in range(i, n)}
    for i in range(n):
        A[i, i] = A[i, i] + lam
    return _ldl_solve(A, list(np.einsum("ikb,kb->ib", J, e)), n)


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a x b along axis 1 of (n, 3, B) stacks."""
    out = np.empty(a.shape)
    for k, (i, j) in enumerate(((1, 2), (2, 0), (0, 1))):
        np.subtract(a[:, i] * b[:, j], a[:, j] * b[:, i], out=out[:, k])
    return out


def _sq(v: np.ndarray) -> np.ndarray:
    """|v|^2 along axis 0 of (3, B)."""
    return np.einsum("ib,ib->b", v, v)


_JIT: list[bool] = []
JIT_AFTER = 50_000  # runs solved with numpy before a process loads the compiled path (see jit())
_NUMPY_RUNS = [0]


def jit(runs: int = 0) -> bool:
    """Whether `runs` runs take the compiled path (modc.design.reach_jit, reach_jit_pose: numba).
    Both paths return the same bits, so when to switch is a matter of cost only: importing numba
    and loading the cached kernel take ~0.9 s CPU per process, so a process switches once it has
    solved JIT_AFTER runs with numpy (~0.5 s; more with oriented runs, which cost more each; their kernel
    another ~0.5 s to load, when the first oriented batch comes) - a short search never pays for it.
    Oriented and position-only runs count alike. MODC_JIT=0 never switches, MODC_JIT=1 at once;
    without numba installed the numpy path always runs."""
    import os

    mode = os.environ.get("MODC_JIT", "")
    if mode == "0":
        return False
    if mode != "1" and _NUMPY_RUNS[0] < JIT_AFTER:
        _NUMPY_RUNS[0] += runs
        return False
    if not _JIT:
        try:
            from . import reach_jit  # noqa: F401  (numba; its cache needs a writable folder)
        except Exception:  # noqa: BLE001 - numba missing or unusable here: the numpy path
            _JIT.append(False)
        else:
            _JIT.append(reach_jit.numba is not None and reach_jit.matches_numpy())
    return _JIT[0]


def _pose_jit() -> bool:
    """Whether batches with oriented targets take the compiled path too (once jit() says so)."""
    from . import reach_jit_pose

    return reach_jit_pose.matches_numpy()


def solve(g: Geometry, tg: Targets, q0: np.ndarray, lower, upper, iterations: int = ITERATIONS,
          rows: np.ndarray | None = None):
    """Runs from every seed q0 (S, n), or per candidate (C, S, n), towards every target, for
    every candidate of g (or its candidates `rows`, without copying g's arrays for them). Returns
    q (C, T, S, n), position error (C, T, S) m, orientation error (C, T, S) rad.

    The runs are one flat batch; a run leaves it when it is within 1e-7 m (and 1e-6 rad) of its target or
    stalls (its damping saturates), so late iterations cost only what is still moving. Targets
    without an orientation take a position-only path: no tool rotation, three residual rows."""
    C, n, T, S = g.pre.shape[0] if rows is None else len(rows), g.dof, len(tg.names), q0.shape[-2]
    lo, hi = np.asarray(lower, float)[:, None], np.asarray(upper, float)[:, None]
    B = C * T * S
    c_idx = np.repeat(np.arange(C) if rows is None else np.asarray(rows), T * S)
    t_idx = np.tile(np.repeat(np.arange(T), S), C)
    q_all = np.ascontiguousarray((np.tile(q0, (C * T, 1)) if q0.ndim == 2 else
                                  np.repeat(q0[:, None], T, axis=1).reshape(B, n)).T)  # (n, B)
    ep_all, er_all = np.empty(B), np.zeros(B)
    oriented = bool(np.asarray(tg.oriented).any())
    if jit(B) and (not oriented or _pose_jit()):
        # the same runs compiled, bit for bit (reach_jit's and reach_jit_pose's docstrings)
        give_up = np.asarray(tg.tol_p, float)[t_idx] * STALL_FACTOR
        if not oriented:
            from . import reach_jit

            q_all, ep_all = reach_jit.solve_position(g.joints, c_idx, t_idx, tg.xyz, give_up, q_all, lo, hi,
                                                     iterations, STALL_EVERY, STALL_GAIN, LAMBDA0)
        else:
            from . import reach_jit_pose

            q_all, ep_all, er_all = reach_jit_pose.solve(g.joints, c_idx, t_idx, tg, give_up, q_all, lo, hi,
                                                         iterations, STALL_EVERY, STALL_GAIN, LAMBDA0,
                                                         ROTATION_WEIGHT)
        return q_all.T.reshape(C, T, S, n), ep_all.reshape(C, T, S), er_all.reshape(C, T, S)
    w = ROTATION_WEIGHT
    live = np.arange(B)
    q = q_all.copy()
    f = Flat.of(g, c_idx)
    runs = _Runs(tg, t_idx)
    oriented = runs.any_oriented
    # a run still STALL_FACTOR tolerances off that has not cut its cost by STALL_GAIN in STALL_EVERY
    # iterations leaves: the screen is a local search, and such runs end beyond the tolerance
    give_up = np.asarray(tg.tol_p, float)[t_idx] * STALL_FACTOR
    ref = np.full(B, np.inf)
    if not oriented:  # position only: in joint 1's frame (batch.forward_flat, local)
        d = runs.xyz - f.k_t[0]
        runs.xyz = np.stack([f.k_R[0][0, k] * d[0] + f.k_R[0][1, k] * d[1] + f.k_R[0][2, k] * d[2] for k in range(3)])
    local = not oriented
    p, z, R_tool, t_tool = forward_flat(f, q, rotation=oriented, local=local)
    e_p, e_r, cost = _residual(runs, R_tool, t_tool, oriented)
    lam = np.full(B, LAMBDA0)
    for it in range(iterations + 1):
        # runs go on well inside the tolerances (LM converges quadratically there): reported errors are ~0
        if oriented:
            ep, er = np.sqrt(_sq(e_p)), np.sqrt(_sq(e_r))
            active = ((ep > 1e-7) | (er > 1e-6)) & (lam < 1e4)
        else:
            ep = np.sqrt(cost)
            active = (ep > 1e-7) & (lam < 1e4)
        if it == iterations:
            active[:] = False
        if it % STALL_EVERY == 0:
            if it >= 2 * STALL_EVERY:
                active &= ~((cost > STALL_GAIN * ref) & (ep > give_up))
            ref = cost
        left = np.count_nonzero(active)
        if left < 0.8 * active.size or not left:  # compaction costs: do it in steps
            gone = ~active
            q_all[:, live[gone]], ep_all[live[gone]] = q[:, gone], ep[gone]
            if oriented:
                er_all[live[gone]] = er[gone]
            live, q, f, runs = live[active], q[:, active], f.take(active), runs.take(active)
            give_up, ref, cost, lam = give_up[active], ref[active], cost[active], lam[active]
            p, z, t_tool, e_p = p[..., active], z[..., active], t_tool[:, active], e_p[:, active]
            if oriented:
                R_tool, e_r, er = R_tool[..., active], e_r[:, active], er[active]
            active = active[active]
        if not left:
            break
        # J columns: position z_i x (p_tool - p_i), rotation z_i (weighted, oriented targets only)
        J = _cross(z, t_tool[None] - p)  # (n, 3, b)
        e = e_p
        if oriented:
            J = np.concatenate([J, w * runs.rotation_rows(z, R_tool)], axis=1)  # (n, 6, b)
            e = np.concatenate([e_p, w * e_r], axis=0)  # (6, b)
        qn = _step(J, e, lam)
        qn += q
        np.minimum(np.maximum(qn, lo, out=qn), hi, out=qn)
        pn, zn, Rn, tn = forward_flat(f, qn, rotation=oriented, local=local)
        e_pn, e_rn, cost_n = _residual(runs, Rn, tn, oriented)
        ok = (cost_n < cost) & active
        np.copyto(q, qn, where=ok)
        np.copyto(p, pn, where=ok)
        np.copyto(z, zn, where=ok)
        np.copyto(t_tool, tn, where=ok)
        np.copyto(e_p, e_pn, where=ok)
        if oriented:
            np.copyto(R_tool, Rn, where=ok)
            np.copyto(e_r, e_rn, where=ok)
        cost = np.where(ok, cost_n, cost)
        lam = np.where(ok, np.maximum(lam / 3.0, 1e-9), lam * 4.0)
    return q_all.T.reshape(C, T, S, n), ep_all.reshape(C, T, S), er_all.reshape(C, T, S)


def _residual(runs: _Runs, R_tool, t_tool, oriented: bool):
    """Position and rotation residuals and the cost |e_p|^2 + w^2 |e_r|^2 (no rotation part for
    position-only runs: e_r None)."""
    e_p = runs.xyz - t_tool
    if not oriented:
        return e_p, None, _sq(e_p)
    e_r = _rotation_error(runs.R, R_tool) * runs.oriented
    if runs.any_pointed:
        e_r = np.where(runs.pointed, axis_error(R_tool[:, 0], runs.axis), e_r)
    return e_p, e_r, _sq(e_p) + ROTATION_WEIGHT * ROTATION_WEIGHT * _sq(e_r)
