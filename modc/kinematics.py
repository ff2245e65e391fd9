"""The paper's modular kinematics (section 3.1; docs/conventions.md), in numpy.

Per unit i, with the library's constants (x01, z01, z12, x23) and the unit's twists:

    A_t1(pivot) = [Ry(pivot) | (x01, 0, z01)]     unit base -> twist1           (paper eq. 4)
    A_J(theta)  = [Rz(theta) | (0, 0, z12)]       twist1    -> joint (axis z)   (paper eq. 5)
    A_t2(port)  = [Rx(port)  | (x23, 0, 0)]       joint     -> twist2, units 3/4 (paper eq. 6)

    T_base_tool(q) = prod_i A_t1 . A_J . A_t2  (eq. 3), then the tool offset.

This is not DH of either kind: each unit has three frames. Names read T_<from>_<to>.
"""
from __future__ import annotations

import numpy as np

from .model import ResolvedRobot
from .records import Record
from .rotation import Rx, Ry, Rz, matrix_rpy, rpy_matrix  # noqa: F401 (used here and re-exported)


def homogeneous(R: np.ndarray, p) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = p
    return T


def A_t1(pivot: float, x01: float, z01: float) -> np.ndarray:
    """Paper eq. (4): unit base frame -> twist1 frame."""
    return homogeneous(Ry(pivot), (x01, 0.0, z01))


def A_J(theta: float, z12: float) -> np.ndarray:
    """Paper eq. (5): twist1 frame -> joint frame; the joint turns about this frame's z."""
    return homogeneous(Rz(theta), (0.0, 0.0, z12))


def A_t2(port: float, x23: float) -> np.ndarray:
    """Paper eq. (6): joint frame -> twist2 frame at the end of the link module."""
    return homogeneous(Rx(port), (x23, 0.0, 0.0))


def transform(xyz, rpy) -> np.ndarray:
    return homogeneous(rpy_matrix(rpy), xyz)


def rotation_vector(R: np.ndarray) -> np.ndarray:
    """Axis times angle (log map) of rotation matrices (..., 3, 3) -> (..., 3), accurate up to 180°.

    The home of "how far is one orientation from another" (plan/ik.py calls it at every IK step);
    design/batch.py (rotation_error) keeps a batched copy for the design search, which
    tests/test_concepts.py checks equal to this one."""
    R = np.asarray(R, float)
    if R.ndim == 2:
        return _rotation_vector_one(R)
    v = 0.5 * np.stack([R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0], R[..., 1, 0] - R[..., 0, 1]], -1)
    cos = np.clip((np.trace(R, axis1=-2, axis2=-1) - 1.0) / 2.0, -1.0, 1.0)
    angle = np.arccos(cos)
    sin = np.linalg.norm(v, axis=-1)
    out = v * np.where(sin > 1e-9, angle / np.maximum(sin, 1e-12), 1.0)[..., None]  # near identity: v itself
    # near 180° the skew part vanishes: the axis comes from the symmetric part
    near_pi = (cos < -0.999) & (sin < 1e-3)
    if np.any(near_pi):
        B = (R[near_pi] + np.eye(3)) / 2.0
        k = np.argmax(np.diagonal(B, axis1=-2, axis2=-1), axis=-1)
        axis = B[np.arange(len(k)), :, k]
        out[near_pi] = axis / np.linalg.norm(axis, axis=-1, keepdims=True) * angle[near_pi][:, None]
    return out


def _rotation_vector_one(R: np.ndarray) -> np.ndarray:
    """rotation_vector of one matrix, the same rules in scalar arithmetic: the IK calls it at
    every step, where numpy's per-call cost of the batched form (~2.5x) is the whole cost."""
    import math

    v = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]]) * 0.5
    cos = min(1.0, max(-1.0, (R[0, 0] + R[1, 1] + R[2, 2] - 1.0) / 2.0))
    angle = math.acos(cos)
    sin = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    if cos < -0.999 and sin < 1e-3:  # near 180° the skew part vanishes: the axis from the symmetric part
        B = (R + np.eye(3)) / 2.0
        axis = B[:, int(np.argmax(np.diagonal(B)))]
        return axis / np.linalg.norm(axis) * angle
    return v * (angle / max(sin, 1e-12)) if sin > 1e-9 else v  # near identity: v itself


def rotation_error(R_target: np.ndarray, R: np.ndarray) -> np.ndarray:
    """The turn (rotation vector, in base_link axes) that brings R onto R_target; its norm is the
    angle between the two orientations, rad."""
    return rotation_vector(np.asarray(R_target, float) @ np.swapaxes(np.asarray(R, float), -1, -2))


def target_errors(target, T_base_tool: np.ndarray) -> tuple[float, float | None]:
    """(m, rad) from tool0's pose to a target (modc.model.Target): the position error and, if the
    target asks for an orientation, the angle to it - the whole frame's for `rpy`, tool0's x axis
    against the direction for `pointing`; None when it asks for none. Compare with
    `target.tolerance`: the one test of "reached"."""
    T = np.asarray(T_base_tool, float)
    position = float(np.linalg.norm(T[:3, 3] - np.asarray(target.xyz, float)))
    if target.rpy is not None:
        return position, float(np.linalg.norm(rotation_error(rpy_matrix(target.rpy), T[:3, :3])))
    if target.pointing is not None:
        x, d = T[:3, 0], np.asarray(target.pointing, float)
        return position, float(np.arctan2(np.linalg.norm(np.cross(x, d)), x @ d))
    return position, None


class UnitGeometry(Record, kw_only=False):
    """The numbers eqs. (4)-(6) need for one unit, resolved from the library."""

    x01: float
    z01: float
    z12: float
    x23: float  # 0 for units without a link module
    pivot: float
    port: float
    has_link: bool


def unit_geometry(robot: ResolvedRobot) -> list[UnitGeometry]:
    lib = robot.library
    out = []
    for u in robot.units:
        t = lib.units[u.kind]
        out.append(UnitGeometry(t.x01, t.z01, t.z12, robot.link_length(u), u.pivot, u.port if t.link else 0.0, t.link))
    return out


class Chain:
    """Forward kinematics of a checked robot, frame by frame."""

    def __init__(self, robot: ResolvedRobot):
        self.units = unit_geometry(robot)
        self.T_flange_tool = transform(robot.tool.xyz, robot.tool.rpy)
        self.dof = len(self.units)

    def T_joint_end(self, i: int) -> np.ndarray:
        """Joint frame of unit i -> its last frame (twist2 for units 3/4, itself for 1/2)."""
        u = self.units[i]
        return A_t2(u.port, u.x23) if u.has_link else np.eye(4)

    def T_last_tool(self) -> np.ndarray:
        """Last joint frame -> tool0."""
        return self.T_joint_end(self.dof - 1) @ self.T_flange_tool

    def frames(self, q) -> list[dict[str, np.ndarray]]:
        """Per unit: T_base_unit, T_base_twist1, T_base_joint, T_base_end (all in base_link)."""
        q = np.asarray(q, dtype=float)
        if q.shape != (self.dof,):
            raise ValueError(f"expected {self.dof} joint values, got {q.shape}")
        T = np.eye(4)
        out = []
        for u, qi in zip(self.units, q, strict=True):
            f = {"T_base_unit": T}
            f["T_base_twist1"] = T @ A_t1(u.pivot, u.x01, u.z01)
            f["T_base_joint"] = f["T_base_twist1"] @ A_J(qi, u.z12)
            T = f["T_base_joint"] @ A_t2(u.port, u.x23) if u.has_link else f["T_base_joint"]
            f["T_base_end"] = T
            out.append(f)
        return out

    def T_base_flange(self, q) -> np.ndarray:
        """Eq. (3): the product of all units' matrices."""
        return self.frames(q)[-1]["T_base_end"] if self.dof else np.eye(4)

    def T_base_tool(self, q) -> np.ndarray:
        return self.T_base_flange(q) @ self.T_flange_tool

    def joint_axes(self, q=None) -> list[tuple[np.ndarray, np.ndarray]]:
        """(point, unit direction) of every joint axis in base_link."""
        q = np.zeros(self.dof) if q is None else q
        return [(f["T_base_joint"][:3, 3].copy(), f["T_base_joint"][:3, 2].copy()) for f in self.frames(q)]
