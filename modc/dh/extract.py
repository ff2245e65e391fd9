"""The realised standard DH table of a chain, read off its joint axes (paper section 4.2; docs/language.md).

Standard DH (Rz(theta) Tz(d) Tx(a) Rx(alpha)); row i relates axis i to axis i+1, and the last
row relates axis n to the tool0 z axis. a is the length of the common normal, alpha the angle
between the axes about it. Where DH leaves a choice, the usual conventions apply:
  * intersecting axes: x_i = ±(z_i x z_i+1), the sign following `prefer` (the requested
    table) so that alpha keeps the requested sign; otherwise alpha >= 0;
  * parallel axes: the common normal through the previous frame's origin (d_i = 0), except in
    the last row, where it runs through the tool0 origin so that d_n reaches the tool;
  * frame 0: on axis 1, level with base_link's origin, x along base_link's x.
"""
from __future__ import annotations

import itertools

import numpy as np

from ..kinematics import Chain
from ..records import Record

EPS = 1e-9


class Row(Record, kw_only=False):
    a: float
    alpha: float
    d: float
    theta: float


def _cross(a, b) -> np.ndarray:
    # np.cross costs ~10 µs of overhead per call on 3-vectors; this is the whole DH extraction
    return np.array((a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]))


def _project(p, point, u):
    return point + ((p - point) @ u) * u


def _feet(p1, u, p2, v):
    """Closest points of two non-parallel lines."""
    w = _cross(u, v)
    ww = w @ w
    dp = p2 - p1
    t = _cross(dp, v) @ w / ww
    s = _cross(dp, u) @ w / ww
    return p1 + t * u, p2 + s * v, w / np.sqrt(ww)


def realised_dh(chain: Chain, q=None, prefer: list[float] | None = None) -> list[Row]:
    q = np.zeros(chain.dof) if q is None else np.asarray(q, float)
    frames = chain.frames(q)
    T_tool = chain.T_base_tool(q)
    lines = [(f["T_base_joint"][:3, 3], f["T_base_joint"][:3, 2]) for f in frames]
    lines.append((T_tool[:3, 3], T_tool[:3, 2]))
    n = chain.dof

    p1, z1 = lines[0]
    origin = _project(np.zeros(3), p1, z1)
    x = np.array([1.0, 0.0, 0.0]) - z1[0] * z1
    if np.linalg.norm(x) < 1e-6:
        x = np.array([0.0, 1.0, 0.0]) - z1[1] * z1
    x /= np.linalg.norm(x)

    rows = []
    for i in range(n):
        (pa, za), (pb, zb) = lines[i], lines[i + 1]
        last = i == n - 1
        if np.linalg.norm(_cross(za, zb)) > EPS:
            fa, fb, w = _feet(pa, za, pb, zb)
            a = float(np.linalg.norm(fb - fa))
            if a > EPS:
                x_new = (fb - fa) / a
            else:
                x_new = w
                if prefer is not None and prefer[i] < 0:
                    x_new = -w
                a = 0.0
        else:
            if last:
                fb = pb
                fa = _project(pb, pa, za)
            else:
                fa = _project(origin, pa, za)
                fb = _project(fa, pb, zb)
            a = float(np.linalg.norm(fb - fa))
            x_new = (fb - fa) / a if a > EPS else x
            a = a if a > EPS else 0.0
        d = float((fa - origin) @ za)
        theta = float(np.arctan2(_cross(x, x_new) @ za, x @ x_new))
        alpha = float(np.arctan2(_cross(za, zb) @ x_new, za @ zb))
        rows.append(Row(a, alpha, d, theta))
        origin, x = fb, x_new
    return rows


def axis_angles(chain: Chain, q=None) -> list[float]:
    """Angle between consecutive joint axes (directed), radians: what a twist sets."""
    axes = chain.joint_axes(q)
    return [float(np.arccos(np.clip(u @ v, -1.0, 1.0))) for (_, u), (_, v) in itertools.pairwise(axes)]
