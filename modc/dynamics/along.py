"""The dynamic check: joint torques along a trajectory (inverse dynamics, RNEA at every point).

A trajectory from `modc plan` moves at the actuators' rated speeds (trapezoidal profiles within
the URDF velocities), so its peaks say whether the arm can follow it, not just hold itself.
Velocities and accelerations are finite differences of the points (np.gradient on the uneven
time grid); between points the motion is linear in joint space, as `play` interpolates it.
"""
from __future__ import annotations

import numpy as np

from .model import Dynamics
from .torque import JointWorst


class JointPeak(JointWorst, kw_only=False):
    t: float = 0.0  # s: when the peak happens

    def to_json(self) -> dict:
        return {**super().to_json(), "t": round(self.t, 6)}


def torques(dyn: Dynamics, t, Q) -> np.ndarray:
    """(len(t), n) joint torques along the points Q (rad) at times t (s)."""
    t, Q = np.asarray(t, float), np.asarray(Q, float)
    if len(t) < 2:
        return np.array([dyn.gravity(Q[0])])
    V = np.gradient(Q, t, axis=0)
    A = np.gradient(V, t, axis=0)
    return np.array([dyn.rnea(q, v, a) for q, v, a in zip(Q, V, A, strict=True)])


def peaks(dyn: Dynamics, traj) -> list[JointPeak]:
    """Per joint: the largest |torque| along the trajectory, when and where it happens."""
    robot = dyn.robot
    names = [f"joint_{i}" for i in range(1, robot.dof + 1)]
    traj = traj.in_order(names)
    tau = np.abs(torques(dyn, traj.t, traj.q))
    out = []
    lib = robot.library
    for i, name in enumerate(names):
        k = int(np.argmax(tau[:, i]))
        act = lib.variants[robot.units[i].variant].actuator
        out.append(JointPeak(name, robot.units[i].name, float(tau[k, i]), tuple(traj.q[k]), act.torque_nominal,
                             act.torque_peak, t=float(traj.t[k])))
    return out
