"""The paper's kinematics (docs/conventions.md) for many candidate chains and many joint vectors at once (numpy).

Per unit, A_t1(pivot) . A_J(theta) . A_t2(port) = PRE . Rz(theta) . POST with PRE = A_t1 . Tz(z12)
and POST = A_t2 (identity for units 1/2), so one forward pass is two fixed 4x4 products and a
rotation about z per unit. Arrays carry a leading batch shape (candidates, targets, seeds); the
fixed parts broadcast over the last two. This is what the search evaluates by the thousand;
modc.kinematics.Chain stays the reference (tests compare the two).
"""
from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from ..kinematics import transform


@dataclass(frozen=True)
class Geometry:
    """Fixed transforms of C candidates of one skeleton."""

    pre: np.ndarray  # (C, n, 4, 4): A_t1(pivot) . Tz(z12)
    post: np.ndarray  # (C, n, 4, 4): A_t2(port, link) or identity
    t1: np.ndarray  # (n, 3): the twist1 origin in the unit's base frame, (x01, 0, z01)
    flange_tool: np.ndarray  # (4, 4)

    @property
    def dof(self) -> int:
        return self.pre.shape[1]

    @functools.cached_property
    def joints(self) -> np.ndarray:
        """K_0 = PRE_1, K_i = POST_i . PRE_(i+1), K_n = POST_n . tool (C, n+1, 4, 4): the transform
        from one joint's rotation to the next. Computed once per geometry and carried by take(),
        so the IK calls of one screen (a target and a seed at a time) share them."""
        C, n = self.pre.shape[:2]
        K = np.empty((C, n + 1, 4, 4))
        K[:, 0] = self.pre[:, 0]
        K[:, 1:n] = self.post[:, :-1] @ self.pre[:, 1:]
        K[:, n] = self.post[:, -1] @ self.flange_tool
        return K

    def take(self, idx) -> Geometry:
        """The candidates idx (with their joint transforms, when computed)."""
        out = Geometry(self.pre[idx], self.post[idx], self.t1, self.flange_tool)
        if "joints" in self.__dict__:
            out.__dict__["joints"] = self.__dict__["joints"][idx]
        return out


def geometry(units, pivots: np.ndarray, ports: np.ndarray, links, tool_xyz, tool_rpy) -> Geometry:
    """units: the library's UnitType per position; pivots, ports: (C, n) rad; links: m per position."""
    C, n = pivots.shape
    pre_R, pre_t, post_R, post_t = pre_post(units, np.asarray(pivots, float), np.asarray(ports, float), links)
    pre = np.zeros((C, n, 4, 4))
    post = np.zeros((C, n, 4, 4))
    pre[..., :3, :3], pre[..., :3, 3], pre[..., 3, 3] = pre_R, pre_t, 1.0
    post[..., :3, :3], post[..., :3, 3], post[..., 3, 3] = post_R, post_t, 1.0
    t1 = np.array([(t.x01, 0.0, t.z01) for t in units], dtype=float).reshape(n, 3)
    return Geometry(pre, post, t1, transform(tool_xyz, tool_rpy))


def _ry(a: np.ndarray) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    z, o = np.zeros_like(a), np.ones_like(a)
    return np.stack([np.stack([c, z, s], -1), np.stack([z, o, z], -1), np.stack([-s, z, c], -1)], -2)


def _rx(a: np.ndarray) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    z, o = np.zeros_like(a), np.ones_like(a)
    return np.stack([np.stack([o, z, z], -1), np.stack([z, c, -s], -1), np.stack([z, s, c], -1)], -2)


def pre_post(units, pivots: np.ndarray, ports: np.ndarray, links) -> tuple[np.ndarray, ...]:
    """PRE_i = A_t1(pivot) . Tz(z12) and POST_i = A_t2(port, link) of C settings at once:
    rotations (C, n, 3, 3) and translations (C, n, 3). Units 1/2 have port 0 and no link, for
    which A_t2 is the identity."""
    x01 = np.array([u.x01 for u in units], float)
    z01 = np.array([u.z01 for u in units], float)
    z12 = np.array([u.z12 for u in units], float)
    x23 = np.array([x if u.link else 0.0 for u, x in zip(units, links, strict=True)], float)
    pre_R = _ry(pivots)
    pre_t = np.stack([x01 + np.sin(pivots) * z12, np.zeros_like(pivots), z01 + np.cos(pivots) * z12], -1)
    post_R = _rx(ports)
    post_t = np.broadcast_to(np.stack([x23, np.zeros_like(x23), np.zeros_like(x23)], -1), pre_t.shape)
    return pre_R, pre_t, post_R, post_t


def forward(g: Geometry, q: np.ndarray, points: bool = False):
    """q (C, T, S, n) -> joint origins p and axes z (C, T, S, n, 3), T_base_tool (C, T, S, 4, 4) and,
    with points, each unit's frame origins (base, twist1, joint, end) as (C, T, S, n, 4, 3)."""
    C, T, S, n = q.shape
    M = np.broadcast_to(np.eye(4), (C, T, S, 4, 4)).copy()
    p = np.empty((C, T, S, n, 3))
    z = np.empty((C, T, S, n, 3))
    pts = np.empty((C, T, S, n, 4, 3)) if points else None
    c, s = np.cos(q), np.sin(q)
    for i in range(n):
        if pts is not None:
            pts[..., i, 0, :] = M[..., :3, 3]
            pts[..., i, 1, :] = M[..., :3, 3] + M[..., :3, :3] @ g.t1[i]
        M = M @ g.pre[:, i][:, None, None]
        ci, si = c[..., i, None], s[..., i, None]
        x, y = M[..., :3, 0].copy(), M[..., :3, 1].copy()
        M[..., :3, 0] = ci * x + si * y
        M[..., :3, 1] = ci * y - si * x
        p[..., i, :] = M[..., :3, 3]
        z[..., i, :] = M[..., :3, 2]
        M = M @ g.post[:, i][:, None, None]
        if pts is not None:
            pts[..., i, 2, :] = p[..., i, :]
            pts[..., i, 3, :] = M[..., :3, 3]
    return p, z, M @ g.flange_tool, pts


@dataclass
class Flat:
    """Fixed transforms per run, structure of arrays (run index last, so every product is a few
    long vector operations): K_0 = PRE_1, K_i = POST_i . PRE_(i+1), K_n = POST_n . tool - the
    transform from one joint's rotation to the next, one product per joint -, rotations
    (n+1, 3, 3, B), translations (n+1, 3, B)."""

    k_R: np.ndarray
    k_t: np.ndarray

    @classmethod
    def of(cls, g: Geometry, c_idx: np.ndarray) -> Flat:
        Kc = g.joints[c_idx]
        return cls(np.ascontiguousarray(np.moveaxis(Kc[:, :, :3, :3], 0, -1)),
                   np.ascontiguousarray(np.moveaxis(Kc[:, :, :3, 3], 0, -1)))

    def take(self, keep: np.ndarray) -> Flat:
        return Flat(self.k_R[..., keep], self.k_t[..., keep])


def _rot(R, P):
    """R . P for stacks (3, 3, B) of rotations (einsum: several times faster here than broadcast
    products, which stream (3, 3, B) temporaries)."""
    return np.einsum("ijb,jkb->ikb", R, P)


def _apply(R, v):
    """R . v for (3, 3, B) and (3, B)."""
    return np.einsum("ijb,jb->ib", R, v)


def _rz_vec(c, s, v):
    """Rz(theta) . v for (3, B) or, row by row, (3, 3, B): two rows mixed (written into one
    array: a stack costs more than the arithmetic at a few hundred runs)."""
    out = np.empty(v.shape)
    np.subtract(c * v[0], s * v[1], out=out[0])
    np.add(s * v[0], c * v[1], out=out[1])
    out[2] = v[2]
    return out


def _rz_times(c, s, K_R, k_t):
    """Rz(theta) . K for a rotation stack (3, 3, B) and a translation (3, B)."""
    return _rz_vec(c, s, K_R), _rz_vec(c, s, k_t)


def _turn(R, c, s):
    """R . Rz(theta) for (3, 3, B): two columns mixed."""
    out = np.empty(R.shape)
    x, y = R[:, 0], R[:, 1]
    np.add(c * x, s * y, out=out[:, 0])
    np.subtract(c * y, s * x, out=out[:, 1])
    out[:, 2] = R[:, 2]
    return out


def forward_flat(f: Flat, q: np.ndarray, rotation: bool = True, local: bool = False):
    """One run per column: q (n, B) -> joint origins and axes (n, 3, B), tool0's rotation (3, 3, B)
    and position (3, B). Without rotation (a position-only solve) tool0's rotation is None and
    the last joint costs three matrix-vector products, not a 3x3 product.

    local: in joint 1's frame before its rotation (K_0 left out: joint 1 turns about z through
    the origin), where the first products are Rz(q_1) . K_1 - two rows mixed, not a 3x3 product;
    a caller that moves its targets into that frame gets the same distances."""
    n, B = q.shape
    p = np.empty((n, 3, B))
    z = np.empty((n, 3, B))
    c, s = np.cos(q), np.sin(q)
    if local:
        p[0], z[0, :2], z[0, 2] = 0.0, 0.0, 1.0
        R, t = _rz_times(c[0], s[0], f.k_R[1], f.k_t[1])
        if n == 1:
            return p, z, R if rotation else None, t
        first = 1
    else:
        R, t = f.k_R[0], f.k_t[0]  # base_link is the identity: K_0 needs no product
        first = 0
    for i in range(first, n):
        if i > first:
            t = t + _apply(R, f.k_t[i])
            if i == n - 1 and not rotation:
                # tool0 = t + R . K_i . Rz(q_i) . t(K_n)
                p[i], z[i] = t, _apply(R, f.k_R[i][:, 2])
                return p, z, None, t + _apply(R, _apply(f.k_R[i], _rz_vec(c[i], s[i], f.k_t[n])))
            R = _rot(R, f.k_R[i])
        elif i == n - 1 and not rotation:
            p[i], z[i] = t, R[:, 2]
            return p, z, None, t + _apply(R, _rz_vec(c[i], s[i], f.k_t[n]))
        R = _turn(R, c[i], s[i])
        p[i] = t
        z[i] = R[:, 2]
    return p, z, _rot(R, f.k_R[n]) if rotation else None, t + _apply(R, f.k_t[n])


def rotation_error(R_target: np.ndarray, R: np.ndarray) -> np.ndarray:
    """Rotation vector (..., 3) of R_target . R^T: the turn (in base_link axes) that brings R onto R_target."""
    E = R_target @ np.swapaxes(R, -1, -2)
    v = 0.5 * np.stack([E[..., 2, 1] - E[..., 1, 2], E[..., 0, 2] - E[..., 2, 0], E[..., 1, 0] - E[..., 0, 1]], -1)
    cos = np.clip((np.trace(E, axis1=-2, axis2=-1) - 1.0) / 2.0, -1.0, 1.0)
    angle = np.arccos(cos)
    sin = np.linalg.norm(v, axis=-1)
    scale = np.where(sin > 1e-9, angle / np.maximum(sin, 1e-12), 1.0)
    out = v * scale[..., None]
    # at 180° the skew part vanishes: take the axis from the symmetric part
    near_pi = (cos < -0.999) & (sin < 1e-3)
    if np.any(near_pi):
        B = (E[near_pi] + np.eye(3)) / 2.0
        k = np.argmax(np.diagonal(B, axis1=-2, axis2=-1), axis=-1)
        axis = B[np.arange(len(k)), :, k]
        axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
        out[near_pi] = axis * angle[near_pi][:, None]
    return out
