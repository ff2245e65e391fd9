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
from typing import TYPE_CHECKING

import numpy as np

from ..kinematics import Rz, homogeneous, transform
from ..model import Robot
from ..physical.assembly import describe
from ..physical.meshes import tessellate
from ..physical.parts import Part

if TYPE_CHECKING:
    from ..dynamics.model import Dynamics

# Part role -> RGB 0..255, the URDF's materials (one palette for every view of the arm).
OBSTACLE_RGB = (158, 178, 199)
TARGET_RGB = (219, 31, 56)
TARGET_RADIUS = 0.012  # m, as `modc render` marks a target
# Gravity torque against the actuator: within nominal, above nominal, above peak (modc check's levels).
LEVEL_RGB = {"ok": (46, 160, 67), "over-nominal": (230, 140, 20), "over-peak": (215, 40, 40)}


def part_rgb(part: Part) -> tuple[int, int, int]:
    from ..backends.urdf import MATERIALS

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


def _shape(link: str, k: int, part: Part, T_link_part: np.ndarray) -> Shape:
    vertices, faces, _ = tessellate(part)  # the URDF's mesh of the part (normals: the viewer's own)
    v = np.array(vertices, dtype=np.float64)
    v[:, 0] *= part.scale_x  # link bars are meshed 1 m long, as the URDF scales them
    v = v @ T_link_part[:3, :3].T + T_link_part[:3, 3]
    return Shape(link, f"{part.mesh}_{k}", v.astype(np.float32), np.asarray(faces, dtype=np.uint32), part_rgb(part))


class Arm:
    def __init__(self, robot: Robot):
        self.robot = robot
        self.description = describe(robot)
        self.dof = robot.dof
        self.joint_names = [f"joint_{i}" for i in range(1, self.dof + 1)]
        self.limits = [robot.joint_range(i) for i in range(1, self.dof + 1)]
        self.T_world_base = transform(robot.base.xyz, robot.base.rpy)
        self._dynamics: Dynamics | None = None

    @property
    def poses(self) -> list[tuple[str, tuple[float, ...]]]:
        """Named poses, home first (Robot.home: the declared one, else MoveIt's default)."""
        return [("home", self.robot.home())] + [(p.name, tuple(p.q)) for p in self.robot.poses if p.name != "home"]

    def shapes(self) -> list[Shape]:
        return [_shape(link.name, k, v.part, v.T_link_part)
                for link in self.description.links for k, v in enumerate(link.visuals)]

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
        from ..dynamics.worst import JointWorst

        if self._dynamics is None:
            from ..dynamics.model import Dynamics

            self._dynamics = Dynamics(self.robot)  # pinocchio: built on first use, kept for the arm's life
        tau = self._dynamics.gravity(q)
        lib = self.robot.library
        assert lib is not None
        out = []
        for i, u in enumerate(self.robot.units):
            act = lib.variants[u.variant].actuator
            # JointWorst.level is modc check's one rule for ok / over-nominal / over-peak
            name, nom, peak = self.joint_names[i], act.torque_nominal, act.torque_peak
            level = JointWorst(name, u.variant, abs(float(tau[i])), tuple(q), nom, peak).level
            out.append(JointTorque(name, u.name, float(tau[i]), nom, peak, level))
        return out

