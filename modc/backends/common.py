"""What several backends share, so that no backend imports another (a layer rule, .importlinter in
pyproject.toml): the URDF's rendering context over a physical Description (the urdf backend writes
it with relative mesh paths, the ros backend with package:// URIs), the material colours, MoveIt's
group and frame names, and the per-build self-collision matrix (the srdf, xacro and mjcf backends
read the same one).
"""
from __future__ import annotations

from .._version import __version__
from ..kinematics import matrix_rpy
from ..model import ResolvedRobot
from ..physical import collisions
from ..physical.assembly import Description
from ..physical.parts import MATERIALS
from .build import Build
from .format import num, vec
from .templates import comment

GROUP = "arm"
TOOL_GROUP = "tool"
BASE_LINK = "base_link"
TIP_LINK = "tool0"
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


def collision_matrix(build: Build, robot: ResolvedRobot) -> collisions.CollisionMatrix:
    """The robot's self-collision matrix, computed once per build (every backend shares it)."""
    samples, seed = options(build)
    cache = build.__dict__.setdefault(_CACHE, {})
    key = (robot.name, samples, seed)
    if key not in cache:
        cache[key] = collisions.cached_matrix(build.description(robot), samples, seed)
    return cache[key]


def _origin(T) -> dict:
    return {"xyz": vec(T[:3, 3]), "rpy": vec(matrix_rpy(T[:3, :3]))}


def urdf_context(desc: Description, robot, source: str, mesh_prefix: str) -> dict:
    """Every value urdf.xml.j2 places: the urdf backend renders it with relative mesh paths, the ros
    backend with package:// URIs over its KDL-friendly description."""
    links = []
    for link in desc.links:
        inertial = None
        if link.inertial is not None:
            inertia = link.inertial.inertia
            inertial = {
                "mass": num(link.inertial.mass), "xyz": vec(link.inertial.com),
                "ixx": num(inertia[0, 0]), "ixy": num(inertia[0, 1]), "ixz": num(inertia[0, 2]),
                "iyy": num(inertia[1, 1]), "iyz": num(inertia[1, 2]), "izz": num(inertia[2, 2]),
            }
        visuals = [{
            **_origin(v.T_link_part), "mesh": f"{mesh_prefix}{v.part.mesh}.stl",
            "scale": vec((v.part.scale_x, 1.0, 1.0)) if v.part.scale_x != 1.0 else None,
            "material": v.part.color,
        } for v in link.visuals]
        links.append({"name": link.name, "inertial": inertial, "visuals": visuals})
    joints = []
    for j in desc.joints:
        lim = j.limits
        joints.append({
            "name": j.name, "type": j.kind, "parent": j.parent, "child": j.child, **_origin(j.T_parent_child),
            "limit": None if lim is None else {
                "lower": num(lim.lower), "upper": num(lim.upper), "effort": num(lim.effort),
                "velocity": num(lim.velocity)},
        })
    return {
        "name": robot.file_stem, "robot": robot.name, "sequence": robot.sequence, "source": comment(source),
        "library": comment(robot.library.name), "version": __version__,
        "materials": [{"name": k, "rgba": vec(v)} for k, v in MATERIALS.items()],
        "links": links, "joints": joints,
    }
