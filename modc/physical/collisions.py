"""Self-collision matrix of an arm, computed the way the MoveIt Setup Assistant does it, but
seeded and deterministic (the SRDF backend writes it as <disable_collisions>).

Every pair of links that carry collision geometry gets at most one reason to be disabled:

    Adjacent  connected by a joint. Links without collision geometry (tool0, payload) are
              collapsed first: their neighbours become adjacent to each other (MoveIt's
              computeConnectionGraph), and they never appear in a pair themselves.
    Default   in collision in the default configuration (q = 0, or the middle of a joint's
              range when 0 is outside it: MoveIt's default joint values).
    Always    in collision in >= 95 % of the random samples.
    Never     in collision in none of the random samples (default 10,000, as in the Setup
              Assistant), drawn uniformly within the joint limits from a seeded PCG64 stream.
Other pairs stay enabled: MoveIt checks them while planning.

What is tested is what MoveIt loads: the <collision> meshes of the emitted URDF, here built in
memory from the arm's Description (modc.physical.multibody: the STL files' triangles as coal BVH
models, placed as pinocchio's URDF parser places them; tests/test_multibody.py checks both give
the same matrix), tested by coal (BVH meshes, so coal's mesh-mesh semantics, which are FCL's and
MoveIt's: surfaces that cross or touch collide; a mesh wholly inside another one does not). No
geometry test is hand-written here. load() reads an emitted URDF instead (the consumer check).

Speed (10,000 samples of a 6-DoF arm well under 0.5 s on one core; see
benchmarks/bench_collisions.py for the figure next to a naive all-mesh-pairs anchor) comes from
three things, none of which can change a result:
  1. link pairs, not mesh pairs, are classified, and a pair leaves the loop as soon as its
     reason is certain: one collision -> not Never, and then more than 5 % free samples -> not
     Always (it stays enabled); >= 95 % collisions -> Always. Never pairs see every sample.
  2. a vectorised broad phase: forward kinematics of all samples at once in numpy, then a
     bounding sphere per link and per mesh (plus a 1 mm margin), then, for meshes whose spheres
     touch, their bounding boxes in their own frames (oriented boxes, the same margin, the
     separating axis test). A sphere or box contains its mesh, so spheres or boxes apart =>
     meshes apart; only samples where some boxes of a pair touch reach coal (on the farm arm,
     none of the 2,887 whose spheres touched: the box saves ~2,900 exact tests, ~40 ms).
     (Bounding volumes are only a filter: classifying with them alone -- or with convex hulls --
     would be conservative for Never but would wrongly disable pairs as Default or Always.)
  3. the exact test of a link pair is one pinocchio call over all its mesh pairs, stopping at
     the first collision (coal's BVH rejects far meshes at the root).
Samples are drawn and visited in order on one thread, so the result depends only on the arm's
geometry and joints, the sample count and the seed: same input -> same matrix on any machine and thread
count (barring floating-point differences in coal for meshes that touch to within rounding;
the filter's margin keeps near-contacts out of the broad phase's hands).
"""
from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from ..model.robot import default_position
from .assembly import Description
from .multibody import enclosing_sphere, hull_points

DEFAULT_SAMPLES = 10_000  # the MoveIt Setup Assistant's default "sampling density"
DEFAULT_SEED = 0
ALWAYS_PERCENT = 95  # "Always": colliding in at least this percentage of the samples
CHUNK = 4096  # samples per broad-phase batch (bounds memory for large sample counts)
SPHERE_MARGIN = 1e-3  # m: bounding spheres closer than this count as touching (the filter errs towards testing meshes)

REASONS = ("Adjacent", "Default", "Always", "Never")
# Which pairs a collision check skips: the one rule of `modc plan`, `modc sim` (both engines) and
# the viewer. "Never" pairs stay checked: never colliding in the samples is MoveIt's shortcut for
# speed, not a promise, so a pose that brings them into contact is a real collision.
UNCHECKED_REASONS = ("Adjacent", "Default", "Always")


@dataclass(frozen=True)
class Pair:
    link1: str
    link2: str
    reason: str  # one of REASONS


@dataclass(frozen=True)
class CollisionMatrix:
    links: tuple[str, ...]  # every URDF link, in URDF order
    geometry_links: tuple[str, ...]  # links with collision geometry, in URDF order
    disabled: tuple[Pair, ...]  # in URDF link order (link1 before link2)
    enabled: tuple[tuple[str, str], ...]  # pairs MoveIt has to keep checking
    samples: int
    seed: int
    default_q: tuple[float, ...]
    counts: dict[tuple[str, str], tuple[int, int]] = field(default_factory=dict, compare=False)
    # (collisions, samples tested) per sampled pair; a pair leaves the loop once decided
    stats: dict[str, int] = field(default_factory=dict, compare=False)

    @property
    def links_without_geometry(self) -> tuple[str, ...]:
        return tuple(name for name in self.links if name not in self.geometry_links)

    def unchecked(self) -> set[frozenset[str]]:
        """The pairs a collision check skips (UNCHECKED_REASONS); every other pair of links with
        geometry is checked."""
        return {frozenset((p.link1, p.link2)) for p in self.disabled if p.reason in UNCHECKED_REASONS}

    def reason(self, a: str, b: str) -> str | None:
        for p in self.disabled:
            if {p.link1, p.link2} == {a, b}:
                return p.reason
        return None


@dataclass(frozen=True)
class Joints:
    """An arm's joints for numpy forward kinematics (every one revolute): per joint j (0: the
    universe) its parent, its frame at q = 0 in the parent's frame (R, t), its axis and q index."""

    parents: tuple[int, ...]
    R: np.ndarray  # (nj, 3, 3)
    t: np.ndarray  # (nj, 3)
    axis: np.ndarray  # (nj, 3), unit
    idx_q: tuple[int, ...]
    lower: np.ndarray  # (nq,) position limits as the model has them (joint_limits() cleans them)
    upper: np.ndarray


@dataclass
class Mesh:
    """One collision mesh: the joint carrying it, its placement in that joint's frame (R, t), the
    points whose hull holds it (its vertices, in its own frame) and its coal geometry, made on
    first use (a matrix whose pairs the bounding boxes settle needs no coal at all)."""

    joint: int
    R: np.ndarray
    t: np.ndarray
    points: np.ndarray
    make_shape: Callable[[], Any] = field(repr=False, compare=False)

    @property
    def shape(self) -> Any:
        return self.make_shape()


@dataclass
class Geometry:
    """An arm's collision model: its link graph, its joints (numpy forward kinematics; None: other
    joint types, pinocchio's) and its collision meshes placed on the joints. compute() needs no
    more and imports no pinocchio; model and geom_model (pinocchio's Model and GeometryModel of
    the same arm) are built on first use."""

    links: tuple[str, ...]
    edges: tuple[tuple[str, str], ...]  # (parent, child) per URDF joint
    objects: dict[str, list[int]]  # link -> indices into meshes (and geom_model.geometryObjects)
    joints: Joints | None
    meshes: list[Mesh]  # in geom_model's order
    pin_models: Callable[[], tuple[Any, Any]] = field(repr=False, compare=False)
    _pin: tuple[Any, Any] | None = field(default=None, repr=False, compare=False)

    @property
    def geometry_links(self) -> tuple[str, ...]:
        return tuple(name for name in self.links if self.objects.get(name))

    @property
    def model(self) -> Any:
        """pin.Model"""
        if self._pin is None:
            self._pin = self.pin_models()
        return self._pin[0]

    @property
    def geom_model(self) -> Any:
        """pin.GeometryModel (collision meshes)"""
        self.model  # noqa: B018 - builds both
        assert self._pin is not None
        return self._pin[1]


def geometry(desc: Description) -> Geometry:
    """The arm's collision model, built in memory from its Description (no files, no pinocchio:
    the same joints, meshes and placements as multibody.model and multibody.geometry make)."""
    from . import multibody

    placed = multibody.link_frames(desc)
    parents, Ms, lower, upper = [0], [np.eye(4)], [], []
    for j in desc.joints:
        if j.kind == "revolute":
            assert j.limits is not None
            parents.append(placed[j.parent][0])
            Ms.append(placed[j.parent][1] @ j.T_parent_child)
            lower.append(j.limits.lower)
            upper.append(j.limits.upper)
    M = np.array(Ms)
    nj = len(parents)
    joints = Joints(tuple(parents), M[:, :3, :3], M[:, :3, 3], np.tile([0.0, 0.0, 1.0], (nj, 1)),
                    tuple(range(-1, nj - 1)), np.array(lower, float), np.array(upper, float))
    links = tuple(link.name for link in desc.links)
    objects: dict[str, list[int]] = {name: [] for name in links}
    meshes: list[Mesh] = []
    for link in desc.links:  # multibody.geometry's order
        joint, T = placed[link.name]
        for v in link.visuals:
            P = T @ v.T_link_part
            objects[link.name].append(len(meshes))
            points = multibody.mesh_vertices(v.part)  # the vertices bvh(part) holds
            meshes.append(Mesh(joint, P[:3, :3], P[:3, 3], points, partial(multibody.bvh, v.part)))

    def pin_models() -> tuple[Any, Any]:
        model = multibody.model(desc)
        return model, multibody.geometry(desc, model)

    return Geometry(links, tuple((j.parent, j.child) for j in desc.joints), objects, joints, meshes, pin_models)


def _joints_of(model) -> Joints | None:
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


def load(files: Mapping[str, str | bytes], urdf_path: str) -> Geometry:
    """Load a URDF and the meshes it references from an output tree held in memory
    ({relative path: content}, as backends produce it): the files are written to a temporary
    directory so that pinocchio resolves relative mesh paths exactly as a user's tools do."""
    import tempfile
    import xml.etree.ElementTree as ET

    import pinocchio as pin

    from ..files import write_files

    with tempfile.TemporaryDirectory(prefix="modc-collisions-") as tmp:
        root = Path(tmp)
        write_files(files, root)
        urdf_file = root / urdf_path
        model = pin.buildModelFromUrdf(str(urdf_file))
        geom_model = pin.buildGeomFromUrdf(model, str(urdf_file), pin.GeometryType.COLLISION,
                                           package_dirs=[str(urdf_file.parent)])
        text = urdf_file.read_text(encoding="utf-8")
    xml = ET.fromstring(text)
    links = tuple(str(link.get("name")) for link in xml.findall("link"))
    edges = tuple((str(j.find("parent").get("link")), str(j.find("child").get("link")))  # type: ignore[union-attr]
                  for j in xml.findall("joint"))
    objects: dict[str, list[int]] = {name: [] for name in links}
    meshes: list[Mesh] = []
    for i, go in enumerate(geom_model.geometryObjects):
        objects[model.frames[go.parentFrame].name].append(i)
        meshes.append(Mesh(go.parentJoint, np.asarray(go.placement.rotation), np.asarray(go.placement.translation),
                           hull_points(go.geometry), partial(lambda g: g, go.geometry)))
    return Geometry(links, edges, objects, _joints_of(model), meshes, lambda: (model, geom_model))


def adjacent_pairs(links: tuple[str, ...], edges, has_geometry) -> set[frozenset[str]]:
    """MoveIt's connection graph: joint-connected links, with geometry-less links removed
    and their neighbours connected to each other (repeated until none is left)."""
    graph: dict[str, set[str]] = {name: set() for name in links}
    for a, b in edges:
        graph[a].add(b)
        graph[b].add(a)
    for link in links:  # URDF order: deterministic, and the result does not depend on it
        if has_geometry(link):
            continue
        nbrs = sorted(graph.pop(link), key=links.index)
        for n in nbrs:
            graph[n].discard(link)
        for i, a in enumerate(nbrs):
            for b in nbrs[i + 1:]:
                graph[a].add(b)
                graph[b].add(a)
    return {frozenset((a, b)) for a, nb in graph.items() for b in nb}


def joint_limits(model) -> tuple[np.ndarray, np.ndarray]:
    """Position limits to sample within (of a pin.Model or Joints); an unbounded (continuous)
    joint gets one turn."""
    lo, hi = (np.array(model.lower, float), np.array(model.upper, float)) if isinstance(model, Joints) else (
        np.array(model.lowerPositionLimit, float), np.array(model.upperPositionLimit, float))
    bad = ~(np.isfinite(lo) & np.isfinite(hi)) | (np.abs(lo) > 1e10) | (np.abs(hi) > 1e10)
    lo[bad], hi[bad] = -np.pi, np.pi
    return lo, hi


def default_configuration(lower, upper) -> np.ndarray:
    """MoveIt's default joint values (modc.model.robot.default_position, joint by joint)."""
    return np.array([default_position(float(lo), float(hi)) for lo, hi in zip(lower, upper, strict=True)])


def sample_configurations(lower, upper, samples: int, seed: int) -> np.ndarray:
    """samples x nq joint vectors, uniform in [lower, upper] from PCG64(seed) doubles."""
    lo, hi = np.asarray(lower, float), np.asarray(upper, float)
    u = np.random.Generator(np.random.PCG64(seed)).random((samples, lo.size))
    return lo + (hi - lo) * u


_REVOLUTE_AXES = {"JointModelRX": (1.0, 0.0, 0.0), "JointModelRY": (0.0, 1.0, 0.0), "JointModelRZ": (0.0, 0.0, 1.0)}


def batch_placements(model, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Forward kinematics of N configurations at once: world rotation (N, njoints, 3, 3) and
    translation (N, njoints, 3) of every joint frame (index 0 = universe), as pinocchio's
    data.oMi. Revolute joints are done in numpy; any other joint type falls back to pinocchio."""
    joints = _joints_of(model)
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


class _Checker:
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


def _sample(checker: _Checker, n: int, active: list[int], Q: np.ndarray, samples: int,
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


def _classify(candidates: list[tuple[str, str]], coll: list[int], decided_at: list[int], samples: int,
              reasons: dict[tuple[str, str], str], counts: dict[tuple[str, str], tuple[int, int]]) -> None:
    """Never or Always from the sampled counts, for the candidates without a reason yet (not
    Default); a pair that collides sometimes stays enabled. Fills reasons and counts."""
    for k, p in enumerate(candidates):
        if p in reasons:
            continue
        counts[p] = (coll[k], decided_at[k] or samples)
        if coll[k] == 0:
            reasons[p] = "Never"
        elif coll[k] * 100 >= samples * ALWAYS_PERCENT:
            reasons[p] = "Always"


def compute(geo: Geometry, samples: int = DEFAULT_SAMPLES, seed: int = DEFAULT_SEED) -> CollisionMatrix:
    """Classify every pair of links with collision geometry (see the module docstring)."""
    if samples < 0 or seed < 0:
        raise ValueError("samples and seed must be >= 0")
    links = geo.links
    glinks = geo.geometry_links
    all_pairs = [(a, b) for i, a in enumerate(glinks) for b in glinks[i + 1:]]
    adjacent = adjacent_pairs(links, geo.edges, lambda name: bool(geo.objects.get(name)))
    reasons: dict[tuple[str, str], str] = {p: "Adjacent" for p in all_pairs if frozenset(p) in adjacent}
    candidates = [p for p in all_pairs if p not in reasons]

    lower, upper = joint_limits(geo.joints if geo.joints is not None else geo.model)
    q0 = default_configuration(lower, upper)
    counts: dict[tuple[str, str], tuple[int, int]] = {}
    stats = {"pairs": len(all_pairs), "sampled_pairs": 0, "samples_run": 0, "broad_phase_hits": 0, "exact_tests": 0}

    if candidates:
        checker = _Checker(geo, candidates)
        checker.set_configuration(q0)
        near = checker.broad_phase(q0[None])[0]  # pairs whose boxes are apart do not collide there
        for k, p in enumerate(candidates):
            if near[k] and checker.collides(k):
                reasons[p] = "Default"
        active = [k for k, p in enumerate(candidates) if p not in reasons]
        stats["sampled_pairs"] = len(active)
        Q = sample_configurations(lower, upper, samples, seed)
        coll, decided_at, undecided = _sample(checker, len(candidates), active, Q, samples, stats)
        stats["samples_run"] = samples if undecided else max(decided_at, default=0)
        if samples:  # else no sampling was asked for
            _classify(candidates, coll, decided_at, samples, reasons, counts)
        stats["exact_tests"] = checker.exact_tests

    disabled = tuple(Pair(a, b, reasons[(a, b)]) for a, b in all_pairs if (a, b) in reasons)
    enabled = tuple(p for p in all_pairs if p not in reasons)
    return CollisionMatrix(links, glinks, disabled, enabled, samples, seed, tuple(float(x) for x in q0), counts, stats)


ALGORITHM = "1"  # bump when compute() could classify any pair differently


def cached_matrix(desc: Description, samples: int = DEFAULT_SAMPLES, seed: int = DEFAULT_SEED) -> CollisionMatrix:
    """compute() on the arm's geometry, through the disk cache: the matrix is a pure function of
    the Description (links, joints, limits, parts), the sample count and the seed, so a hit
    equals a fresh computation (per-pair counts and stats are not kept)."""
    import json

    from .. import cache

    name = cache.key(ALGORITHM, str(samples), str(seed), desc.fingerprint()) + ".json"
    hit = cache.get("collisions", name)
    if hit is not None:
        d = json.loads(hit)
        return CollisionMatrix(
            links=tuple(d["links"]), geometry_links=tuple(d["geometry_links"]),
            disabled=tuple(Pair(*p) for p in d["disabled"]), enabled=tuple(tuple(p) for p in d["enabled"]),
            samples=d["samples"], seed=d["seed"], default_q=tuple(d["default_q"]))
    matrix = compute(geometry(desc), samples=samples, seed=seed)
    doc = {"links": matrix.links, "geometry_links": matrix.geometry_links,
           "disabled": [[p.link1, p.link2, p.reason] for p in matrix.disabled], "enabled": matrix.enabled,
           "samples": matrix.samples, "seed": matrix.seed, "default_q": matrix.default_q}
    cache.put("collisions", name, json.dumps(doc).encode())
    return matrix


def compute_naive(geo: Geometry, samples: int = DEFAULT_SAMPLES, seed: int = DEFAULT_SEED) -> CollisionMatrix:
    """The anchor for the benchmark and a cross-check in the tests: every mesh pair of every
    non-adjacent link pair, in every sample, every result read back. Same classification."""
    import pinocchio as pin

    links, glinks = geo.links, geo.geometry_links
    all_pairs = [(a, b) for i, a in enumerate(glinks) for b in glinks[i + 1:]]
    adjacent = adjacent_pairs(links, geo.edges, lambda name: bool(geo.objects.get(name)))
    reasons = {p: "Adjacent" for p in all_pairs if frozenset(p) in adjacent}
    candidates = [p for p in all_pairs if p not in reasons]
    gm = geo.geom_model.copy()
    gm.removeAllCollisionPairs()
    owner = []
    for k, (a, b) in enumerate(candidates):
        for i in geo.objects[a]:
            for j in geo.objects[b]:
                gm.addCollisionPair(pin.CollisionPair(i, j))
                owner.append(k)
    gd = gm.createData()
    model = geo.model
    data = model.createData()
    lower, upper = joint_limits(model)
    q0 = default_configuration(lower, upper)

    def colliding(q) -> set[int]:
        pin.computeCollisions(model, data, gm, gd, q, False)
        return {owner[m] for m, r in enumerate(gd.collisionResults) if r.isCollision()}

    at_default = colliding(q0)
    coll = [0] * len(candidates)
    for q in sample_configurations(lower, upper, samples, seed):
        for k in colliding(q):
            coll[k] += 1
    counts = {}
    for k, p in enumerate(candidates):
        if k in at_default:
            reasons[p] = "Default"
            continue
        counts[p] = (coll[k], samples)
        if coll[k] == 0:
            reasons[p] = "Never"
        elif coll[k] * 100 >= samples * ALWAYS_PERCENT:
            reasons[p] = "Always"
    disabled = tuple(Pair(a, b, reasons[(a, b)]) for a, b in all_pairs if (a, b) in reasons)
    enabled = tuple(p for p in all_pairs if p not in reasons)
    return CollisionMatrix(links, glinks, disabled, enabled, samples, seed, tuple(float(x) for x in q0), counts,
                           {"pairs": len(all_pairs), "mesh_pairs": len(owner)})


__all__ = ["ALWAYS_PERCENT", "DEFAULT_SAMPLES", "DEFAULT_SEED", "REASONS", "UNCHECKED_REASONS", "CollisionMatrix",
           "Geometry", "Joints", "Pair", "adjacent_pairs", "batch_placements", "cached_matrix", "compute",
           "compute_naive", "default_configuration", "geometry", "joint_limits", "load", "placements",
           "sample_configurations"]
