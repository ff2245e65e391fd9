"""SRDF backend: config/mod<n>_<name>.srdf per robot (SPEC section 5), the MoveIt semantic
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

from .. import __version__
from ..model import Robot, Transform
from ..physical import collisions
from . import Build, register
from .format import num
from .templates import comment, render

GROUP = "arm"
TOOL_GROUP = "tool"
BASE_LINK = "base_link"
TIP_LINK = "tool0"
FRAME_LINKS = ("tool0", "payload")  # frames without geometry by design: no warning for them
_CACHE = "_srdf_collision_matrices"


def options(build: Build) -> tuple[int, int]:
    """(samples, seed) for this build: attributes set by the driver, else the defaults."""
    samples = getattr(build, "collision_samples", None)
    seed = getattr(build, "seed", None)
    samples = collisions.DEFAULT_SAMPLES if samples is None else int(samples)
    seed = collisions.DEFAULT_SEED if seed is None else int(seed)
    if samples < 0 or seed < 0:
        raise ValueError(f"collision samples and seed must be >= 0 (got {samples}, {seed})")
    return samples, seed


def collision_matrix(build: Build, robot: Robot) -> collisions.CollisionMatrix:
    """The robot's self-collision matrix, computed once per build (emit and warnings share it)."""
    samples, seed = options(build)
    cache = build.__dict__.setdefault(_CACHE, {})
    key = (robot.name, samples, seed)
    if key not in cache:
        cache[key] = collisions.cached_matrix(build.description(robot), samples, seed)
    return cache[key]


def robot_warnings(robot: Robot, matrix: collisions.CollisionMatrix) -> list[str]:
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
    return [w for r in build.design.robots for w in robot_warnings(r, collision_matrix(build, r))]


def has_tool(robot: Robot) -> bool:
    return robot.tool != Transform() or robot.payload is not None


def context(build: Build, robot: Robot) -> dict:
    desc = build.description(robot)
    matrix = collision_matrix(build, robot)
    joints = [j.name for j in desc.joints if j.kind != "fixed"]
    states = [("home", robot.home())] + [(p.name, p.q) for p in robot.poses if p.name != "home"]
    tool = None
    if has_tool(robot):
        parent = next(j.parent for j in desc.joints if j.child == TIP_LINK)
        links = [TIP_LINK] + [j.child for j in desc.joints if j.parent == TIP_LINK]
        tool = {"group": TOOL_GROUP, "links": links, "parent_link": parent}
    assert robot.library is not None  # resolved before any backend runs
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


def srdf_text(build: Build, robot: Robot) -> str:
    return render("srdf.xml.j2", context(build, robot))


@register("srdf", "MoveIt SRDF per robot (groups, poses, self-collision matrix): config/mod<n>_<name>.srdf", heavy=True)
def emit(build: Build):
    return {f"config/{r.file_stem}.srdf": srdf_text(build, r) for r in build.design.robots}
