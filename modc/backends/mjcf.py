"""MJCF backend: mjcf/mod<n>_<name>.xml per robot (docs/outputs.md), a MuJoCo model of the arm, and
mjcf/scene_mod<n>_<name>.xml, the arm in its cell, both made from the same description as the URDF
(physical.assembly), never from URDF text.

    bodies      base_link (welded to the world at `base`), link_1 … link_n with hinge joints
                joint_1 … joint_n about z, then tool0 and payload welded on: one body per URDF
                link, with the URDF's inertial (mass, centre of mass, full inertia tensor)
    defaults    MuJoCo Menagerie's layout: a class named after the file (childclass of base_link:
                hinge axis z, no damping, ARMATURE) holding "visual" (mesh geoms, contype =
                conaffinity = 0, group 2: seen, never touched), "collision" (group 3) and one
                servo class per actuator variant ("servo_H": kp, kv, force limit)
    visual      the parts' STL meshes (../meshes/, as the URDF), in their URDF material colours
    collision   the primitives the meshes are made of (physical.parts: cylinders, boxes; a tube
                as the solid cylinder it closes, its bore holds the actuator), each a convex
                MuJoCo primitive: a U-shaped twist bracket collides as its plate and two cheeks,
                not as the solid block of its mesh's convex hull
    tool0       a site at the origin of body tool0
    scene       mjcf/scene_<stem>.xml includes this file and adds floor, light, skybox, a named
                camera, the cell's obstacles and the targets (mjcf_scene.py); this file alone is
                the robot, as Menagerie ships it, and loads by itself
    keyframes   home (Robot.home) first, then every other named pose; ctrl = qpos, so a
                keyframe is held
    numbers     every number written is finite: a library value that makes one infinite (a
                peak torque near the float limit gives kp = inf) is a not-finite diagnostic at
                the robot's `library` statement, and nothing is written
    contact     <exclude> for every pair the SRDF disables (physical.collisions, the same cached
                computation the SRDF backend uses)
    actuators   one position servo per joint, force-limited to the actuator's peak torque

Gains. The paper's decentralised PID [2, 0, 0.05] runs inside the Kinova actuator, in its own
units: read as N·m/rad, p = 2 would let a 3 N·m gravity load sag 1.5 rad. What carries over
unit-free is kept: no integral action (i = 0) and the derivative time d/p = 0.025 s (both read
from the library's `control`). The stiffness is set so that the actuator reaches its peak torque
at ERROR_AT_PEAK of position error: kp = τmax / ERROR_AT_PEAK, kv = kp · d/p (H: 6100 N·m/rad
and 152.5 N·m·s/rad; L: 1360 and 34). A load the actuator can carry then rests within
ERROR_AT_PEAK of its target; one it cannot saturates the servo and falls.
Joints have no damping of their own (kv is the only damper, so the servo's torque is all the
actuator's) and ARMATURE of rotor inertia, which keeps the stiff servos of light distal links
stable at the 1 ms step; neither changes a torque at rest.
"""
from __future__ import annotations

import math

import numpy as np

from .._version import __version__
from ..kinematics import matrix_rpy, transform
from ..model import ResolvedRobot
from ..physical.assembly import Description
from ..physical.constants import GRAVITY_VECTOR, TIME_STEP
from ..physical.parts import Primitive
from . import format as fmt
from .build import Build
from .common import MATERIALS, collision_matrix
from .registry import register
from .templates import comment, render

ERROR_AT_PEAK = 0.005  # rad of position error at which a servo reaches the actuator's peak torque
ARMATURE = 1e-3  # kg·m², reflected rotor inertia per joint (numerical regularisation, see above)
TOOL_SITE_RADIUS = 0.005  # m
TARGET_PREFIX = "target_"
SCENE_PREFIX = "scene_"
VISUAL_GROUP, COLLISION_GROUP = 2, 3  # Menagerie's: the viewer shows 0-2, hides 3


class NotFinite(ValueError):
    """A number that cannot be written into the MJCF (inf or nan)."""


def num(x: float) -> str:
    if not math.isfinite(float(x)):
        raise NotFinite
    return fmt.num(x)


def vec(xs) -> str:
    return " ".join(num(x) for x in xs)


def derivative_time(robot: ResolvedRobot) -> float:
    """s: the library's d/p (the paper's 0.05 / 2). Its i is not modelled: a position servo has
    no integral term (the paper's is 0)."""
    control = robot.library.control
    return control.d / control.p


def gains(robot: ResolvedRobot, torque_peak: float) -> tuple[float, float]:
    """(kp N·m/rad, kv N·m·s/rad) of one joint's position servo."""
    kp = torque_peak / ERROR_AT_PEAK
    return kp, kp * derivative_time(robot)


def mesh_name(stem: str, scale_x: float) -> str:
    """Link bars share one unit-length STL; MuJoCo scales per mesh asset, so one asset per length."""
    return stem if scale_x == 1.0 else f"{stem}_{fmt.num(scale_x * 1000.0)}mm"


def placement(T) -> dict:
    return {"pos": vec(T[:3, 3]), "euler": vec(matrix_rpy(T[:3, :3]))}


def _inertial(link) -> dict | None:
    if link.inertial is None:
        return None
    inertia = link.inertial.inertia  # MuJoCo's order: ixx iyy izz ixy ixz iyz
    return {"pos": vec(link.inertial.com), "mass": num(link.inertial.mass),
            "fullinertia": vec(inertia[i, j] for i, j in ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)))}


def collision_geom(p: Primitive, T_link_part) -> dict:
    """A part's primitive as a MuJoCo primitive in the link frame (cylinders along their z)."""
    T = np.eye(4)
    T[:3, :3] = np.asarray(p.rotation)
    T[:3, 3] = p.center
    T = np.asarray(T_link_part) @ T
    if p.shape == "box":
        return {"type": "box", "size": vec(v / 2.0 for v in p.dims), **placement(T)}
    radius, height = (p.dims[1], p.dims[2]) if p.shape == "tube" else p.dims  # a tube closed: its bore is filled
    return {"type": "cylinder", "size": vec((radius, height / 2.0)), **placement(T)}


def _bodies(desc: Description, robot: ResolvedRobot) -> list[dict]:
    """The kinematic tree as nested bodies (children lists), base_link at the root."""
    links = {link.name: link for link in desc.links}
    by_parent: dict[str, list] = {}
    for j in desc.joints:
        by_parent.setdefault(j.parent, []).append(j)

    def body(name: str, T, joint, depth: int) -> dict:
        link = links[name]
        hinge = None
        if joint is not None and joint.kind == "revolute":
            assert joint.limits is not None
            hinge = {"name": joint.name, "range": vec((joint.limits.lower, joint.limits.upper))}
        return {
            "name": name, **placement(T), "indent": "  " * (depth + 2), "joint": hinge,
            "childclass": robot.file_stem if depth == 0 else None,
            "inertial": _inertial(link),
            "geoms": [{"mesh": mesh_name(v.part.mesh, v.part.scale_x), "material": v.part.color,
                       **placement(v.T_link_part)} for v in link.visuals],
            "collisions": [collision_geom(p, v.T_link_part) for v in link.visuals for p in v.part.primitives],
            "sites": [{"name": "tool0", "size": num(TOOL_SITE_RADIUS)}] if name == "tool0" else [],
            "children": [body(j.child, j.T_parent_child, j, depth + 1) for j in by_parent.get(name, [])],
        }

    return [body("base_link", transform(robot.base.xyz, robot.base.rpy), None, 0)]


def _assets(desc: Description) -> list[dict]:
    seen: dict[str, dict] = {}
    for link in desc.links:
        for v in link.visuals:
            name = mesh_name(v.part.mesh, v.part.scale_x)
            scale = vec((v.part.scale_x, 1.0, 1.0)) if v.part.scale_x != 1.0 else None
            seen.setdefault(name, {"name": name, "file": f"{v.part.mesh}.stl", "scale": scale})
    return [seen[k] for k in sorted(seen)]


def _servos(robot: ResolvedRobot, joints) -> tuple[list[dict], list[dict]]:
    """(servo classes, one per actuator variant; actuators, one per joint). A joint whose peak
    torque differs from its variant's class carries its own gains."""
    classes: dict[str, dict] = {}
    actuators = []
    for j in joints:
        assert j.limits is not None
        gain = _gains_text(robot, j)
        cls = classes.setdefault(j.variant, {"name": f"servo_{j.variant}", **gain})
        own = {k: v for k, v in gain.items() if cls[k] != v}
        actuators.append({"name": j.name, "joint": j.name, "class": cls["name"], "own": own,
                          "ctrlrange": vec((j.limits.lower, j.limits.upper))})
    return list(classes.values()), actuators


def _gains_text(robot: ResolvedRobot, j) -> dict:
    kp, kv = gains(robot, j.limits.effort)
    try:
        return {"kp": num(kp), "kv": num(kv), "forcerange": vec((-j.limits.effort, j.limits.effort))}
    except NotFinite:
        peak = f"{j.limits.effort:.3g} N·m" if math.isfinite(j.limits.effort) else "(not finite)"
        raise NotFinite(f"the MuJoCo servo gain of {j.name} (kp = peak torque {peak} / "
                        f"{ERROR_AT_PEAK:g} rad, kv = kp · d/p)") from None


def context(build: Build, robot: ResolvedRobot) -> dict:
    desc = build.description(robot)
    joints = [j for j in desc.joints if j.kind == "revolute"]
    servo_classes, actuators = _servos(robot, joints)
    poses = robot.named_poses()
    return {
        "name": robot.file_stem, "robot": comment(robot.name), "sequence": comment(robot.sequence),
        "source": comment(build.source_name), "library": comment(robot.library.name),
        "version": __version__, "timestep": num(TIME_STEP), "gravity": vec(GRAVITY_VECTOR),
        "armature": num(ARMATURE), "visual_group": VISUAL_GROUP, "collision_group": COLLISION_GROUP,
        "materials": [{"name": k, "rgba": vec(v)} for k, v in MATERIALS.items()],
        "meshes": _assets(desc), "bodies": _bodies(desc, robot),
        "excludes": [{"body1": p.link1, "body2": p.link2} for p in collision_matrix(build, robot).disabled],
        "servo_classes": servo_classes, "actuators": actuators,
        "keys": [{"name": n, "qpos": vec(q)} for n, q in poses],
        "derivative_time": num(derivative_time(robot)), "error_at_peak": num(ERROR_AT_PEAK),
    }


def mjcf_text(build: Build, robot: ResolvedRobot) -> str:
    return render("mjcf/robot.xml.j2", _finite(robot, lambda: context(build, robot)))


def scene_name(robot: ResolvedRobot) -> str:
    return f"{SCENE_PREFIX}{robot.file_stem}.xml"


def scene_text(build: Build, robot: ResolvedRobot) -> str:
    from .mjcf_scene import scene_context

    return render("mjcf/scene.xml.j2", _finite(robot, lambda: scene_context(build, robot)))


def _finite(robot: ResolvedRobot, make):
    """make(), or a not-finite diagnostic (at the robot's `library` statement, where the number
    comes from, else at the robot) when a number of the model is infinite or not a number."""
    from ..diagnostics import NOWHERE, codes
    from ..diagnostics.errors import InputError

    try:
        return make()
    except NotFinite as e:
        what = str(e) or f"every number of robot {robot.name}'s MuJoCo model"
        span = robot.library_span if robot.library_span != NOWHERE else robot.span
        raise InputError(codes.NOT_FINITE.at(span, what=what)) from None


@register("mjcf", "MuJoCo model per robot (tool0 site, keyframes, servos; visual and collision geoms) and its "
                  "scene (floor, light, camera, cell, targets): mjcf/mod<n>_<name>.xml, mjcf/scene_mod<n>_<name>.xml",
          heavy=True)
def emit(build: Build):
    files = {}
    for r in build.robots:
        files[f"mjcf/{r.file_stem}.xml"] = mjcf_text(build, r)
        files[f"mjcf/{scene_name(r)}"] = scene_text(build, r)
    return files
