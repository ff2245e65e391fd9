"""Static gravity torques of an assembled arm (numpy; no dynamics library needed).

tau_i(q) = -z_i . sum_{bodies j after joint i} (c_j - p_i) x (m_j g): the torque holding the arm still,
g as seen in base_link (multibody.gravity: the base may be tilted); the same convention as pinocchio's g(q).

The reference for gravity torques is pinocchio's g(q) on the multibody model (dynamics.Dynamics
and physical.evaluate.Candidate, both multibody.model with multibody.gravity). This numpy copy is
kept on purpose: DH conversion runs inside `modc lint`, which imports no pinocchio (0.2 s), and
only needs a ranking. tests/test_concepts.py checks that it equals the reference, and that
worst() (random samples, used to choose H or L modules) is a lower bound of the refined search
of dynamics/worst.py that the `check` command and the torque pass report.
"""
from __future__ import annotations

import numpy as np

from ..kinematics import Chain
from ..model import ResolvedRobot
from .assembly import describe
from .multibody import gravity


class Statics:
    def __init__(self, robot: ResolvedRobot):
        self.robot = robot
        self.chain = Chain(robot)
        self.g = gravity(robot)
        desc = describe(robot)
        by_name = {link.name: link for link in desc.links}
        # bodies rigid with link_i (i = 1..n), payload folded into link_n at its tool0 offset
        self.masses = []
        self.coms = []  # in the link (joint) frame
        n = robot.dof
        for i in range(1, n + 1):
            inert = by_name[f"link_{i}"].inertial
            assert inert is not None
            m, c = inert.mass, inert.com
            if i == n and robot.payload is not None:
                T = self.chain.T_last_tool()
                pc = T[:3, :3] @ np.array(robot.payload.com) + T[:3, 3]
                m, c = m + robot.payload.mass, (m * c + robot.payload.mass * pc) / (m + robot.payload.mass)
            self.masses.append(m)
            self.coms.append(np.asarray(c))

    def torques(self, q) -> np.ndarray:
        frames = self.chain.frames(q)
        n = len(frames)
        P = np.array([f["T_base_joint"][:3, 3] for f in frames])
        Z = np.array([f["T_base_joint"][:3, 2] for f in frames])
        C = np.array([f["T_base_joint"][:3, :3] @ c + f["T_base_joint"][:3, 3]
                      for f, c in zip(frames, self.coms, strict=True)])
        M = np.array(self.masses)
        tau = np.empty(n)
        for i in range(n):
            F = (M[i:, None] * (C[i:] - P[i])).sum(axis=0)
            tau[i] = -(Z[i] @ np.cross(F, self.g))  # the torque that holds the arm against gravity (pinocchio's g(q))
        return tau

    def worst(self, samples: int = 256, seed: int = 0) -> np.ndarray:
        """max_q |tau_i(q)| over random poses within the joint ranges (a lower bound of the true max)."""
        rng = np.random.default_rng(seed)
        lo, hi = np.array([self.robot.joint_range(i + 1) for i in range(self.robot.dof)]).T
        best = np.zeros(self.robot.dof)
        for q in rng.uniform(lo, hi, size=(samples, self.robot.dof)):
            best = np.maximum(best, np.abs(self.torques(q)))
        return best


__all__ = ["Statics"]
