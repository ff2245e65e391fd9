"""Worst-case static gravity torque per joint over the joint ranges.

|g_i(q)| is a smooth trigonometric polynomial on a box. We sample the box (seeded, so results
are reproducible), then refine the best samples of every joint by projected gradient ascent
with analytic derivatives dg/dq, stopping where the projected gradient vanishes (a local
maximum on the box). Starting from many well-spread samples makes missing the global maximum
unlikely; the tests compare with a dense grid.

The ascents of every joint and start run side by side, one pose per ascent per step, so that
each step is one batched call of the gravity model: the numpy statics (modc.physical.statics,
what the compile uses: no pinocchio to import) or pinocchio's (dynamics.Dynamics, the
reference; the tests compare both). Each ascent takes the steps it would take alone.

The result is a pure function of the checked robot (its arm, base, payload and library) and the
search's parameters, so modc.dynamics.torque caches it on disk under their digest: a compile
whose robot has not changed needs neither pinocchio nor numpy for it.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from .model import Dynamics  # the reference model worst_case runs on (modc check's callers import it from here)
from .torque import REFINE, SAMPLES, SEED, JointWorst

ITERS = 60  # gradient steps per ascent at most
MIN_STEP = 1e-6  # rad: a line search gives up below this step


def _ascend(model: Any, joint: np.ndarray, q: np.ndarray, iters: int = ITERS) -> tuple[np.ndarray, np.ndarray]:
    """Projected gradient ascent of |g_joint[a](q)| from each row q[a], all at once: (values, poses).
    Per ascent: take the gradient, then halve the step from the last one (x1.5 after a success)
    until a step gains, or give up below MIN_STEP; stop where the projected gradient vanishes."""
    lo, hi = model.lower, model.upper
    lo_in, hi_in = lo + 1e-12, hi - 1e-12
    L = len(joint)
    q = q.copy()
    g, J = model.gravity_with_jacobians(q)
    val = np.abs(g[np.arange(L), joint])
    step = np.full(L, 0.3)
    grad, norm = np.zeros_like(q), np.ones(L)
    active = np.ones(L, bool)
    taken = np.zeros(L, int)  # gradients taken

    def new_direction(a: np.ndarray, g_a: np.ndarray, J_a: np.ndarray) -> None:
        """Lanes a take the gradient at their pose (g_a, J_a: the model at it); a lane that has taken
        `iters` of them, or whose projected gradient vanishes, stops."""
        over = taken[a] >= iters
        if over.any():
            active[a[over]] = False
            a, g_a, J_a = a[~over], g_a[~over], J_a[~over]
        rows, ja = np.arange(len(a)), joint[a]
        d = np.sign(g_a[rows, ja])[:, None] * J_a[rows, ja]
        qa = q[a]
        d[((qa <= lo_in) & (d < 0)) | ((qa >= hi_in) & (d > 0))] = 0.0  # pushing out of the box: held
        nrm = np.sqrt((d * d).sum(axis=1))
        flat = nrm < 1e-10
        active[a[flat]] = False
        grad[a], norm[a] = d, np.where(flat, 1.0, nrm)
        taken[a] += 1

    new_direction(np.arange(L), g, J)
    while True:
        active &= step > MIN_STEP  # a line search that found no gain: the ascent ends
        s = np.flatnonzero(active)
        if s.size == 0:
            return val, q
        cand = np.clip(q[s] + step[s][:, None] * grad[s] / norm[s][:, None], lo, hi)
        g, J = model.gravity_with_jacobians(cand)
        cval = np.abs(g[np.arange(s.size), joint[s]])
        up = cval > val[s]
        a = s[up]
        q[a], val[a] = cand[up], cval[up]
        step[a] = np.minimum(step[a] * 1.5, 1.0)
        step[s[~up]] *= 0.5
        if a.size:
            new_direction(a, g[up], J[up])


def _canonical(model: Any, joint: np.ndarray, val: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Joints the worst case does not depend on (joint 1 about a vertical axis, say) are set to 0
    (or the nearest limit), so the reported pose says which joints matter and is reproducible.
    One lane per row (joint[a], val[a], q[a]); a lane without torque gets the pose 0 (clipped)."""
    lo, hi = model.lower, model.upper
    val, q = val.copy(), q.copy()
    zero = val < 1e-9
    rows = np.arange(len(joint))
    for k in range(q.shape[1]):
        trial = q.copy()
        trial[:, k] = np.clip(0.0, lo[k], hi[k])
        tv = np.abs(model.gravities(trial)[rows, joint])
        ok = (tv >= val * (1 - 1e-9)) & ~zero
        q[ok], val[ok] = trial[ok], np.maximum(val[ok], tv[ok])
    val[zero] = 0.0
    q[zero] = np.clip(np.zeros(q.shape[1]), lo, hi)
    return val, q


def worst_case(model: Any, samples: int = SAMPLES, refine: int = REFINE, seed: int = SEED) -> list[JointWorst]:
    """model: robot, nq, lower, upper, gravities(Q) (N, n) and gravity_with_jacobians(Q) ((N, n), (N, n, n)):
    modc.physical.statics.Statics or modc.dynamics.model.Dynamics."""
    robot = model.robot
    lib = robot.library
    n = model.nq
    rng = np.random.default_rng(seed)
    Q = rng.uniform(model.lower, model.upper, size=(samples, n))
    Q = np.vstack([Q, np.zeros(n)])
    G = np.abs(model.gravities(Q))
    starts = [(i, k) for i in range(n) for k in np.argsort(-G[:, i])[:refine]]
    joint = np.array([i for i, _ in starts], int)
    vals, poses = _ascend(model, joint, Q[[k for _, k in starts]])
    best = [max((a for a in range(len(starts)) if joint[a] == i), key=lambda a: (vals[a], -a)) for i in range(n)]
    val, q = _canonical(model, np.arange(n), vals[best], poses[best])
    out = []
    for i in range(n):
        act = lib.variants[robot.units[i].variant].actuator
        out.append(JointWorst(f"joint_{i + 1}", robot.units[i].name, float(val[i]), tuple(float(x) for x in q[i]),
                              act.torque_nominal, act.torque_peak))
    return out


__all__ = ["Dynamics", "worst_case"]
