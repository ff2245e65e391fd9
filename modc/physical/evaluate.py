"""The fast path for design search: one candidate arm, evaluated in memory.

    arm = Candidate(robot)            # Description + pinocchio Model (~0.3-0.4 ms for 6 DoF)
    arm.tool(q)                       # T_base_tool, 4x4 (FK of tool0)
    arm.gravity(q)                    # g(q): the joint torques holding the arm still, N·m
    arm.collides(q)                   # any self- or environment collision at q
    evaluate(robot, q)                # tool pose, g(q) and collision at once: an Evaluation
                                      # (~1 ms for 6 DoF; benchmarks/bench_compile.py)

Everything comes from the same Description the URDF backend renders (modc.physical.assembly)
and the same pinocchio model and collision meshes the analyses use (modc.physical.multibody),
so a design the search ranks first compiles to exactly the arm it evaluated. Nothing is
written or parsed; coal's BVH models are built once per part and shared by every candidate.

Collisions at one pose are judged by the rule of CollisionMatrix.unchecked (physical/collisions.py)
without its sampling, which costs too much per candidate: pairs of links
joined by a joint (after collapsing links without geometry) never count, nor do pairs that
touch in the default configuration (MoveIt's default joint values: touching by construction);
every other pair of links, and every link but base_link against every obstacle of the file,
does. base_link against an obstacle is the same in every pose, so it is not counted here (the
planner's CollisionChecker.static_contacts reports it). Only "Always" pairs, which need the
samples, are counted here and skipped by the rule: tests/test_evaluate.py compares both on arms
without them. The collision model is built on the
first query (about 0.4 ms), so arms rejected on reach or torque never pay for it.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..model import ResolvedRobot
from . import multibody
from .assembly import Description, describe
from .collisions import SPHERE_MARGIN, adjacent_pairs, default_configuration


@dataclass(frozen=True)
class Evaluation:
    T_base_tool: np.ndarray  # 4x4, tool0 in base_link
    tau_gravity: np.ndarray  # (n,) N·m, g(q)
    collision: bool


class Candidate:
    """One arm: its pinocchio model now, its collision model on the first collision query."""

    def __init__(self, robot: ResolvedRobot, desc: Description | None = None):
        import pinocchio as pin

        self.pin = pin
        self.robot = robot
        self.desc = describe(robot) if desc is None else desc
        self.model = multibody.model(self.desc, gravity=multibody.gravity(robot))
        self.data = self.model.createData()
        self.tool_frame = self.model.getFrameId("tool0")
        self._geometry: _Collisions | None = None

    def tool(self, q) -> np.ndarray:
        pin = self.pin
        pin.forwardKinematics(self.model, self.data, np.asarray(q, float))
        return np.array(pin.updateFramePlacement(self.model, self.data, self.tool_frame).homogeneous)

    def gravity(self, q) -> np.ndarray:
        return np.array(self.pin.computeGeneralizedGravity(self.model, self.data, np.asarray(q, float)))

    def collides(self, q) -> bool:
        """Any counted pair (see the module docstring) in collision at q: coal on the meshes,
        after a bounding-sphere filter (a sphere contains its mesh, so spheres apart means
        meshes apart: the filter changes no answer)."""
        return self._collisions().first(self, np.asarray(q, float)) is not None

    def _collisions(self) -> _Collisions:
        if self._geometry is None:
            self._geometry = _Collisions(self)
        return self._geometry

    def placements(self, q) -> tuple[np.ndarray, np.ndarray]:
        """World rotation (njoints, 3, 3) and translation (njoints, 3) of every joint frame at q."""
        self.pin.forwardKinematics(self.model, self.data, np.asarray(q, float))
        oMi = self.data.oMi
        R = np.array([oMi[j].rotation for j in range(self.model.njoints)])
        p = np.array([oMi[j].translation for j in range(self.model.njoints)])
        return R, p


class _Collisions:
    """The counted pairs of one arm and the bodies they are made of (meshes placed on joints,
    obstacles on the universe), as arrays for a vectorised sphere filter."""

    def __init__(self, arm: Candidate):
        import coal

        self.coal = coal
        self.request = coal.CollisionRequest()
        frames = multibody.link_frames(arm.desc)
        names: list[str] = []  # owners: links with geometry, then obstacles
        owner, joints, Ts, shapes, centers, radii = [], [], [], [], [], []
        for link in arm.desc.links:
            if not link.visuals:
                continue
            joint, M = frames[link.name]
            names.append(link.name)
            for v in link.visuals:
                shape, c, r = multibody.collision_mesh(v.part)
                owner.append(len(names) - 1)
                joints.append(joint)
                Ts.append(v.T_link_part if M is multibody.EYE4 else M @ v.T_link_part)
                shapes.append(shape)
                centers.append(c)
                radii.append(r)
        n_links = len(names)
        for o in arm.robot.obstacles:
            g, M = multibody.obstacle_geometry(o)
            names.append(o.name)
            owner.append(len(names) - 1)
            joints.append(0)
            Ts.append(M.homogeneous)
            shapes.append(g)
            centers.append(np.zeros(3))
            radii.append(_obstacle_radius(o))
        T = np.array(Ts)
        self.names, self.shapes = names, shapes
        self.owner, self.joints = np.array(owner), np.array(joints)
        self.R, self.p = T[:, :3, :3], T[:, :3, 3]
        self.centers = np.einsum("kij,kj->ki", self.R, np.array(centers)) + self.p  # in the joint frames
        self.radii = np.array(radii)
        links = tuple(link.name for link in arm.desc.links)
        has = set(names[:n_links])
        adjacent = adjacent_pairs(links, [(j.parent, j.child) for j in arm.desc.joints], lambda name: name in has)
        counted = np.zeros((len(names), len(names)), bool)  # counted[a, b], a < b
        for a in range(n_links):
            for b in range(a + 1, n_links):
                counted[a, b] = frozenset((names[a], names[b])) not in adjacent
        counted[:n_links, n_links:] = True
        counted[names.index(multibody.ROOT) if multibody.ROOT in has else [], n_links:] = False  # fixed: static
        self.counted = counted
        # pairs touching in the default configuration touch by construction (the SRDF's "Default")
        q0 = default_configuration(arm.model.lowerPositionLimit, arm.model.upperPositionLimit)
        for a, b in self._hits(*arm.placements(q0), first=False):
            if b < n_links:
                counted[a, b] = False
        self.first_body, self.second_body = self._body_pairs()

    def _body_pairs(self) -> tuple[np.ndarray, np.ndarray]:
        o = self.owner
        first, second = np.nonzero(self.counted[o[:, None], o[None, :]])
        return first, second

    def first(self, arm: Candidate, q: np.ndarray) -> tuple[str, str] | None:
        hits = self._hits(*arm.placements(q), first=True)
        return (self.names[hits[0][0]], self.names[hits[0][1]]) if hits else None

    def _hits(self, R: np.ndarray, p: np.ndarray, first: bool) -> list[tuple[int, int]]:
        """Owner pairs in collision with the joints placed at (R, p): all of them, or the first."""
        first_body, second_body = self._body_pairs() if not first else (self.first_body, self.second_body)
        if not len(first_body):
            return []
        j = self.joints
        centers = np.einsum("kij,kj->ki", R[j], self.centers) + p[j]
        d2 = ((centers[first_body] - centers[second_body]) ** 2).sum(axis=1)
        reach = self.radii[first_body] + self.radii[second_body] + SPHERE_MARGIN
        near = np.flatnonzero(d2 <= reach ** 2)
        placed: dict[int, Any] = {}
        hits: list[tuple[int, int]] = []
        for k in near.tolist():
            a, b = int(first_body[k]), int(second_body[k])
            pair = (int(self.owner[a]), int(self.owner[b]))
            if pair in hits:
                continue
            for m in (a, b):
                if m not in placed:
                    Rj = R[j[m]]
                    placed[m] = self.coal.Transform3s(Rj @ self.R[m], Rj @ self.p[m] + p[j[m]])
            if self.coal.collide(self.shapes[a], placed[a], self.shapes[b], placed[b], self.request,
                                 self.coal.CollisionResult()):
                hits.append(pair)
                if first:
                    break
        return hits


def _obstacle_radius(o) -> float:
    s = [float(x) for x in o.size]
    if o.shape == "box":
        return 0.5 * float(np.linalg.norm(s[:3]))
    if o.shape == "sphere":
        return s[0]
    return float(np.hypot(s[0], s[1] / 2))  # cylinder: radius, length


def evaluate(robot: ResolvedRobot, q) -> Evaluation:
    """Tool pose, gravity torques and collision of one arm at one pose, from scratch."""
    arm = Candidate(robot)
    return Evaluation(arm.tool(q), arm.gravity(q), arm.collides(q))


__all__ = ["Candidate", "Evaluation", "evaluate"]
