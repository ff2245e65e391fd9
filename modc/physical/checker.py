"""Collision checking (the one home: the planner, the task planner, the viewer's contacts and
the design search's exact check use it): pinocchio + coal, double precision, on the geometry
the compiler emits. `modc.plan.collision` re-exports it under the planner's old name.

The robot is what `modc FILE -o OUT` writes: the URDF's <collision> meshes, built in memory
from the robot's Description (modc.physical.collisions.geometry, as the SRDF backend does; or
read from emitted files when given), tested by coal as BVH meshes. The environment is the file's
obstacles, in base_link, as coal primitives attached to the universe (base_link is the root and
never moves): box (size = full extents), sphere (radius), cylinder (radius, length along its
z), each placed by its origin (xyz, then URDF roll-pitch-yaw).

Pairs that are checked:
    robot vs environment   every moving link with geometry vs every obstacle. base_link never
                           moves, so base_link vs obstacles is tested once, on the start pose
                           (static_contacts), and never again;
    self                   every pair of links with geometry except those the SRDF disables as
                           Adjacent (links without geometry, tool0 and payload, collapsed first),
                           Default (touching in the default pose by construction) or Always.
                           The SRDF's Never pairs stay checked: never colliding in 10,000 random
                           poses is a sampling result, not a guarantee, and checking them is cheap.
The matrix is modc.physical.collisions.cached_matrix with the SRDF's defaults (same samples, same
seed), so "disabled" means what the emitted SRDF says.

Clearance and certified motions. A configuration is valid when every checked pair is more than
`margin` apart (coal's security margin). A straight joint-space motion is certified by
checking states close enough together that no point of the robot moves more than margin / 2
between two of them: then two bodies at least margin apart at every checked state cannot meet
in between (each moves at most margin / 2 towards the other). The bound on how far a point
moves is  sum_i |dq_i| * R_i, where R_i bounds the distance of any point beyond joint i from
joint i's axis (joint offsets plus the farthest mesh vertex of each link; see reach_radii).
"""
from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..model import ResolvedRobot
from .multibody import hull_points, obstacle_geometry

DEFAULT_MARGIN = 0.005  # m kept between the arm and obstacles, and between links, while planning
STATIC_TOLERANCE = 1e-3  # m: base_link may touch (penetrate by less than this) a fixed obstacle


@dataclass(frozen=True)
class Contact:
    a: str  # link name
    b: str  # link name, or obstacle name
    b_is_obstacle: bool
    b_shape: str = ""  # box / sphere / cylinder for obstacles

    def describe(self) -> str:
        other = f"{self.b_shape} '{self.b}'" if self.b_is_obstacle else self.b
        return f"{self.a} with {other}"


def _box_corners(geometry) -> np.ndarray:
    """The 8 corners of a geometry's bounding box in its own frame."""
    v = hull_points(geometry)
    lo, hi = v.min(axis=0), v.max(axis=0)
    return np.array([[(lo, hi)[i][0], (lo, hi)[j][1], (lo, hi)[k][2]] for i in (0, 1) for j in (0, 1) for k in (0, 1)])


class CollisionChecker:
    """The arm's collision model plus its environment. q is joint_1 … joint_n (rad)."""

    def __init__(self, robot: ResolvedRobot, files: Mapping[str, str | bytes] | None = None,
                 margin: float = DEFAULT_MARGIN, matrix=None):
        import pinocchio as pin

        from . import collisions
        from .assembly import describe

        self.pin = pin
        self.robot = robot
        desc = describe(robot)
        # files: the emitted URDF and meshes ({relative path: content}) to check instead of the
        # in-memory geometry (they describe the same arm; the tests compare the two)
        geo = collisions.geometry(desc) if files is None else collisions.load(files, f"urdf/{robot.file_stem}.urdf")
        self.geo = geo
        self.model = geo.model
        self.data = self.model.createData()
        self.matrix = collisions.cached_matrix(desc) if matrix is None else matrix
        self.tool_frame = self.model.getFrameId("tool0")
        names = [self.model.names[j] for j in range(1, self.model.njoints)]
        want = [f"joint_{i}" for i in range(1, robot.dof + 1)]
        if names != want or self.model.nq != robot.dof:
            raise ValueError(f"the URDF's joints {names} are not {want}")
        self.lower = np.array([robot.joint_range(i)[0] for i in range(1, robot.dof + 1)])
        self.upper = np.array([robot.joint_range(i)[1] for i in range(1, robot.dof + 1)])

        gm = geo.geom_model.copy()
        gm.removeAllCollisionPairs()
        self.owner: list[str] = []  # geometry index -> link or obstacle name
        for go in gm.geometryObjects:
            self.owner.append(self.model.frames[go.parentFrame].name)
        self.n_robot = len(self.owner)
        self.obstacles = {o.name: o for o in robot.obstacles}
        obstacle_ids: dict[str, int] = {}
        for o in robot.obstacles:
            g, M = obstacle_geometry(o)
            go = pin.GeometryObject(f"obstacle:{o.name}", 0, 0, M, g)
            obstacle_ids[o.name] = gm.addGeometryObject(go)
            self.owner.append(o.name)
        pairs, static = self._pairs(geo, obstacle_ids)

        self.gm = gm
        self.pairs = pairs
        self.static_pairs = static
        for i, j in pairs:
            gm.addCollisionPair(pin.CollisionPair(i, j))
        self.gd = gm.createData()
        self._corners = [_box_corners(go.geometry) for go in gm.geometryObjects]
        self.margin = float(margin)
        self.set_margin(margin)
        # a model with the static pairs only (tested once per start pose)
        self.gm_static = gm.copy()
        self.gm_static.removeAllCollisionPairs()
        for i, j in static:
            self.gm_static.addCollisionPair(pin.CollisionPair(i, j))
        self.gd_static = self.gm_static.createData()
        for req in self.gd_static.collisionRequests:
            req.security_margin = 0.0
            req.enable_contact = True
            req.num_max_contacts = 100000
        self.radii = self.reach_radii()
        self.checks = 0  # validity checks done (a deterministic measure of work)

    def _pairs(self, geo, obstacle_ids: dict[str, int]) -> tuple[list[tuple[int, int]], list[tuple[int, int]]]:
        """The geometry pairs to test while the arm moves (links the matrix checks, each moving
        link with each obstacle) and the static ones (base_link with each obstacle); sets
        self_pairs, the link pairs the matrix checks."""
        objects = geo.objects
        disabled = self.matrix.unchecked()  # the one rule: the SRDF's, modc sim's
        glinks = geo.geometry_links
        self.self_pairs = [(a, b) for i, a in enumerate(glinks) for b in glinks[i + 1:]
                           if frozenset((a, b)) not in disabled]
        moving = [name for name in glinks if name != "base_link"]
        pairs: list[tuple[int, int]] = []
        for a, b in self.self_pairs:
            pairs += [(i, j) for i in objects[a] for j in objects[b]]
        for link in moving:
            for name in sorted(obstacle_ids, key=lambda n: list(self.obstacles).index(n)):
                pairs += [(i, obstacle_ids[name]) for i in objects[link]]
        static = [(i, obstacle_ids[name]) for name in obstacle_ids for i in objects.get("base_link", [])]
        return pairs, static

    # -- configuration --------------------------------------------------------------------------
    def set_margin(self, margin: float) -> None:
        self.margin = float(margin)
        for req in self.gd.collisionRequests:
            req.security_margin = self.margin

    def tool_position(self, q) -> np.ndarray:
        pin = self.pin
        pin.forwardKinematics(self.model, self.data, np.asarray(q, float))
        return np.array(pin.updateFramePlacement(self.model, self.data, self.tool_frame).translation)

    # -- checks ---------------------------------------------------------------------------------
    def valid(self, q) -> bool:
        """No checked pair closer than the margin (joint limits are the caller's business)."""
        self.checks += 1
        return not self.pin.computeCollisions(self.model, self.data, self.gm, self.gd, np.asarray(q, float), True)

    def contacts(self, q, margin: float = 0.0) -> list[Contact]:
        """The moving pairs closer than margin at q (0: in collision), one entry per pair of
        names, in the order the pairs are checked (self pairs first)."""
        pin = self.pin
        saved = self.margin
        self.set_margin(margin)
        try:
            pin.computeCollisions(self.model, self.data, self.gm, self.gd, np.asarray(q, float), False)
            return self._named(p for p, r in zip(self.gm.collisionPairs, self.gd.collisionResults, strict=True)
                               if r.isCollision())
        finally:
            self.set_margin(saved)

    def static_contacts(self) -> list[Contact]:
        """base_link against the obstacles (the same in every pose): penetrating by more than
        STATIC_TOLERANCE (a floor the base stands on only touches it)."""
        pin = self.pin
        q = np.clip(np.zeros(self.model.nq), self.lower, self.upper)
        pin.computeCollisions(self.model, self.data, self.gm_static, self.gd_static, q, False)
        deep = []
        for p, r in zip(self.gm_static.collisionPairs, self.gd_static.collisionResults, strict=True):
            # coal's penetration_depth is a signed distance: negative inside
            depth = min((r.getContact(k).penetration_depth for k in range(r.numContacts())), default=0.0)
            if r.isCollision() and depth < -STATIC_TOLERANCE:
                deep.append(p)
        return self._named(deep)

    def _named(self, pairs) -> list[Contact]:
        out: list[Contact] = []
        for p in pairs:
            a, b = self.owner[p.first], self.owner[p.second]
            obstacle = p.second >= self.n_robot
            c = Contact(a, b, obstacle, self.obstacles[b].shape if obstacle else "")
            if c not in out:
                out.append(c)
        return out

    def clearance(self, q) -> tuple[float, Contact | None]:
        """Smallest distance over the checked pairs at q (m; a negative value means in collision,
        not necessarily the deepest penetration), and that pair. Pairs are visited in order of a
        lower bound (the distance between their world axis-aligned boxes) and the search stops
        once the bound exceeds the best distance. (inf, None) when no pair is checked."""
        pin = self.pin
        pin.updateGeometryPlacements(self.model, self.data, self.gm, self.gd, np.asarray(q, float))
        lo = np.empty((len(self.owner), 3))
        hi = np.empty((len(self.owner), 3))
        for k, corners in enumerate(self._corners):
            M = self.gd.oMg[k]
            w = corners @ np.asarray(M.rotation).T + np.asarray(M.translation)
            lo[k], hi[k] = w.min(axis=0), w.max(axis=0)
        if not self.pairs:  # nothing to check (e.g. one module, no obstacles): no closest pair
            return math.inf, None
        first = np.array([p[0] for p in self.pairs], dtype=int)
        second = np.array([p[1] for p in self.pairs], dtype=int)
        gap = np.maximum(0.0, np.maximum(lo[second] - hi[first], lo[first] - hi[second]))
        bound = np.sqrt((gap ** 2).sum(axis=1))
        best, which = math.inf, None
        for k in np.argsort(bound, kind="stable"):
            if bound[k] >= best:
                break
            d = float(pin.computeDistance(self.gm, self.gd, int(k)).min_distance)
            if d < best:
                best, which = d, self.gm.collisionPairs[int(k)]
        if which is None:
            return math.inf, None
        return best, self._named([which])[0]

    # -- motions --------------------------------------------------------------------------------
    def reach_radii(self) -> np.ndarray:
        """R_i (m): no point of the robot beyond joint i is farther than R_i from joint i's
        origin (which lies on its axis), in any configuration. Sum of the joint-to-joint
        offsets up to link k plus the farthest collision vertex of link k, maximised over k."""
        model, gm = self.model, self.geo.geom_model
        n = model.nq
        rho = np.zeros(model.njoints)  # farthest geometry point of each joint's body, from its origin
        for go in gm.geometryObjects:
            v = hull_points(go.geometry) @ np.asarray(go.placement.rotation).T + np.asarray(go.placement.translation)
            rho[go.parentJoint] = max(rho[go.parentJoint], float(np.sqrt((v ** 2).sum(axis=1)).max()))
        offset = [float(np.linalg.norm(model.jointPlacements[j].translation)) for j in range(model.njoints)]
        R = np.zeros(n)
        for i in range(1, n + 1):
            best, run = 0.0, 0.0
            for k in range(i, n + 1):
                if k > i:
                    run += offset[k]
                best = max(best, run + rho[k])
            # tool0 and payload are frames, not geometry: nothing to add
            R[i - 1] = best
        return R

    def motion_steps(self, qa, qb, step: float | None = None) -> int:
        """Intervals a straight motion qa -> qb is cut into so that no point moves more than
        `step` (default margin / 2) between checked states."""
        step = self.margin / 2 if step is None else step
        d = float(np.abs(np.asarray(qb, float) - np.asarray(qa, float)) @ self.radii)
        return max(1, math.ceil(d / step))

    def motion_valid(self, qa, qb, check_ends: bool = False) -> bool:
        """Certified straight motion (see the module docstring); states visited in bisection
        order, so that a blocked motion is usually rejected after a few checks."""
        qa, qb = np.asarray(qa, float), np.asarray(qb, float)
        n = self.motion_steps(qa, qb)
        if check_ends and not (self.valid(qa) and self.valid(qb)):
            return False
        for k in bisection_order(n):
            if not self.valid(qa + (qb - qa) * (k / n)):
                return False
        return True


def bisection_order(n: int) -> list[int]:
    """Interior indices 1 … n-1, coarse to fine (midpoint first)."""
    out: list[int] = []
    seen = {0, n}
    queue = [(0, n)]
    while queue:
        nxt = []
        for a, b in queue:
            if b - a < 2:
                continue
            m = (a + b) // 2
            if m not in seen:
                seen.add(m)
                out.append(m)
            nxt += [(a, m), (m, b)]
        queue = nxt
    return out


__all__ = ["DEFAULT_MARGIN", "STATIC_TOLERANCE", "CollisionChecker", "Contact", "bisection_order", "obstacle_geometry"]
