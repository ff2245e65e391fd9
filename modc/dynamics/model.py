"""A pinocchio model of a checked robot, built in memory from the same Description the URDF
backend renders (modc.physical.multibody; tests/test_multibody.py checks it equals pinocchio's
reading of the emitted URDF). SI units; gravity in base_link follows the base placement.

    dyn = Dynamics(robot)
    dyn.rnea(q, v, a)        # inverse dynamics: joint torques, N·m
    dyn.gravity(q)           # static gravity torques g(q)
    dyn.mass_matrix(q)       # M(q), symmetric
"""
from __future__ import annotations

import numpy as np

from ..diagnostics.span import NOWHERE
from ..model import Payload, ResolvedRobot
from ..physical.multibody import gravity

PayloadOverride = tuple[float, tuple[float, float, float]]  # (kg, centre of mass in tool0, m)


def with_payload(robot: ResolvedRobot, payload: PayloadOverride | None) -> ResolvedRobot:
    """The robot carrying another payload (None: the file's own)."""
    if payload is None:
        return robot
    span = robot.payload.span if robot.payload is not None else NOWHERE
    return robot.model_copy(update={"payload": Payload(mass=payload[0], com=payload[1], span=span)})


class Dynamics:
    def __init__(self, robot: ResolvedRobot, payload: PayloadOverride | None = None):
        import pinocchio as pin

        from ..physical import multibody
        from ..physical.assembly import describe

        self.pin = pin
        self.robot = robot
        self.model = multibody.model(describe(with_payload(robot, payload)), gravity=gravity(robot))
        self.data = self.model.createData()
        self.nq = self.model.nq
        self.lower = np.array(self.model.lowerPositionLimit)
        self.upper = np.array(self.model.upperPositionLimit)

    def rnea(self, q, v, a) -> np.ndarray:
        q, v, a = (np.asarray(x, float) for x in (q, v, a))
        return np.array(self.pin.rnea(self.model, self.data, q, v, a))

    def gravity(self, q) -> np.ndarray:
        return np.array(self.pin.computeGeneralizedGravity(self.model, self.data, np.asarray(q, float)))

    def gravity_derivatives(self, q) -> np.ndarray:
        return np.array(self.pin.computeGeneralizedGravityDerivatives(self.model, self.data, np.asarray(q, float)))

    def gravities(self, Q) -> np.ndarray:
        """(N, n) g(q) of the poses Q (N, n): Statics.gravities' interface (worst_case runs on either)."""
        return np.array([self.gravity(q) for q in np.atleast_2d(np.asarray(Q, float))])

    def gravity_with_jacobians(self, Q) -> tuple[np.ndarray, np.ndarray]:
        """g(q) (N, n) and dg/dq (N, n, n) of the poses Q."""
        Q = np.atleast_2d(np.asarray(Q, float))
        return self.gravities(Q), np.array([self.gravity_derivatives(q) for q in Q])

    def mass_matrix(self, q) -> np.ndarray:
        M = np.array(self.pin.crba(self.model, self.data, np.asarray(q, float)))
        return np.triu(M) + np.triu(M, 1).T  # crba fills the upper triangle
