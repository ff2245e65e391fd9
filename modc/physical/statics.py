"""Static gravity torques of an assembled arm and their derivatives (numpy; no dynamics library).

tau_i(q) = -z_i . (r_i x g), r_i = sum_{bodies b carried by joint i} m_b (c_b - p_i): the torque holding
the arm still, g as seen in base_link (multibody.gravity: the base may be tilted); the bodies are the
Description's inertials, every one of them, as the pinocchio model has them (multibody.model), so
this is pinocchio's g(q) (computeGeneralizedGravity) and dg/dq (computeGeneralizedGravityDerivatives)
to rounding. Turning joint k moves what it carries about z_k through p_k, hence
    d tau_i / d q_k = -[(z_k x z_i) . (r_i x g) + z_i . ((z_k x r_i) x g)]   k carries i (k = i too)
    d tau_i / d q_k = -z_i . ((z_k x r_k) x g)                              i carries k (k != i)
and 0 otherwise. Everything is batched over poses (N, ...): one call serves many poses at once.

pinocchio stays the reference (dynamics.Dynamics); tests/test_concepts.py and tests/test_startup_compile.py
check this copy against it. It is kept because `modc lint` (DH conversion's ranking) imports no
pinocchio, and because the worst-case torque search of a compile (dynamics/worst.py) runs on it: a
first compile then imports no pinocchio for the torques (~0.06 s).
"""
from __future__ import annotations

import numpy as np

from ..model import ResolvedRobot
from .assembly import Description, describe
from .multibody import gravity, link_frames


class Statics:
    def __init__(self, robot: ResolvedRobot, desc: Description | None = None):
        """desc: the arm's Description (default describe(robot); another payload: describe that robot)."""
        self.robot = robot
        self.g = gravity(robot)
        desc = describe(robot) if desc is None else desc
        placed = link_frames(desc)  # link -> (joint carrying it, placement in that joint's frame)
        parents, M, lower, upper = [-1], [np.eye(4)], [], []
        for j in desc.joints:
            if j.kind == "revolute":
                assert j.limits is not None
                parent, T = placed[j.parent]
                parents.append(parent)
                M.append(T @ j.T_parent_child)
                lower.append(j.limits.lower)
                upper.append(j.limits.upper)
        self.nq = len(parents) - 1
        self.parents = parents
        self.M = np.array(M)  # (nj, 4, 4): joint j's frame at q = 0 in its parent joint's frame
        self.lower, self.upper = np.array(lower, float), np.array(upper, float)
        # the bodies on each joint, summed: mass m_j and first moment h_j = sum m_b c_b (joint frame)
        n = self.nq
        self.m_joint, self.h_joint = np.zeros(n), np.zeros((n, 3))
        for link in desc.links:
            joint, T = placed[link.name]
            if link.inertial is not None and joint > 0:  # base_link's own mass holds no joint
                m = link.inertial.mass
                self.m_joint[joint - 1] += m
                self.h_joint[joint - 1] += m * (T[:3, :3] @ np.asarray(link.inertial.com, float) + T[:3, 3])
        # carries[i, j]: joint i + 1 carries joint j + 1 (itself included)
        carries = np.zeros((n, n), bool)
        for k in range(1, n + 1):
            a = k
            while a > 0:
                carries[a - 1, k - 1] = True
                a = parents[a]
        self._carries = carries.astype(float)
        self._m_carried = self._carries @ self.m_joint  # (n,): the mass joint i holds
        self._k_carries_i = carries.T.astype(float)[None]  # [i, k]: joint k carries joint i (k = i too)
        self._i_carries_k = (carries & ~np.eye(n, dtype=bool)).astype(float)[None]  # [i, k]: i carries k, k != i
        gx, gy, gz = self.g
        self._g_cross = np.array([[0.0, -gz, gy], [gz, 0.0, -gx], [-gy, gx, 0.0]])  # v @ this = v x g
        # M_j @ Rz(q) = cos q (M_j C) + sin q (M_j S) + M_j Z: joint j's frame turned by q, in its parent's
        C, S, Z = np.diag([1.0, 1.0, 0.0]), np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]]), np.diag(
            [0.0, 0.0, 1.0])
        R = self.M[:, :3, :3]
        self._MC, self._MS, self._MZ = R @ C, R @ S, R @ Z

    def _frames(self, Q: np.ndarray) -> tuple[list[np.ndarray], list[np.ndarray]]:
        """Per joint 1..n: its frame's rotation (N, 3, 3) and origin (N, 3) in base_link."""
        c, s = np.cos(Q)[:, :, None, None], np.sin(Q)[:, :, None, None]
        turned = c * self._MC[None, 1:] + s * self._MS[None, 1:] + self._MZ[None, 1:]  # (N, n, 3, 3)
        Rs: list[np.ndarray] = []
        ps: list[np.ndarray] = []
        for j in range(1, self.nq + 1):
            par = self.parents[j]
            if par == 0:  # on base_link
                Rs.append(turned[:, j - 1])
                ps.append(np.broadcast_to(self.M[j, :3, 3], (Q.shape[0], 3)))
            else:
                Rs.append(Rs[par - 1] @ turned[:, j - 1])
                ps.append(Rs[par - 1] @ self.M[j, :3, 3] + ps[par - 1])
        return Rs, ps

    def _moments(self, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Joint axes z_i and r_i = sum m_b (c_b - p_i) over the bodies joint i carries, (N, n, 3) each."""
        Rs, ps = self._frames(Q)
        R, p = np.stack(Rs, axis=1), np.stack(ps, axis=1)  # (N, n, 3, 3), (N, n, 3)
        first = (R @ self.h_joint[:, :, None])[..., 0] + self.m_joint[:, None] * p  # sum m_b c_b per joint
        r = self._carries @ first - self._m_carried[:, None] * p
        return R[:, :, :, 2], r

    def gravities(self, Q) -> np.ndarray:
        """(N, n) holding torques g(q) of the poses Q (N, n), N·m."""
        z, r = self._moments(np.atleast_2d(np.asarray(Q, float)))
        return -(z * (r @ self._g_cross)).sum(axis=-1)

    def gravity_with_jacobians(self, Q) -> tuple[np.ndarray, np.ndarray]:
        """g(q) (N, n) and dg/dq (N, n, n) of the poses Q: [k, i, j] = d tau_i / d q_j at pose k."""
        z, r = self._moments(np.atleast_2d(np.asarray(Q, float)))
        rxg = r @ self._g_cross  # r_i x g
        tau = -(z * rxg).sum(axis=-1)
        # (z_k x z_i).(r_i x g) + z_i.((z_k x r_i) x g) = z_k.(z_i x (r_i x g) + r_i x (g x z_i)), by triple products
        upper = -np.einsum("nkd,nid->nik", z, _cross(z, rxg) + _cross(r, -(z @ self._g_cross)))
        lower = -np.einsum("nid,nkd->nik", z, _cross(z, r) @ self._g_cross)  # z_i.((z_k x r_k) x g)
        return tau, self._k_carries_i * upper + self._i_carries_k * lower

    def torques(self, q) -> np.ndarray:
        return self.gravities(q)[0]

    def worst(self, samples: int = 256, seed: int = 0) -> np.ndarray:
        """max_q |tau_i(q)| over random poses within the joint ranges (a lower bound of the true max)."""
        rng = np.random.default_rng(seed)
        lo, hi = np.array([self.robot.joint_range(i + 1) for i in range(self.robot.dof)]).T
        return np.abs(self.gravities(rng.uniform(lo, hi, size=(samples, self.robot.dof)))).max(axis=0)


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a x b over the last axis (np.cross costs ~20 us a call in axis handling, np.stack ~10: the
    search makes hundreds)."""
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    out = np.empty(np.broadcast_shapes(a.shape, b.shape))
    out[..., 0] = a1 * b2 - a2 * b1
    out[..., 1] = a2 * b0 - a0 * b2
    out[..., 2] = a0 * b1 - a1 * b0
    return out


__all__ = ["Statics"]
