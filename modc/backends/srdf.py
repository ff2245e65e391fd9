"""SRDF backend: config/mod<n>_<name>.srdf per robot (docs/outputs.md), the MoveIt semantic
description of the URDF the urdf backend emits.

    virtual_joint   fixed, world -> base_link ("virtual_joint")
    group arm       chain base_link -> tool0
    group tool      links tool0 (and payload), plus an end_effector "tool" on the arm's last
                    link -- only when the file declares a tool (offset) or a payload
    group_state     "home" (Robot.home: the pose named home, else MoveIt's default values), then every
                    other named pose
    disable_collisions   the self-collision matrix of modc.physical.collisions: seeded and
                    deterministic, computed with pinocchio + coal on the collision meshes the URDF references
                    (built in memory from the same Description)

Options, read from the Build when present (the CLI sets them), else the defaults:
    build.collision_samples   random configurations for Never/Always (default 10,000; 0 = only
                              Adjacent and Default pairs)
    build.seed                seed of the PCG64 sample stream (default 0)
Warnings (links without collision geometry) are written into the SRDF as XML comments and
returned by warnings(build) for the driver to report.
"""
from __future__ import annotations

from .._version import __version__
from ..model import ResolvedRobot, Transform
from ..physical import collisions
from .build import Build
from .common import BASE_LINK, GROUP, TIP_LINK, TOOL_GROUP, collision_matrix, options
from .format import num
from .registry import register
from .templates import comment, render

# collision_matrix and options: tests and the mjcf backend read them here today
__all__ = ["BASE_LINK", "GROUP", "TIP_LINK", "TOOL_GROUP", "collision_matrix", "emit", "options", "srdf_text",
           "warnings"]

FRAME_LINKS = ("tool0", "payload")  # frames without geometry by design: no warning for them


def robot_warnings(robot: ResolvedRobot, matrix: collisions.CollisionMatrix) -> list[str]:
    out = []
    bare = [link for link in matrix.links_without_geometry if link not in FRAME_LINKS]
    if bare:
        out.append(f"robot {robot.name}: link(s) {', '.join(bare)} have no collision geometry; "
                   "MoveIt cannot check them for collisions")
    if len(matrix.geometry_links) < 2:
        out.append(f"robot {robot.name}: fewer than two links have collision geometry; "
                   "the SRDF disables no collision pairs and MoveIt checks no self-collisions")
    return out


def warnings(build: Build) -> list[str]:
    """Warnings about every robot of the build, one line each (computes the matrices if needed)."""
    return [w for r in build.robots for w in robot_warnings(r, collision_matrix(build, r))]


def has_tool(robot: ResolvedRobot) -> bool:
    return robot.tool != Transform() or robot.payload is not None


def context(build: Build, robot: ResolvedRobot) -> dict:
    desc = build.description(robot)
    matrix = collision_matrix(build, robot)
    joints = [j.name for j in desc.joints if j.kind != "fixed"]
    states = robot.named_poses()
    tool = None
    if has_tool(robot):
        parent = next(j.parent for j in desc.joints if j.child == TIP_LINK)
        links = [TIP_LINK] + [j.child for j in desc.joints if j.parent == TIP_LINK]
        tool = {"group": TOOL_GROUP, "links": links, "parent_link": parent}
    return {
        "name": robot.file_stem, "robot": robot.name, "sequence": robot.sequence, "source": comment(build.source_name),
        "library": comment(robot.library.name), "version": __version__,
        "samples": matrix.samples, "seed": matrix.seed, "always_percent": collisions.ALWAYS_PERCENT,
        "warnings": [comment(w) for w in robot_warnings(robot, matrix)],
        "group": GROUP, "base_link": BASE_LINK, "tip_link": TIP_LINK, "tool": tool,
        "states": [{"name": name, "joints": [{"name": j, "value": num(v)} for j, v in zip(joints, q, strict=True)]}
                   for name, q in states],
        "disabled": [{"link1": p.link1, "link2": p.link2, "reason": p.reason} for p in matrix.disabled],
    }


def srdf_text(build: Build, robot: ResolvedRobot) -> str:
    return render("srdf.xml.j2", context(build, robot))


@register("srdf", "MoveIt SRDF per robot (groups, poses, self-collision matrix): config/mod<n>_<name>.srdf", heavy=True)
def emit(build: Build):
    return {f"config/{r.file_stem}.srdf": srdf_text(build, r) for r in build.robots}
