"""A backend-neutral description of the assembled arm: URDF-shaped links and joints.

Link i (child of joint_i) carries everything that turns with joint i: unit i's output casing
and link module, and the next unit's twist unit, input casing and actuator housing (they are
bolted to unit i's output). base_link carries unit 1's input side.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..kinematics import Chain, A_J
from ..model import Robot
from .inertia import Inertial, combine, part_inertial, sphere
from .parts import Part, unit_parts

PAYLOAD_RADIUS = 0.02  # m: a payload is modelled as a solid sphere this size around its centre of mass
# tool0 is a frame, not a body, but PyBullet gives a link without <inertial> 1 kg and unit
# inertia; a microgram-scale inertial keeps every consumer's dynamics right.
FRAME_MASS = 1e-6
FRAME_RADIUS = 1e-3
BASE_INERTIA_LINK = "base_link_inertia"  # see kdl_root


@dataclass(frozen=True)
class Visual:
    part: Part
    T_link_part: np.ndarray


@dataclass
class Link:
    name: str
    visuals: list[Visual] = field(default_factory=list)
    inertial: Inertial | None = None


@dataclass(frozen=True)
class Limits:
    lower: float
    upper: float
    effort: float
    velocity: float


@dataclass(frozen=True)
class Joint:
    name: str
    kind: str  # "revolute" | "fixed"
    parent: str
    child: str
    T_parent_child: np.ndarray
    limits: Limits | None = None
    variant: str = ""


@dataclass
class Description:
    name: str
    links: list[Link]
    joints: list[Joint]

    @property
    def parts(self) -> dict[str, Part]:
        """Mesh stem -> a part using it (scaled parts share one unit-length mesh)."""
        out: dict[str, Part] = {}
        for link in self.links:
            for v in link.visuals:
                out.setdefault(v.part.mesh, v.part)
        return dict(sorted(out.items()))

    @property
    def total_mass(self) -> float:
        """Mass of the arm and payload (the tool0 frame's placeholder inertial excluded)."""
        return sum(l.inertial.mass for l in self.links if l.inertial is not None and l.name != "tool0")


def describe(robot: Robot) -> Description:
    lib = robot.library
    assert lib is not None
    chain = Chain(robot)
    n = robot.dof
    links = [Link("base_link")] + [Link(f"link_{i}") for i in range(1, n + 1)]
    joints: list[Joint] = []
    for i, u in enumerate(robot.units):
        parts = unit_parts(lib, u.variant, u.kind, robot.link_length(u))
        # Frames of this unit's parts, in the link that carries them.
        T_prev_unit = np.eye(4) if i == 0 else chain.T_joint_end(i - 1)
        T_prev_twist1 = T_prev_unit @ chain.T_unit_twist1(i)
        T_prev_joint0 = T_prev_twist1 @ A_J(0.0, chain.units[i].z12)
        input_side = {"unit": T_prev_unit, "twist1": T_prev_twist1, "joint": T_prev_joint0}
        for p in parts:
            if p.mesh.startswith(("output_casing", "link_")):
                links[i + 1].visuals.append(Visual(p, np.eye(4)))
            else:
                links[i].visuals.append(Visual(p, input_side[p.frame]))
        v = lib.variants[u.variant]
        lo, hi = robot.joint_range(i + 1)
        joints.append(Joint(
            f"joint_{i + 1}", "revolute", links[i].name, links[i + 1].name, chain.T_parent_joint(i),
            Limits(lo, hi, v.actuator.torque_peak, v.actuator.velocity), u.variant))
    for link in links:
        if link.visuals:
            link.inertial = combine([part_inertial(v.part, v.T_link_part) for v in link.visuals])
    links.append(Link("tool0", inertial=sphere(FRAME_MASS, FRAME_RADIUS, (0.0, 0.0, 0.0))))
    joints.append(Joint("tool0_joint", "fixed", links[n].name, "tool0", chain.T_last_tool()))
    if robot.payload is not None:
        T = np.eye(4)
        T[:3, 3] = robot.payload.com
        links.append(Link("payload", inertial=sphere(robot.payload.mass, PAYLOAD_RADIUS, (0.0, 0.0, 0.0))))
        joints.append(Joint("payload_joint", "fixed", "tool0", "payload", T))
    return Description(robot.name, links, joints)


def kdl_root(desc: Description) -> Description:
    """The same arm with an inertia-free root: base_link's mass on a fixed child base_link_inertia
    at the same frame, as ur_description does. KDL (robot_state_publisher, MoveIt) ignores a root
    link's inertia and warns about it; PyBullet gives a link without <inertial> 1 kg, so only the
    ROS description takes this form. The total mass is unchanged."""
    base = desc.links[0]
    if base.inertial is None:
        return desc
    links = [Link(base.name, list(base.visuals)), *desc.links[1:], Link(BASE_INERTIA_LINK, inertial=base.inertial)]
    joint = Joint(f"{BASE_INERTIA_LINK}_joint", "fixed", base.name, BASE_INERTIA_LINK, np.eye(4))
    return Description(desc.name, links, [*desc.joints, joint])


def library_mass(robot: Robot) -> float:
    """What the library says the arm weighs (with payload): the check on describe()'s inertials."""
    lib = robot.library
    assert lib is not None
    m = sum(p.mass for u in robot.units for p in unit_parts(lib, u.variant, u.kind, robot.link_length(u)))
    return m + (robot.payload.mass if robot.payload else 0.0)


