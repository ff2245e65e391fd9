"""The collision matrix's machinery (modc.physical.collisions classifies the pairs with it):
numpy forward kinematics of many samples at once, the bounds that settle most samples without a
mesh test (link spheres, link boxes, mesh spheres, mesh boxes: each holds what it bounds, grown by
SPHERE_MARGIN, so "apart" is certain), coal's exact mesh tests for the rest, and the sampling loop
that stops testing a pair once its reason is certain. coal is imported at the first exact test
only: an arm whose pairs the bounds settle (the farm arm's) needs no coal at all.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ..records import Record
from .multibody import enclosing_sphere

if TYPE_CHECKING:
    from .collisions import Geometry

ALWAYS_PERCENT = 95  # "Always": colliding in at least this percentage of the samples
CHUNK = 4096  # samples per broad-phase batch (bounds memory for large sample counts)
SPHERE_MARGIN = 1e-3  # m: bounding spheres closer than this count as touching (the filter errs towards testing meshes)


class Joints(Record, kw_only=False):
    """An arm's joints for numpy forward kinematics (every one revolute): per joint j (0: the
    universe) its parent, its frame at q = 0 in the parent's frame (R, t), its axis and q index."""

    parents: tuple[int, ...]
    R: np.ndarray  # (nj, 3, 3)
    t: np.ndarray  # (nj, 3)
    axis: np.ndarray  # (nj, 3), unit
    idx_q: tuple[int, ...]
    lower: np.ndarray  # (nq,) position limits as the model has them (joint_limits() cleans them)
    upper: np.ndarray


def joints_of(model) -> Joints | None:
    """A pinocchio model's joints, when every one is revolute (else None)."""
    kinds = [model.joints[j].shortname() for j in range(1, model.njoints)]
    if not all(k in _REVOLUTE_AXES or k == "JointModelRevoluteUnaligned" for k in kinds):
        return None
    axes = [np.array([0.0, 0.0, 1.0])]
    for j in range(1, model.njoints):
        known = _REVOLUTE_AXES.get(model.joints[j].shortname())
        axes.append(np.asarray(model.joints[j].extract().axis if known is None else known, float))
    return Joints(tuple(model.parents), np.array([np.asarray(M.rotation) for M in model.jointPlacements]),
                  np.array([np.asarray(M.translation) for M in model.jointPlacements]),
                  np.array([a / np.linalg.norm(a) for a in axes]),
                  (-1, *(model.joints[j].idx_q for j in range(1, model.njoints))),
                  np.array(model.lowerPositionLimit, float), np.array(model.upperPositionLimit, float))


_REVOLUTE_AXES = {"JointModelRX": (1.0, 0.0, 0.0), "JointModelRY": (0.0, 1.0, 0.0), "JointModelRZ": (0.0, 0.0, 1.0)}


def batch_placements(model, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Forward kinematics of N configurations at once: world rotation (N, njoints, 3, 3) and
    translation (N, njoints, 3) of every joint frame (index 0 = universe), as pinocchio's
    data.oMi. Revolute joints are done in numpy; any other joint type falls back to pinocchio."""
    joints = joints_of(model)
    if joints is not None:
        return placements(joints, Q)
    import pinocchio as pin

    N = Q.shape[0]
    nj = model.njoints
    R = np.empty((N, nj, 3, 3))
    p = np.empty((N, nj, 3))
    R[:, 0], p[:, 0] = np.eye(3), 0.0
    data = model.createData()
    for n, q in enumerate(Q):
        pin.forwardKinematics(model, data, q)
        for j in range(1, nj):
            R[n, j], p[n, j] = data.oMi[j].rotation, data.oMi[j].translation
    return R, p


def placements(joints: Joints, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """batch_placements in numpy, for revolute joints."""
    N = Q.shape[0]
    nj = len(joints.parents)
    R = np.empty((N, nj, 3, 3))
    p = np.empty((N, nj, 3))
    R[:, 0], p[:, 0] = np.eye(3), 0.0
    for j in range(1, nj):
        parent = joints.parents[j]
        Rpar = R[:, parent].reshape(N * 3, 3)
        p[:, j] = p[:, parent] + (Rpar @ joints.t[j]).reshape(N, 3)
        R0 = Rpar @ joints.R[j]  # (N*3, 3): the joint frame at q = 0
        # R0 @ Rot(axis, q) = R0 + sin q (R0 K) + (1 - cos q) (R0 K^2)   (Rodrigues)
        k = joints.axis[j]
        K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
        R0K = R0 @ K
        angle = Q[:, joints.idx_q[j]]
        s_, c_ = np.repeat(np.sin(angle), 3)[:, None], np.repeat(1.0 - np.cos(angle), 3)[:, None]
        R[:, j] = (R0 + s_ * R0K + c_ * (R0K @ K)).reshape(N, 3, 3)
    return R, p


class Checker:
    """Broad phase (bounding spheres and boxes, all samples at once in numpy) and exact mesh tests
    of link pairs (coal) for one Geometry."""

    def __init__(self, geo: Geometry, pairs: list[tuple[str, str]]):
        self.geo = geo
        self.pairs = pairs
        self.exact = [[(i, j) for i in geo.objects[a] for j in geo.objects[b]] for a, b in pairs]
        self._coal: tuple[Any, Any, dict[int, Any]] | None = None  # coal, its request, the meshes' shapes
        self._at: tuple[np.ndarray, np.ndarray] | None = None  # joint placements of the last set_configuration
        self._placed: dict[int, Any] = {}  # mesh -> its coal.Transform3s there
        # a bounding sphere per mesh and per link, in the frame of the joint that carries it, and a
        # box per mesh (its bounding box in its own frame) and per link (its meshes' bounding box in
        # the joint's frame), grown by half the margin on every side: boxes 0..n_geo-1 are the
        # meshes', then one per link (link_box)
        self.spheres: dict[int, tuple[int, np.ndarray, float]] = {}  # geometry index -> sphere
        self.link_spheres: dict[str, tuple[int, np.ndarray, float]] = {}
        n_geo = len(geo.meshes)
        used = sorted({name for pr in pairs for name in pr}, key=geo.links.index)
        self.link_box = {link: n_geo + i for i, link in enumerate(used)}
        n_box = n_geo + len(used)
        self.box_joint = np.zeros(n_box, int)
        self.box_R, self.box_c, self.box_h = np.zeros((n_box, 3, 3)), np.zeros((n_box, 3)), np.zeros((n_box, 3))
        for link in used:
            pts = []
            for k in geo.objects[link]:
                mesh = geo.meshes[k]
                joint, Rk, tk, local = mesh.joint, mesh.R, mesh.t, mesh.points
                v = local @ Rk.T + tk
                self.spheres[k] = (joint, *enclosing_sphere(v))
                lo, hi = local.min(axis=0), local.max(axis=0)
                self.box_joint[k], self.box_R[k] = joint, Rk
                self.box_c[k], self.box_h[k] = Rk @ ((lo + hi) / 2) + tk, (hi - lo) / 2 + SPHERE_MARGIN / 2
                pts.append(v)
            assert len({geo.meshes[k].joint for k in geo.objects[link]}) == 1
            joint = geo.meshes[geo.objects[link][0]].joint
            v = np.vstack(pts)
            self.link_spheres[link] = (joint, *enclosing_sphere(v))
            b, lo, hi = self.link_box[link], v.min(axis=0), v.max(axis=0)
            self.box_joint[b], self.box_R[b] = joint, np.eye(3)
            self.box_c[b], self.box_h[b] = (lo + hi) / 2, (hi - lo) / 2 + SPHERE_MARGIN / 2
        self.sphere_joint = np.array([self.spheres.get(k, (0, None, 0.0))[0] for k in range(n_geo)], int)
        self.sphere_c = np.array([self.spheres[k][1] if k in self.spheres else np.zeros(3) for k in range(n_geo)],
                                 float).reshape(-1, 3)
        self.sphere_r = np.array([self.spheres.get(k, (0, None, 0.0))[2] for k in range(n_geo)], float)
        self.exact_tests = 0

    def broad_phase(self, Q: np.ndarray) -> np.ndarray:
        """(N, pairs) bool: may the two links touch in sample n? False is certain: every mesh
        lies in its spheres and boxes, which count as touching when closer than SPHERE_MARGIN.
        Link spheres, then link boxes, then the meshes' spheres and boxes, each only in the
        samples the one before could not settle."""
        R, p = self.placements(Q)
        N = Q.shape[0]

        def world(spheres: dict) -> tuple[dict, np.ndarray, np.ndarray]:
            keys = list(spheres)
            joints = np.array([spheres[k][0] for k in keys])
            local = np.array([spheres[k][1] for k in keys])
            c = np.empty((N, len(keys), 3))
            # world centres: R_j @ local + p_j, per joint (sorted(set()), not np.unique: that imports
            # numpy.ma, ~15 ms of a new arm's compile)
            for j in sorted(set(joints.tolist())):
                sel = np.flatnonzero(joints == j)
                c[:, sel] = (R[:, j].reshape(N * 3, 3) @ local[sel].T).reshape(N, 3, sel.size).transpose(0, 2, 1)
                c[:, sel] += p[:, j][:, None, :]
            return {k: i for i, k in enumerate(keys)}, c, np.array([spheres[k][2] for k in keys])

        lcol, lc, lr = world(self.link_spheres)
        mask = np.zeros((N, len(self.pairs)), bool)
        for k, (a, b) in enumerate(self.pairs):
            d2 = ((lc[:, lcol[a]] - lc[:, lcol[b]]) ** 2).sum(axis=1)
            rows = np.flatnonzero(d2 < (lr[lcol[a]] + lr[lcol[b]] + SPHERE_MARGIN) ** 2)
            if rows.size:  # the links' spheres touch: do the links' boxes?
                links = np.full(rows.size, self.link_box[a]), np.full(rows.size, self.link_box[b])
                rows = rows[~self._boxes_apart(R, p, rows, *links)]
            if rows.size == 0:
                continue
            ga, gb = np.asarray(self.geo.objects[a]), np.asarray(self.geo.objects[b])
            ca, cb = self._centres(R, p, rows, ga), self._centres(R, p, rows, gb)  # (rows, meshes, 3)
            d2 = ((ca[:, :, None, :] - cb[:, None, :, :]) ** 2).sum(axis=-1)
            reach = (self.sphere_r[ga][:, None] + self.sphere_r[gb][None, :] + SPHERE_MARGIN) ** 2
            r, i, j = np.nonzero(d2 < reach)  # mesh pairs whose spheres touch: do their boxes?
            near = ~self._boxes_apart(R, p, rows[r], ga[i], gb[j])
            mask[rows[r[near]], k] = True
        return mask

    def _centres(self, R: np.ndarray, p: np.ndarray, rows: np.ndarray, meshes: np.ndarray) -> np.ndarray:
        """(rows, meshes, 3): the meshes' sphere centres in the world in samples rows."""
        n, j = rows[:, None], self.sphere_joint[meshes][None, :]
        return (R[n, j] @ self.sphere_c[meshes][:, :, None])[..., 0] + p[n, j]  # R[n, j]: (rows, meshes, 3, 3)

    def _boxes_apart(self, R: np.ndarray, p: np.ndarray, n: np.ndarray, ga: np.ndarray,
                     gb: np.ndarray) -> np.ndarray:
        """(M,) bool: are the boxes of meshes ga[m] and gb[m] apart in sample n[m]? The separating
        axis test of two oriented boxes (15 axes), each box holding its mesh with half the margin to
        spare on every side; |R| is taken 1e-9 larger, so rounding can only make boxes touch."""
        Ra = R[n, self.box_joint[ga]] @ self.box_R[ga]  # (M, 3, 3): box axes in the world, as columns
        Rb = R[n, self.box_joint[gb]] @ self.box_R[gb]
        ca = (R[n, self.box_joint[ga]] @ self.box_c[ga][:, :, None])[:, :, 0] + p[n, self.box_joint[ga]]
        cb = (R[n, self.box_joint[gb]] @ self.box_c[gb][:, :, None])[:, :, 0] + p[n, self.box_joint[gb]]
        ha, hb = self.box_h[ga], self.box_h[gb]
        C = Ra.transpose(0, 2, 1) @ Rb  # b's axes in a's frame
        t = (Ra.transpose(0, 2, 1) @ (cb - ca)[:, :, None])[:, :, 0]  # b's centre in a's frame
        A = np.abs(C) + 1e-9
        apart = (np.abs(t) > ha + (A @ hb[:, :, None])[:, :, 0]).any(axis=1)  # a's axes
        tb = (C.transpose(0, 2, 1) @ t[:, :, None])[:, :, 0]
        apart |= (np.abs(tb) > (A.transpose(0, 2, 1) @ ha[:, :, None])[:, :, 0] + hb).any(axis=1)  # b's axes
        for i in range(3):  # a_i x b_j
            i1, i2 = (i + 1) % 3, (i + 2) % 3
            for j in range(3):
                j1, j2 = (j + 1) % 3, (j + 2) % 3
                reach = (ha[:, i1] * A[:, i2, j] + ha[:, i2] * A[:, i1, j]
                         + hb[:, j1] * A[:, i, j2] + hb[:, j2] * A[:, i, j1])
                apart |= np.abs(t[:, i2] * C[:, i1, j] - t[:, i1] * C[:, i2, j]) > reach
        return apart

    def placements(self, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        joints = self.geo.joints
        return placements(joints, Q) if joints is not None else batch_placements(self.geo.model, Q)

    def set_configuration(self, q: np.ndarray) -> None:
        R, p = self.placements(np.asarray(q, float)[None])
        self._at = (R[0], p[0])
        self._placed = {}

    def _transform(self, coal, m: int) -> Any:
        tf = self._placed.get(m)
        if tf is None:
            assert self._at is not None
            R, p = self._at
            mesh = self.geo.meshes[m]
            tf = self._placed[m] = coal.Transform3s(R[mesh.joint] @ mesh.R, R[mesh.joint] @ mesh.t + p[mesh.joint])
        return tf

    def collides(self, k: int) -> bool:
        """Exact test of link pair k (meshes, stop at the first colliding pair) at the
        configuration of the last set_configuration."""
        if self._coal is None:
            import coal

            request = coal.CollisionRequest()  # pinocchio's (GeometryData's): one contact, no contact points
            request.enable_contact = False
            self._coal = coal, request, {}
        coal, request, shapes = self._coal
        self.exact_tests += 1
        for i, j in self.exact[k]:
            for m in (i, j):
                if m not in shapes:
                    shapes[m] = self.geo.meshes[m].shape
            if coal.collide(shapes[i], self._transform(coal, i), shapes[j], self._transform(coal, j), request,
                            coal.CollisionResult()):
                return True
        return False


def sample(checker: Checker, n: int, active: list[int], Q: np.ndarray, samples: int,
            stats: dict[str, int]) -> tuple[list[int], list[int], bool]:
    """Run the sampled configurations, a chunk at a time, over the candidate pairs still active
    until each one's reason is certain. Per candidate: how many samples collided, and after how
    many samples its reason was certain (0: it never was); and whether any pair stayed undecided."""
    coll = [0] * n
    decided_at = [0] * n  # how many samples a pair saw before its reason was certain (0: all)
    free_limit = samples * (100 - ALWAYS_PERCENT)  # free * 100 > this -> not Always
    always_at = samples * ALWAYS_PERCENT  # coll * 100 >= this -> Always
    pending: list[int] = []  # active pairs seen colliding: they wait for > 5 % free samples
    for start in range(0, samples, CHUNK):
        if not active:
            break
        mask = checker.broad_phase(Q[start:start + CHUNK])
        for r in np.flatnonzero(mask.any(axis=1)).tolist():  # samples where some spheres touch
            i = start + r
            if not active:
                break
            row = mask[r]
            flagged = [k for k in active if row[k]]
            if flagged:
                checker.set_configuration(Q[i])
            changed = False
            for k in flagged:
                stats["broad_phase_hits"] += 1
                if checker.collides(k):
                    if not coll[k]:
                        pending.append(k)
                    coll[k] += 1
                    if coll[k] * 100 >= always_at:
                        decided_at[k] = i + 1
                        changed = True
            for k in pending:  # samples 0..i seen: i + 1 - coll[k] of them free
                if not decided_at[k] and (i + 1 - coll[k]) * 100 > free_limit:
                    decided_at[k] = i + 1
                    changed = True
            if changed:
                active = [k for k in active if not decided_at[k]]
                pending = [k for k in pending if not decided_at[k]]
    return coll, decided_at, bool(active)


__all__ = ["ALWAYS_PERCENT", "CHUNK", "SPHERE_MARGIN", "Checker", "Joints", "batch_placements", "joints_of",
           "placements", "sample"]
