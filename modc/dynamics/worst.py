"""Worst-case static gravity torque per joint over the joint ranges.

|g_i(q)| is a smooth trigonometric polynomial on a box. We sample the box (seeded, so results
are reproducible), then refine the best samples of every joint by projected gradient ascent
with pinocchio's analytic derivatives dg/dq, stopping where the projected gradient vanishes (a
local maximum on the box). Starting from many well-spread samples makes missing the global
maximum unlikely; the tests compare with a dense grid.

The result is a pure function of the arm's Description (inertials, joints, limits), gravity, the
actuators' torques and the search's parameters, so it is cached on disk under their digest
(modc.cache): a compile whose arm has not changed needs no pinocchio at all.
"""
from __future__ import annotations

import json
from dataclasses import dataclass

import numpy as np

from .. import cache
from ..model import ResolvedRobot
from .model import Dynamics, PayloadOverride, gravity, with_payload

ALGORITHM = "1"  # bump when worst_case() could give another result for the same input


@dataclass(frozen=True)
class JointWorst:
    name: str
    variant: str
    tau: float  # max |g_i(q)|, N·m
    q: tuple[float, ...]  # the pose where it happens, rad
    tau_nom: float
    tau_max: float

    @property
    def margin(self) -> float:
        """Share of the peak torque left in the worst pose (negative: overloaded)."""
        return (self.tau_max - self.tau) / self.tau_max

    def to_json(self) -> dict:
        """The torque report's per-joint record (docs/conventions.md), rounded so that reports are stable."""
        return {"name": self.name, "unit": self.variant, "tau_gravity_max": round(self.tau, 6), "tau_nom": self.tau_nom,
                "tau_max": self.tau_max, "margin": round(self.margin, 6),
                "pose": [round(float(np.degrees(x)), 1) + 0.0 for x in self.q], "status": self.level}

    @property
    def level(self) -> str:
        return "over-peak" if self.tau > self.tau_max else "over-nominal" if self.tau > self.tau_nom else "ok"


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


def worst_case(dyn: Dynamics, samples: int = 512, refine: int = 4, seed: int = 0) -> list[JointWorst]:
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


def analyse(robot: ResolvedRobot, payload_mass: float | None = None) -> list[JointWorst]:
    """The worst case for a checked robot; payload_mass (kg) replaces the file's payload mass,
    keeping its centre of mass (tool0's origin if the file has none). Cached by content."""
    payload: PayloadOverride | None = None
    if payload_mass is not None:
        com = robot.payload.com if robot.payload is not None else (0.0, 0.0, 0.0)
        payload = (payload_mass, com)
    key = _key(robot, payload)
    hit = cache.get("torque", key)
    if hit is not None:
        return [JointWorst(j[0], j[1], j[2], tuple(j[3]), j[4], j[5]) for j in json.loads(hit)]
    result = worst_case(Dynamics(robot, payload))
    cache.put("torque", key, json.dumps([[j.name, j.variant, j.tau, list(j.q), j.tau_nom, j.tau_max]
                                         for j in result]).encode())
    return result


def _key(robot: ResolvedRobot, payload: PayloadOverride | None) -> str:
    """Everything worst_case() reads: the described arm, gravity, the actuators, the defaults."""
    from ..physical.assembly import describe

    lib = robot.library
    actuators = [(u.name, lib.variants[u.variant].actuator.torque_nominal, lib.variants[u.variant].actuator.torque_peak)
                 for u in robot.units]
    defaults = worst_case.__defaults__
    return cache.key(ALGORITHM, describe(with_payload(robot, payload)).fingerprint(), gravity(robot).tobytes(),
                     repr(actuators), repr(defaults)) + ".json"
