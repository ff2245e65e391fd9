"""MJCF backend: mjcf/mod<n>_<name>.xml per robot (docs/outputs.md), a MuJoCo model of the arm in
its cell, made from the same description as the URDF (physical.assembly), never from URDF text.

    bodies      base_link (welded to the world at `base`), link_1 … link_n with hinge joints
                joint_1 … joint_n about z, then tool0 and payload welded on: one body per URDF
                link, with the URDF's inertial (mass, centre of mass, full inertia tensor)
    geoms       the parts' STL meshes (../meshes/, as the URDF), for sight and for contact:
                the same collision geometry the SRDF's matrix was computed on (MuJoCo, like
                PyBullet, collides their convex hulls)
    tool0       a site at the origin of body tool0
    cell        each obstacle a world geom named as in the file; each target a site
                target_<name> (a target may be called tool0); both carried into the world
                through `base`, like `modc sim`
    keyframes   home (Robot.home) first, then every other named pose; ctrl = qpos, so a
                keyframe is held
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

import numpy as np

from .. import __version__
from ..kinematics import matrix_rpy, transform
from ..model import Robot
from ..physical.assembly import Description
from ..physical.cell import OBSTACLE_RGBA, TARGET_RADIUS, TARGET_RGBA
from ..physical.statics import G
from . import Build, register
from .format import num, vec
from .srdf import collision_matrix
from .templates import comment, render
from .urdf import MATERIALS

TIME_STEP = 1e-3  # s, as `modc sim`
ERROR_AT_PEAK = 0.005  # rad of position error at which a servo reaches the actuator's peak torque
ARMATURE = 1e-3  # kg·m², reflected rotor inertia per joint (numerical regularisation, see above)
TOOL_SITE_RADIUS = 0.005  # m
TARGET_PREFIX = "target_"


def derivative_time(robot: Robot) -> float:
    """s: the library's d/p (the paper's 0.05 / 2). Its i is not modelled: a position servo has
    no integral term (the paper's is 0)."""
    assert robot.library is not None
    control = robot.library.control
    return control.d / control.p


def gains(robot: Robot, torque_peak: float) -> tuple[float, float]:
    """(kp N·m/rad, kv N·m·s/rad) of one joint's position servo."""
    kp = torque_peak / ERROR_AT_PEAK
    return kp, kp * derivative_time(robot)


def mesh_name(stem: str, scale_x: float) -> str:
    """Link bars share one unit-length STL; MuJoCo scales per mesh asset, so one asset per length."""
    return stem if scale_x == 1.0 else f"{stem}_{num(scale_x * 1000.0)}mm"


def _placement(T) -> dict:
    return {"pos": vec(T[:3, 3]), "euler": vec(matrix_rpy(T[:3, :3]))}


def _inertial(link) -> dict | None:
    if link.inertial is None:
        return None
    inertia = link.inertial.inertia  # MuJoCo's order: ixx iyy izz ixy ixz iyz
    return {"pos": vec(link.inertial.com), "mass": num(link.inertial.mass),
            "fullinertia": vec(inertia[i, j] for i, j in ((0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)))}


def _bodies(desc: Description, robot: Robot) -> list[dict]:
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
            hinge = {"name": joint.name, "range": vec((joint.limits.lower, joint.limits.upper)),
                     "armature": num(ARMATURE)}
        return {
            "name": name, **_placement(T), "indent": "  " * (depth + 2), "joint": hinge,
            "inertial": _inertial(link),
            "geoms": [{"mesh": mesh_name(v.part.mesh, v.part.scale_x), "material": v.part.color,
                       **_placement(v.T_link_part)} for v in link.visuals],
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


def _cell(robot: Robot) -> tuple[list[dict], list[dict]]:
    """Obstacles (world geoms) and targets (world sites), given in base_link, placed in the world."""
    T_world_base = transform(robot.base.xyz, robot.base.rpy)
    geoms = []
    for ob in robot.obstacles:
        T = T_world_base @ transform(ob.origin.xyz, ob.origin.rpy)
        size = {"box": lambda s: [v / 2.0 for v in s], "sphere": lambda s: [s[0]],
                "cylinder": lambda s: [s[0], s[1] / 2.0]}[ob.shape](ob.size)
        geoms.append({"name": ob.name, "type": ob.shape, "size": vec(size), **_placement(T)})
    sites = [{"name": TARGET_PREFIX + t.name, "pos": vec((T_world_base @ np.array([*t.xyz, 1.0]))[:3]),
              "size": num(TARGET_RADIUS)} for t in robot.targets]
    return geoms, sites


def context(build: Build, robot: Robot) -> dict:
    desc = build.description(robot)
    joints = [j for j in desc.joints if j.kind == "revolute"]
    actuators = []
    for j in joints:
        assert j.limits is not None
        kp, kv = gains(robot, j.limits.effort)
        actuators.append({"name": j.name, "joint": j.name, "kp": num(kp), "kv": num(kv),
                          "forcerange": vec((-j.limits.effort, j.limits.effort)),
                          "ctrlrange": vec((j.limits.lower, j.limits.upper))})
    poses = [("home", robot.home())] + [(p.name, p.q) for p in robot.poses if p.name != "home"]
    obstacles, targets = _cell(robot)
    return {
        "name": robot.file_stem, "robot": robot.name, "sequence": robot.sequence, "source": comment(build.source_name),
        "library": robot.library.name if robot.library else "", "version": __version__,
        "timestep": num(TIME_STEP), "gravity": vec(G),
        "materials": [{"name": k, "rgba": vec(v)} for k, v in MATERIALS.items()]
        + [{"name": "obstacle", "rgba": vec(OBSTACLE_RGBA)}, {"name": "target", "rgba": vec(TARGET_RGBA)}],
        "meshes": _assets(desc), "bodies": _bodies(desc, robot), "obstacles": obstacles, "targets": targets,
        "excludes": [{"body1": p.link1, "body2": p.link2} for p in collision_matrix(build, robot).disabled],
        "actuators": actuators,
        "keys": [{"name": n, "qpos": vec(q)} for n, q in poses],
        "derivative_time": num(derivative_time(robot)), "error_at_peak": num(ERROR_AT_PEAK),
    }


def mjcf_text(build: Build, robot: Robot) -> str:
    return render("mjcf/robot.xml.j2", context(build, robot))


@register("mjcf", "MuJoCo model per robot (tool0 site, cell, keyframes, servos): mjcf/mod<n>_<name>.xml", heavy=True)
def emit(build: Build):
    return {f"mjcf/{r.file_stem}.xml": mjcf_text(build, r) for r in build.design.robots}
