"""URDF backend: urdf/mod<n>_<name>.urdf per robot (SPEC sections 2 and 5)."""
from __future__ import annotations

from .. import __version__
from ..kinematics import matrix_rpy
from ..physical.assembly import Description
from . import Build, register
from .format import num, vec
from .templates import comment, render

# name -> RGBA; parts pick a material by role
MATERIALS = {
    "heavy": (0.20, 0.33, 0.55, 1.0),
    "light": (0.90, 0.50, 0.15, 1.0),
    "twist": (0.75, 0.75, 0.75, 1.0),
    "actuator": (0.12, 0.12, 0.12, 1.0),
    "link": (0.92, 0.92, 0.88, 1.0),
}


def _origin(T) -> dict:
    return {"xyz": vec(T[:3, 3]), "rpy": vec(matrix_rpy(T[:3, :3]))}


def context(desc: Description, robot, source: str, mesh_prefix: str) -> dict:
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


def urdf_text(build: Build, robot, mesh_prefix: str = "../meshes/") -> str:
    return render("urdf.xml.j2", context(build.description(robot), robot, build.source_name, mesh_prefix))


@register("urdf", "URDF per robot: urdf/mod<n>_<name>.urdf")
def emit(build: Build):
    return {f"urdf/{r.file_stem}.urdf": urdf_text(build, r) for r in build.design.robots}
