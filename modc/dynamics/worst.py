"""Worst-case static gravity torque per joint over the joint ranges.

|g_i(q)| is a smooth trigonometric polynomial on a box. We sample the box (seeded, so results
are reproducible), then refine the best samples of every joint by projected gradient ascent
with pinocchio's analytic derivatives dg/dq, stopping where the projected gradient vanishes (a
local maximum on the box). Starting from many well-spread samples makes missing the global
maximum unlikely; the tests compare with a dense grid.

The result is a pure function of the checked robot (its arm, base, payload and library) and the
search's parameters, so modc.dynamics.torque caches it on disk under their digest: a compile
whose robot has not changed needs neither pinocchio nor numpy for it.
"""
from __future__ import annotations

import numpy as np

from .model import Dynamics
from .torque import REFINE, SAMPLES, SEED, JointWorst


def _ascend(dyn: Dynamics, i: int, q: np.ndarray, iters: int = 60) -> tuple[float, np.ndarray]:
    lo, hi = dyn.lower, dyn.upper
    val = abs(dyn.gravity(q)[i])
    step = 0.3
    for _ in range(iters):
        g = dyn.gravity(q)[i]
        grad = np.sign(g) * dyn.gravity_derivatives(q)[i]
        free = ~(((q <= lo + 1e-12) & (grad < 0)) | ((q >= hi - 1e-12) & (grad > 0)))
        grad = grad * free
        norm = np.linalg.norm(grad)
        if norm < 1e-10:
            break
        while step > 1e-6:
            cand = np.clip(q + step * grad / norm, lo, hi)
            cval = abs(dyn.gravity(cand)[i])
            if cval > val:
                q, val = cand, cval
                step = min(step * 1.5, 1.0)
                break
            step *= 0.5
        else:
            break
    return val, q


def _canonical(dyn: Dynamics, i: int, val: float, q: np.ndarray) -> tuple[float, np.ndarray]:
    """Joints the worst case does not depend on (joint 1 about a vertical axis, say) are set to 0
    (or the nearest limit), so the reported pose says which joints matter and is reproducible."""
    if val < 1e-9:
        return 0.0, np.clip(np.zeros_like(q), dyn.lower, dyn.upper)
    for k in range(len(q)):
        trial = q.copy()
        trial[k] = np.clip(0.0, dyn.lower[k], dyn.upper[k])
        tv = abs(dyn.gravity(trial)[i])
        if tv >= val * (1 - 1e-9):
            q, val = trial, max(val, tv)
    return val, q


def worst_case(dyn: Dynamics, samples: int = SAMPLES, refine: int = REFINE, seed: int = SEED) -> list[JointWorst]:
    robot = dyn.robot
    lib = robot.library
    n = dyn.nq
    rng = np.random.default_rng(seed)
    Q = rng.uniform(dyn.lower, dyn.upper, size=(samples, n))
    Q = np.vstack([Q, np.zeros(n)])
    G = np.abs(np.array([dyn.gravity(q) for q in Q]))
    out = []
    for i in range(n):
        best_val, best_q = -1.0, None
        for k in np.argsort(-G[:, i])[:refine]:
            val, q = _ascend(dyn, i, Q[k].copy())
            if val > best_val:
                best_val, best_q = val, q
        assert best_q is not None
        best_val, best_q = _canonical(dyn, i, best_val, best_q)
        act = lib.variants[robot.units[i].variant].actuator
        out.append(JointWorst(f"joint_{i + 1}", robot.units[i].name, float(best_val), tuple(float(x) for x in best_q),
                              act.torque_nominal, act.torque_peak))
    return out


