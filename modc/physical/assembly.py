"""A backend-neutral description of the assembled arm: URDF-shaped links and joints.

Link i (child of joint_i) carries everything that turns with joint i: unit i's output casing
and link module, and the next unit's twist unit, input casing and actuator housing (they are
bolted to unit i's output). base_link carries unit 1's input side.
"""
from __future__ import annotations

import numpy as np

from ..kinematics import A_J, A_t1, A_t2, transform
from ..model import ResolvedRobot, Transform
from ..records import Record, field
from .inertia import Inertial, combine_groups, local_inertial, sphere
from .parts import Part, unit_mass, unit_parts

PAYLOAD_RADIUS = 0.02  # m: a payload is modelled as a solid sphere this size around its centre of mass
# tool0 is a frame, not a body, but PyBullet gives a link without <inertial> 1 kg and unit
# inertia; a microgram-scale inertial keeps every consumer's dynamics right.
FRAME_MASS = 1e-6
FRAME_RADIUS = 1e-3
BASE_INERTIA_LINK = "base_link_inertia"  # see kdl_root


class Visual(Record, kw_only=False):
    part: Part
    T_link_part: np.ndarray


class Link(Record, kw_only=False, frozen=False):
    name: str
    visuals: list[Visual] = field(default_factory=list)
    inertial: Inertial | None = None


class Limits(Record, kw_only=False):
    lower: float
    upper: float
    effort: float
    velocity: float


class Joint(Record, kw_only=False):
    name: str
    kind: str  # "revolute" | "fixed"
    parent: str
    child: str
    T_parent_child: np.ndarray
    limits: Limits | None = None
    variant: str = ""


class Description(Record, kw_only=False, frozen=False):
    name: str
    links: list[Link]
    joints: list[Joint]
    file_stem: str = ""  # the robot's output name (URDF <robot name>): mod<n>_<name>

    @property
    def parts(self) -> dict[str, Part]:
        """Mesh stem -> a part using it (scaled parts share one unit-length mesh)."""
        out: dict[str, Part] = {}
        for link in self.links:
            for v in link.visuals:
                out.setdefault(v.part.mesh, v.part)
        return dict(sorted(out.items()))

    def fingerprint(self) -> str:
        """A digest of everything the description holds: results computed from it (collision
        matrix, worst-case torques) are cached under it."""
        from .. import cache

        parts: list[str | bytes] = [self.name, self.file_stem]
        for link in self.links:
            parts += [link.name, str(len(link.visuals))]
            for v in link.visuals:
                parts += [repr(v.part), np.asarray(v.T_link_part, float).tobytes()]
            i = link.inertial
            parts += ["-"] if i is None else [repr(float(i.mass)), np.asarray(i.com, float).tobytes(),
                                              np.asarray(i.inertia, float).tobytes()]
        for j in self.joints:
            parts += [j.name, j.kind, j.parent, j.child, j.variant, repr(j.limits),
                      np.asarray(j.T_parent_child, float).tobytes()]
        return cache.key(*parts)

    @property
    def total_mass(self) -> float:
        """Mass of the arm and payload (the tool0 frame's placeholder inertial excluded), summed from
        the links' inertials: deliberately not library_mass(), which it is tested against."""
        return sum(link.inertial.mass for link in self.links if link.inertial is not None and link.name != "tool0")


class _Unit(Record, kw_only=False):
    """What one modular unit contributes, independent of where it sits in the arm."""

    output: tuple[tuple[Part, Inertial], ...]  # carried by the unit's own link, in its joint frame
    input: tuple[tuple[Part, str, Inertial], ...]  # carried by the link before; part frame name
    A_t1: np.ndarray  # unit base -> twist1
    A_J0: np.ndarray  # twist1 -> joint at q = 0
    A_t2: np.ndarray | None  # joint -> twist2 (units with a link module)
    # the parts' local inertials as arrays (masses, centres, inertias), input parts then output
    # parts, and per input part the index of its frame (0 unit, 1 twist1, 2 joint)
    masses: np.ndarray
    centres: np.ndarray
    inertias: np.ndarray
    input_frames: np.ndarray


_UNITS: dict[tuple, tuple[object, _Unit]] = {}  # per library (by identity) and unit settings
_FRAMES = ("unit", "twist1", "joint")


def _unit(lib, variant: str, kind: int, link_length: float, pivot: float, port: float) -> _Unit:
    """Cached: design search describes thousands of arms built from the same few units."""
    key = (id(lib), variant, kind, link_length, pivot, port)
    hit = _UNITS.get(key)
    if hit is not None and hit[0] is lib:  # the library object is kept alive, so its id is not reused
        return hit[1]
    t = lib.units[kind]
    out, inp = [], []
    for p in unit_parts(lib, variant, kind, link_length):
        if p.mesh.startswith(("output_casing", "link_")):
            out.append((p, local_inertial(p)))
        else:
            inp.append((p, p.frame, local_inertial(p)))
    local = [i for _, _, i in inp] + [i for _, i in out]
    unit = _Unit(tuple(out), tuple(inp), A_t1(pivot, t.x01, t.z01), A_J(0.0, t.z12),
                 A_t2(port, link_length) if t.link else None, np.array([i.mass for i in local]),
                 np.array([i.com for i in local]), np.array([i.inertia for i in local]),
                 np.array([_FRAMES.index(f) for _, f, _ in inp]))
    if len(_UNITS) >= 4096:
        _UNITS.clear()
    _UNITS[key] = (lib, unit)
    return unit


_EYE4 = np.eye(4)
_FRAME_INERTIAL = sphere(FRAME_MASS, FRAME_RADIUS, (0.0, 0.0, 0.0))  # shared: inertials are never modified
_NO_TOOL = Transform()


def _link_inertials(units: list[_Unit], frames: list[np.ndarray]) -> list[Inertial]:
    """Every link's inertial (base_link, link_1 … link_n): each unit's input parts moved into
    the link before it (by frames[3 i + k], k its frame index; unit 0's own frame is base_link's,
    so those parts stay), its output parts kept in its joint frame, all links combined at once."""
    m = np.concatenate([u.masses for u in units])
    C = np.concatenate([u.centres for u in units])
    inertia = np.concatenate([u.inertias for u in units])
    moving, which, starts, k = [], [], [0], 0
    for i, u in enumerate(units):
        n_in = len(u.input_frames)
        for j, f in enumerate(u.input_frames.tolist()):
            if i or f:
                moving.append(k + j)
                which.append(3 * i + f)
        starts.append(k + n_in)  # the next link starts with this unit's output parts
        k += len(u.masses)
    if moving:
        T = np.array(frames)[which]
        R = T[:, :3, :3]
        C[moving] = (R @ C[moving][:, :, None])[:, :, 0] + T[:, :3, 3]
        inertia[moving] = R @ inertia[moving] @ R.transpose(0, 2, 1)
    return combine_groups(m, C, inertia, starts)


def describe(robot: ResolvedRobot) -> Description:
    """The assembled arm as links and joints (kinematics: modc.kinematics, docs/conventions.md)."""
    lib = robot.library
    n = robot.dof
    links = [Link("base_link")] + [Link(f"link_{i}") for i in range(1, n + 1)]
    joints: list[Joint] = []
    units: list[_Unit] = []
    frames: list[np.ndarray] = []  # per unit: its base, twist1 and joint (q = 0) frames in the link before it
    T_prev_unit = _EYE4  # unit i's base frame in the link before it
    for i, u in enumerate(robot.units):
        unit = _unit(lib, u.variant, u.kind, robot.link_length(u), u.pivot, u.port if lib.units[u.kind].link else 0.0)
        # Frames of this unit's parts, in the link that carries them.
        T_prev_twist1 = T_prev_unit @ unit.A_t1
        T_prev_joint0 = T_prev_twist1 @ unit.A_J0
        input_side = {"unit": T_prev_unit, "twist1": T_prev_twist1, "joint": T_prev_joint0}
        units.append(unit)
        frames += [T_prev_unit, T_prev_twist1, T_prev_joint0]
        for p, frame, _ in unit.input:
            links[i].visuals.append(Visual(p, input_side[frame]))
        for p, _ in unit.output:
            links[i + 1].visuals.append(Visual(p, _EYE4))
        v = lib.variants[u.variant]
        lo, hi = robot.joint_range(i + 1)
        joints.append(Joint(
            f"joint_{i + 1}", "revolute", links[i].name, links[i + 1].name, T_prev_joint0,
            Limits(lo, hi, v.actuator.torque_peak, v.actuator.velocity), u.variant))
        T_prev_unit = _EYE4 if unit.A_t2 is None else unit.A_t2
    if units:
        for link, inertial in zip(links, _link_inertials(units, frames), strict=True):
            link.inertial = inertial
    links.append(Link("tool0", inertial=_FRAME_INERTIAL))
    tool = robot.tool
    T_last_tool = T_prev_unit if tool == _NO_TOOL else T_prev_unit @ transform(tool.xyz, tool.rpy)
    joints.append(Joint("tool0_joint", "fixed", links[n].name, "tool0", T_last_tool))
    if robot.payload is not None:
        T = np.eye(4)
        T[:3, 3] = robot.payload.com
        links.append(Link("payload", inertial=sphere(robot.payload.mass, PAYLOAD_RADIUS, (0.0, 0.0, 0.0))))
        joints.append(Joint("payload_joint", "fixed", "tool0", "payload", T))
    return Description(robot.name, links, joints, robot.file_stem)


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
    return Description(desc.name, links, [*desc.joints, joint], desc.file_stem)


def library_mass(robot: ResolvedRobot) -> float:
    """What the library says the arm weighs (with payload): the check on describe()'s inertials."""
    lib = robot.library
    m = sum(unit_mass(lib, u.variant, u.kind, robot.link_length(u)) for u in robot.units)
    return m + (robot.payload.mass if robot.payload else 0.0)


