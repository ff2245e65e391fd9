"""One checked robot as the live view shows it: its shapes, the pose of every link for joint
values q, tool0, and the gravity torque of each joint against its actuator.

Geometry comes from the in-memory physical model (physical.assembly.describe) and the same
part tessellation the URDF's STL files are written from (physical.meshes.tessellate), so the page
shows exactly what modc emits.
Frames: obstacles, targets and tool0 are in base_link (as the file gives them); the page puts
base_link at robot.base in the cell frame (T_world_base), as `modc sim` does.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from ..diagnostics import Diagnostic
from ..kinematics import Rz, homogeneous, transform
from ..model import ResolvedRobot
from ..physical.assembly import describe
from ..physical.cell import OBSTACLE_RGBA, TARGET_RGBA
from ..physical.meshes import tessellate
from ..physical.parts import Part

if TYPE_CHECKING:
    from ..dynamics.model import Dynamics
    from ..physical.checker import CollisionChecker, Contact


def rgb255(rgba) -> tuple[int, int, int]:
    return (round(rgba[0] * 255), round(rgba[1] * 255), round(rgba[2] * 255))


# The cell as every other picture and model shows it (physical/cell.py).
OBSTACLE_RGB = rgb255(OBSTACLE_RGBA)
TARGET_RGB = rgb255(TARGET_RGBA)
PAYLOAD_RGB = (96, 160, 96)
TOOL_RGB = (110, 110, 110)
# Gravity torque against the actuator: within nominal, above nominal, above peak (modc check's levels).
LEVEL_RGB = {"ok": (46, 160, 67), "over-nominal": (230, 140, 20), "over-peak": (215, 40, 40)}
COLLISION_RGB = LEVEL_RGB["over-peak"]  # links in contact
# A module named by a diagnostic: errors magenta (apart from the red of a contact), warnings amber.
NAMED_RGB = {"error": (200, 40, 200), "warning": LEVEL_RGB["over-nominal"]}
AXES = 0.05  # m: length of the tool0 and target orientation axes drawn
OUTPUT_PARTS = ("output_casing", "link_")  # physical.assembly: these ride on their own unit's link


def part_rgb(part: Part) -> tuple[int, int, int]:
    from ..physical.parts import MATERIALS

    r, g, b, _ = MATERIALS.get(part.color, (0.6, 0.6, 0.6, 1.0))
    return (round(r * 255), round(g * 255), round(b * 255))


@dataclass(frozen=True)
class Shape:
    """One coloured mesh fixed to a link."""

    link: str
    name: str
    vertices: np.ndarray  # (m, 3) float32, in the link frame
    faces: np.ndarray  # (k, 3) uint32
    rgb: tuple[int, int, int]
    unit: int  # index of the module (robot.units) the part belongs to


@dataclass(frozen=True)
class JointTorque:
    name: str
    unit: str  # the module's name in the chain, e.g. L4
    tau: float  # N·m, gravity torque at the current pose (signed)
    tau_nom: float
    tau_max: float
    level: str  # "ok" | "over-nominal" | "over-peak"

    @property
    def rgb(self) -> tuple[int, int, int]:
        return LEVEL_RGB[self.level]


def _shape(link: str, k: int, part: Part, T_link_part: np.ndarray, unit: int) -> Shape:
    vertices, faces, _ = tessellate(part)  # the URDF's mesh of the part (normals: the viewer's own)
    v = np.array(vertices, dtype=np.float64)
    v[:, 0] *= part.scale_x  # link bars are meshed 1 m long, as the URDF scales them
    v = v @ T_link_part[:3, :3].T + T_link_part[:3, 3]
    return Shape(link, f"{part.mesh}_{k}", v.astype(np.float32), np.asarray(faces, dtype=np.uint32), part_rgb(part),
                 unit)


class Arm:
    def __init__(self, robot: ResolvedRobot):
        self.robot = robot
        self.description = describe(robot)
        self.dof = robot.dof
        self.joint_names = [f"joint_{i}" for i in range(1, self.dof + 1)]
        self.limits = [robot.joint_range(i) for i in range(1, self.dof + 1)]
        self.T_world_base = transform(robot.base.xyz, robot.base.rpy)
        self._dynamics: Dynamics | None = None
        self._checker: CollisionChecker | None = None
        self._shapes: list[Shape] | None = None
        self._static: list[Contact] = []  # base_link against the obstacles: the same in every pose

    @property
    def poses(self) -> list[tuple[str, tuple[float, ...]]]:
        """Named poses, home first (ResolvedRobot.named_poses)."""
        return self.robot.named_poses()

    def shapes(self) -> list[Shape]:
        """Every part's mesh on its link. Link i carries unit i's output parts and unit i+1's
        input side (physical.assembly), so a part's module follows from its link and its kind."""
        if self._shapes is not None:
            return self._shapes
        out = []
        for i, link in enumerate(self.description.links[: self.dof + 1]):
            for k, v in enumerate(link.visuals):
                unit = i - 1 if v.part.mesh.startswith(OUTPUT_PARTS) else i
                out.append(_shape(link.name, k, v.part, v.T_link_part, unit))
        self._shapes = out
        return out

    def extent(self, q) -> np.ndarray:
        """Points (world) whose bounding box is what a picture of the arm at q with its cell shows:
        the corners of every part's box, of every obstacle's box, the targets and region points, the
        payload."""
        from ..physical.assembly import PAYLOAD_RADIUS
        from ..physical.cell import TARGET_RADIUS

        signs = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], dtype=float)
        T = self.link_poses(q)
        pts = []
        for s in self.shapes():
            lo, hi = s.vertices.min(axis=0), s.vertices.max(axis=0)
            box = (lo + hi) / 2 + signs * (hi - lo) / 2
            pts.append(box @ T[s.link][:3, :3].T + T[s.link][:3, 3])
        for ob in self.robot.obstacles:
            half = {"box": lambda z: np.array(z) / 2, "sphere": lambda z: np.array([z[0]] * 3),
                    "cylinder": lambda z: np.array([z[0], z[0], z[1] / 2])}[ob.shape](ob.size)
            T_ob = transform(ob.origin.xyz, ob.origin.rpy)
            pts.append((signs * half) @ T_ob[:3, :3].T + T_ob[:3, 3])
        marks: list[tuple[Any, float]] = [(t.xyz, TARGET_RADIUS) for t in self.robot.targets]
        marks += [(p.xyz, TARGET_RADIUS) for r in self.robot.regions for p in r.points()]
        marks.append((T["tool0"][:3, 3], AXES))
        if "payload" in T:
            marks.append((T["payload"][:3, 3], PAYLOAD_RADIUS))
        pts += [np.asarray(c) + signs * r for c, r in marks]
        local = np.concatenate(pts)
        return local @ self.T_world_base[:3, :3].T + self.T_world_base[:3, 3]

    def unit_named(self, d: Diagnostic) -> int | None:
        """The module a diagnostic points at (its span lies within the module's text in the chain)."""
        s = d.span
        for i, u in enumerate(self.robot.units):
            t = u.span
            if t.file == s.file and t.line > 0 and (t.line, t.col) <= (s.line, s.col) and \
                    (s.end_line, s.end_col) <= (t.end_line, t.end_col):
                return i
        return None

    def tool_segment(self) -> tuple[np.ndarray, np.ndarray]:
        """The tool as drawn: from the last module's flange to tool0, in the last link's frame."""
        joint = next(j for j in self.description.joints if j.child == "tool0")
        T_tool = transform(self.robot.tool.xyz, self.robot.tool.rpy)
        flange = joint.T_parent_child @ np.linalg.inv(T_tool)
        return flange[:3, 3], joint.T_parent_child[:3, 3]

    def contacts(self, q) -> list[Contact]:
        """What touches at q, by the compiler's collision model: the URDF's collision meshes, the
        SRDF's disabled pairs, the file's obstacles (modc.physical.checker, as `modc plan` checks)."""
        if self._checker is None:
            from ..physical.checker import CollisionChecker

            self._checker = CollisionChecker(self.robot)  # built on first use, kept for the arm's life
            self._static = self._checker.static_contacts()
        return self._static + self._checker.contacts(q)

    def clamp(self, q) -> tuple[float, ...]:
        return tuple(float(min(max(x, lo), hi)) for x, (lo, hi) in zip(q, self.limits, strict=True))

    def link_poses(self, q) -> dict[str, np.ndarray]:
        """Link name -> T_base_link for joint values q (rad): the description's joints, revolute about z."""
        q = list(q)
        if len(q) != self.dof:
            raise ValueError(f"expected {self.dof} joint values, got {len(q)}")
        T = {"base_link": np.eye(4)}
        k = 0
        for j in self.description.joints:
            T_parent_child = j.T_parent_child
            if j.kind == "revolute":
                T_parent_child = T_parent_child @ homogeneous(Rz(q[k]), (0.0, 0.0, 0.0))
                k += 1
            T[j.child] = T[j.parent] @ T_parent_child
        return T

    def tool0(self, q) -> np.ndarray:
        """tool0's position in base_link, m."""
        return self.link_poses(q)["tool0"][:3, 3]

    def torques(self, q) -> list[JointTorque]:
        """Gravity torque of every joint holding the arm (and payload) still at q."""
        from ..dynamics.torque import JointWorst

        if self._dynamics is None:
            from ..dynamics.model import Dynamics

            self._dynamics = Dynamics(self.robot)  # pinocchio: built on first use, kept for the arm's life
        tau = self._dynamics.gravity(q)
        lib = self.robot.library
        out = []
        for i, u in enumerate(self.robot.units):
            act = lib.variants[u.variant].actuator
            # JointWorst.level is modc check's one rule for ok / over-nominal / over-peak
            name, nom, peak = self.joint_names[i], act.torque_nominal, act.torque_peak
            level = JointWorst(name, u.variant, abs(float(tau[i])), tuple(q), nom, peak).level
            out.append(JointTorque(name, u.name, float(tau[i]), nom, peak, level))
        return out

