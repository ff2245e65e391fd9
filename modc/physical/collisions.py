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
  2. a vectorised broad phase (modc.physical.broadphase): forward kinematics of all samples at
     once in numpy, then a bounding sphere per link, a box per link (its meshes' bounding box in
     its joint's frame), a sphere per mesh and an oriented box per mesh (its bounding box in its
     own frame, separating axis test), each with a 1 mm margin and each only in the samples the
     one before left open. Every bound contains what it bounds, so bounds apart => meshes
     apart; only samples where some mesh boxes of a pair touch reach coal (the farm arm: none,
     at the default pose included, where spheres alone sent 2,890 samples to coal).
     (Bounding volumes are only a filter: classifying with them alone -- or with convex hulls --
     would be conservative for Never but would wrongly disable pairs as Default or Always.)
  3. the exact test of a link pair is coal over its mesh pairs, placed by the same numpy
     kinematics, stopping at the first collision (coal's BVH rejects far meshes at the root);
     coal is imported at the first exact test, pinocchio not at all (Geometry builds its
     pinocchio models for other users, on first use).
Samples are drawn and visited in order on one thread, so the result depends only on the arm's
geometry and joints, the sample count and the seed: same input -> same matrix on any machine and thread
count (barring floating-point differences in coal for meshes that touch to within rounding;
the filter's margin keeps near-contacts out of the broad phase's hands).
"""
from __future__ import annotations

from collections.abc import Callable, Mapping
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from ..model.robot import default_position
from ..records import Record, field
from .assembly import Description
from .broadphase import (
    ALWAYS_PERCENT,
    CHUNK,
    SPHERE_MARGIN,
    Checker,
    Joints,
    batch_placements,
    joints_of,
    placements,
    sample,
)
from .multibody import hull_points

DEFAULT_SAMPLES = 10_000  # the MoveIt Setup Assistant's default "sampling density"
DEFAULT_SEED = 0

REASONS = ("Adjacent", "Default", "Always", "Never")
# Which pairs a collision check skips: the one rule of `modc plan`, `modc sim` (both engines) and
# the viewer. "Never" pairs stay checked: never colliding in the samples is MoveIt's shortcut for
# speed, not a promise, so a pose that brings them into contact is a real collision.
UNCHECKED_REASONS = ("Adjacent", "Default", "Always")


class Pair(Record, kw_only=False):
    link1: str
    link2: str
    reason: str  # one of REASONS


class CollisionMatrix(Record, kw_only=False):
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


class Mesh(Record, kw_only=False, frozen=False):
    """One collision mesh: the joint carrying it, its placement in that joint's frame (R, t), the
    points whose hull holds it (its vertices, in its own frame) and its coal geometry, made on
    first use (a matrix whose pairs the bounding boxes settle needs no coal at all)."""

    joint: int
    R: np.ndarray
    t: np.ndarray
    points: np.ndarray
    make_shape: Callable[[], Any] = field(hidden=True, compare=False)

    @property
    def shape(self) -> Any:
        return self.make_shape()


class Geometry(Record, kw_only=False, frozen=False):
    """An arm's collision model: its link graph, its joints (numpy forward kinematics; None: other
    joint types, pinocchio's) and its collision meshes placed on the joints. compute() needs no
    more and imports no pinocchio; model and geom_model (pinocchio's Model and GeometryModel of
    the same arm) are built on first use."""

    links: tuple[str, ...]
    edges: tuple[tuple[str, str], ...]  # (parent, child) per URDF joint
    objects: dict[str, list[int]]  # link -> indices into meshes (and geom_model.geometryObjects)
    joints: Joints | None
    meshes: list[Mesh]  # in geom_model's order
    pin_models: Callable[[], tuple[Any, Any]] = field(hidden=True, compare=False)
    _pin: tuple[Any, Any] | None = field(default=None, hidden=True, compare=False)

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
    return Geometry(links, edges, objects, joints_of(model), meshes, lambda: (model, geom_model))


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
        checker = Checker(geo, candidates)
        checker.set_configuration(q0)
        near = checker.broad_phase(q0[None])[0]  # pairs whose boxes are apart do not collide there
        for k, p in enumerate(candidates):
            if near[k] and checker.collides(k):
                reasons[p] = "Default"
        active = [k for k, p in enumerate(candidates) if p not in reasons]
        stats["sampled_pairs"] = len(active)
        Q = sample_configurations(lower, upper, samples, seed)
        coll, decided_at, undecided = sample(checker, len(candidates), active, Q, samples, stats)
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


__all__ = ["ALWAYS_PERCENT", "CHUNK", "DEFAULT_SAMPLES", "DEFAULT_SEED", "REASONS", "SPHERE_MARGIN",
           "UNCHECKED_REASONS", "CollisionMatrix", "Geometry", "Joints", "Mesh", "Pair", "adjacent_pairs",
           "batch_placements", "cached_matrix", "compute", "compute_naive", "default_configuration", "geometry",
           "joint_limits", "load", "placements", "sample_configurations"]
