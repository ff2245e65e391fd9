"""A pinocchio model of a checked robot, built from the URDF modc emits (so that what is
analysed is exactly what users load). SI units; gravity in base_link follows the base placement.

    dyn = Dynamics(robot)
    dyn.rnea(q, v, a)        # inverse dynamics: joint torques, N·m
    dyn.gravity(q)           # static gravity torques g(q)
    dyn.mass_matrix(q)       # M(q), symmetric
"""
from __future__ import annotations

import numpy as np

from ..kinematics import rpy_matrix
from ..model import Robot

G_WORLD = np.array([0.0, 0.0, -9.81])


def urdf_for(robot: Robot, payload: tuple[float, tuple[float, float, float]] | None = None) -> str:
    from ..backends import Build
    from ..backends.urdf import urdf_text
    from ..model import Design, Payload

    if payload is not None:
        robot = robot.model_copy(update={"payload": Payload(mass=payload[0], com=payload[1])})
    design = Design(path="<dynamics>", robots=(robot,))
    return urdf_text(Build(design), robot, mesh_prefix="")


class Dynamics:
    def __init__(self, robot: Robot, payload: tuple[float, tuple[float, float, float]] | None = None):
        import pinocchio as pin

        self.pin = pin
        self.robot = robot
        self.model = pin.buildModelFromXML(urdf_for(robot, payload))
        # base_link may be mounted tilted (`base … rpy`): gravity as seen in base_link
        self.model.gravity.linear = rpy_matrix(robot.base.rpy).T @ G_WORLD
        self.data = self.model.createData()
        self.nq = self.model.nq
        self.lower = np.array(self.model.lowerPositionLimit)
        self.upper = np.array(self.model.upperPositionLimit)

    def rnea(self, q, v, a) -> np.ndarray:
        return np.array(self.pin.rnea(self.model, self.data, np.asarray(q, float), np.asarray(v, float), np.asarray(a, float)))

    def gravity(self, q) -> np.ndarray:
        return np.array(self.pin.computeGeneralizedGravity(self.model, self.data, np.asarray(q, float)))

    def gravity_derivatives(self, q) -> np.ndarray:
        return np.array(self.pin.computeGeneralizedGravityDerivatives(self.model, self.data, np.asarray(q, float)))

    def mass_matrix(self, q) -> np.ndarray:
        M = np.array(self.pin.crba(self.model, self.data, np.asarray(q, float)))
        return np.triu(M) + np.triu(M, 1).T  # crba fills the upper triangle
