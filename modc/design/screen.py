"""Cheap necessary conditions, in numpy, before anything expensive.

reach_bound   the farthest tool0 can get from base_link's origin: every fixed offset of the chain
              laid end to end. A target beyond it rules the skeleton out without any IK.
Obstacles     the arm as spheres along the segments between its frames (unit base -> twist1: the
              twist unit and input casing; twist1 -> joint: the actuator; joint -> end: the link
              bar), tested against each obstacle's signed distance. The radii are the light
              variant's (the thinner arm): the screen rejects only what surely collides, and the
              exact check (coal on the emitted meshes, modc.design.evaluate.verify) decides.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..kinematics import rpy_matrix


def reach_bound(unit_types, links, tool_xyz) -> float:
    r = 0.0
    for t, length in zip(unit_types, links, strict=True):
        r += float(np.hypot(t.x01, t.z01)) + t.z12 + (length if t.link else 0.0)
    return r + float(np.linalg.norm(tool_xyz))


@dataclass(frozen=True)
class Obstacles:
    """The cell's obstacles as arrays: shape code (0 box, 1 sphere, 2 cylinder), centre, rotation, size."""

    shape: np.ndarray  # (K,)
    centre: np.ndarray  # (K, 3)
    R: np.ndarray  # (K, 3, 3) obstacle frame -> base_link
    size: np.ndarray  # (K, 3): box half extents; sphere (r, 0, 0); cylinder (r, half length, 0)

    @classmethod
    def of(cls, obstacles) -> Obstacles:
        shapes, centres, Rs, sizes = [], [], [], []
        for o in obstacles:
            shapes.append({"box": 0, "sphere": 1, "cylinder": 2}[o.shape])
            centres.append(o.origin.xyz)
            Rs.append(rpy_matrix(o.origin.rpy))
            s = o.size
            sizes.append((s[0] / 2, s[1] / 2, s[2] / 2) if o.shape == "box" else (s[0], 0.0, 0.0) if o.shape == "sphere"
                         else (s[0], s[1] / 2, 0.0))
        return cls(np.array(shapes, int), np.array(centres, float).reshape(-1, 3), np.array(Rs).reshape(-1, 3, 3),
                   np.array(sizes, float).reshape(-1, 3))

    def distance(self, pts: np.ndarray) -> np.ndarray:
        """Signed distance (P, K) of points (P, 3) to every obstacle (negative inside)."""
        out = np.empty((pts.shape[0], len(self.shape)))
        for k, shape in enumerate(self.shape):
            out[:, k] = self._one(k, shape, pts)
        return out

    def nearest(self, pts: np.ndarray) -> np.ndarray:
        """Signed distance (P,) of points (P, 3) to the nearest obstacle (at least one)."""
        d = self._one(0, self.shape[0], pts)
        for k in range(1, len(self.shape)):
            d = np.minimum(d, self._one(k, self.shape[k], pts))
        return d

    def gradient(self, k: np.ndarray, pts: np.ndarray, h: float = 1e-6) -> np.ndarray:
        """Unit gradients (P, 3) of obstacle k[i]'s signed distance at pts[i] (central differences:
        the distance is 1-Lipschitz and smooth off the faces' medial planes; on one, either side's
        direction leads out). A point exactly at a box's or sphere's centre gets some unit vector."""
        out = np.zeros(pts.shape)
        for j in np.unique(k):
            at = np.flatnonzero(k == j)
            x = pts[at]
            for a in range(3):
                e = np.zeros(3)
                e[a] = h
                out[at, a] = self._one(int(j), int(self.shape[j]), x + e) - self._one(int(j), int(self.shape[j]), x - e)
        norm = np.linalg.norm(out, axis=1, keepdims=True)
        return np.where(norm > 1e-12, out / np.maximum(norm, 1e-300), np.array([0.0, 0.0, 1.0]))

    def _one(self, k: int, shape: int, pts: np.ndarray) -> np.ndarray:
        # component by component: reductions over an axis of 2 or 3 cost more than the arithmetic
        x = (pts - self.centre[k]) @ self.R[k]  # R^T (p - c), row-wise
        s = self.size[k]
        x0, x1, x2 = x[:, 0], x[:, 1], x[:, 2]
        if shape == 1:
            return np.sqrt(x0 * x0 + x1 * x1 + x2 * x2) - s[0]
        if shape == 0:
            d = [np.abs(x0) - s[0], np.abs(x1) - s[1], np.abs(x2) - s[2]]
        else:
            d = [np.sqrt(x0 ** 2 + x1 ** 2) - s[0], np.abs(x2) - s[1]]
        m = [np.maximum(di, 0.0) for di in d]
        sq = m[0] * m[0] + m[1] * m[1]
        if len(m) == 3:
            sq = sq + m[2] * m[2]
        inner = np.maximum(d[0], d[1])
        if len(d) == 3:
            inner = np.maximum(inner, d[2])
        return np.sqrt(sq) + np.minimum(inner, 0.0)


def segment_radii(library) -> np.ndarray:
    """Radii of the three segments of a unit (twist unit, actuator, link bar): the thinnest variant's."""
    v = min(library.variants.values(), key=lambda v: v.actuator.diameter)
    r = v.actuator.diameter / 2
    bar = float(np.hypot(v.link_module.width, v.link_module.height)) / 2
    return np.array([r, r, bar])


def collides(obstacles: Obstacles, frames: np.ndarray, radii: np.ndarray, step: float = 0.02) -> np.ndarray:
    """frames (R, n, 4, 3): each unit's frame origins (base, twist1, joint, end) in R poses. True
    where the sphere-swept segments between them (except the first unit's twist unit, part of
    base_link, which never moves) go into an obstacle by more than 1 mm."""
    R, n = frames.shape[:2]
    if len(obstacles.shape) == 0 or R == 0:
        return np.zeros(R, bool)
    a, b = frames[:, :, :3, :], frames[:, :, 1:, :]  # (R, n, 3 segments, 3)
    # a segment whose midpoint is farther from every obstacle than half its length plus its
    # radius is clear (a signed distance changes no faster than the distance): only the others
    # are sampled
    mid, half = (a + b) / 2, np.linalg.norm(b - a, axis=-1) / 2
    near = obstacles.nearest(mid.reshape(-1, 3)).reshape(R, n, 3) - half - radii < -1e-3
    near[:, 0, 0] = False
    out = np.zeros(R, bool)
    if not near.any():
        return out
    m = int(np.ceil(0.25 / step)) + 1  # points per segment: enough for a 0.25 m link bar
    ts = np.linspace(0.0, 1.0, m)
    r_i, n_i, s_i = np.nonzero(near)
    aa, ab, rad = a[r_i, n_i, s_i], b[r_i, n_i, s_i] - a[r_i, n_i, s_i], radii[s_i]
    # sample p_j = aa + ab t_j; its two ends first
    ends = obstacles.nearest(np.concatenate([aa + ab * ts[0], aa + ab * ts[-1]])).reshape(2, -1) - rad
    np.logical_or.at(out, r_i, (ends < -1e-3).any(0))
    # then the samples in between, of poses not decided yet, only where the ends leave room: a
    # signed distance changes no faster than the distance, so a sample t_j L from an end clear
    # by more than that is clear too (1e-9: rounding). The same samples decide as when all are
    # measured.
    inner, length = ts[1:-1], 2 * half[r_i, n_i, s_i]
    bound = np.maximum(ends[0][:, None] - inner * length[:, None], ends[1][:, None] - (1 - inner) * length[:, None])
    k, j = np.nonzero((bound < -1e-3 + 1e-9) & ~out[r_i][:, None])
    if k.size:
        d = obstacles.nearest(aa[k] + ab[k] * inner[j][:, None]) - rad[k]
        np.logical_or.at(out, r_i[k], d < -1e-3)
    return out




def escape(obstacles: Obstacles, frames: np.ndarray, radii: np.ndarray,
           step: float = 0.02) -> tuple[np.ndarray, np.ndarray]:
    """frames (R, n, 4, 3) as for collides, of poses that collide: per pose the unit direction
    (R, 3) that leads out of the obstacle the arm goes deepest into - the gradient of that
    obstacle's signed distance at the arm's deepest sample (the segments sampled as collides
    samples them, the first unit's twist unit left out) - and how deep (R,) m. Moving tool0 that
    way moves the part of the arm near it the same way: the screen's retry inside a target's
    tolerance (modc.design.evaluate.clear_within) aims there. The depth is inf where the first
    unit's actuator (twist1 -> joint 1, on joint 1's axis: no joint moves it) collides: no joint
    vector clears that pose.

    Only the segments collides would sample are, and each only against the obstacles it may go
    into: a pose collides, so some sample lies more than 1 mm inside some obstacle, and that
    (segment, obstacle) pair's midpoint bound says so (a signed distance changes no faster than
    the distance); the deepest sample lies at least as deep, so in such a pair too. The first of
    the least values in (unit, segment, sample, obstacle) order is the deepest."""
    R, n = frames.shape[:2]
    a, b = frames[:, :, :3, :], frames[:, :, 1:, :]  # (R, n, 3, 3)
    mid, half = (a + b) / 2, np.linalg.norm(b - a, axis=-1) / 2
    K = len(obstacles.shape)
    pair = obstacles.distance(mid.reshape(-1, 3)).reshape(R, n, 3, K) - (half + radii)[..., None] < -1e-3
    pair[:, 0, 0] = False
    r_i, n_i, s_i = np.nonzero(pair.any(-1))  # pose by pose, in (unit, segment) order
    way, depth = np.tile([0.0, 0.0, 1.0], (R, 1)), np.zeros(R)
    if not r_i.size:
        return way, depth
    m = int(np.ceil(0.25 / step)) + 1
    ts = np.linspace(0.0, 1.0, m)
    aa = a[r_i, n_i, s_i]
    pts = aa[:, None, :] + (b[r_i, n_i, s_i] - aa)[:, None, :] * ts[:, None]  # (M, m, 3)
    rad = radii[s_i]
    by_k = np.full((len(r_i), m, K), np.inf)
    live = pair[r_i, n_i, s_i]  # (M, K)
    for k in range(K):
        rows = np.flatnonzero(live[:, k])
        if rows.size:
            by_k[rows, :, k] = (obstacles._one(k, int(obstacles.shape[k]), pts[rows].reshape(-1, 3)).reshape(-1, m)
                                - rad[rows][:, None])
    d = by_k.reshape(len(r_i), m * K)
    first = d.argmin(1)
    low = d[np.arange(len(r_i)), first]
    starts = np.flatnonzero(np.r_[True, r_i[1:] != r_i[:-1]])
    poses = r_i[starts]
    # per pose the first segment holding its least value
    least = np.repeat(np.minimum.reduceat(low, starts), np.diff(np.r_[starts, len(r_i)]))
    at = np.flatnonzero(low == least)
    pick = at[np.unique(r_i[at], return_index=True)[1]]
    where = pts[pick, first[pick] // K]
    way[poses] = obstacles.gradient(first[pick] % K, where)
    stuck = np.zeros(R, bool)
    act = (n_i == 0) & (s_i == 1)
    np.logical_or.at(stuck, r_i[act], (d[act] < -1e-3).any(1))
    depth[poses] = np.where(stuck[poses], np.inf, -low[pick])
    return way, depth
