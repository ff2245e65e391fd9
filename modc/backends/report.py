"""report.json: a machine-readable account of the compile (robots, joints, outputs, warnings)."""
from __future__ import annotations

import json

from .._version import __version__
from ..dh.report import compare
from ..files import REPORT
from ..kinematics import Chain
from ..physical.assembly import library_mass
from .build import Build
from .format import num
from .registry import register


def _r(x: float) -> float:
    return float(num(x))


def robot_report(build: Build, robot) -> dict:
    desc = build.description(robot)
    chain = Chain(robot)
    T = chain.T_base_tool(robot.home())
    return {
        "name": robot.name,
        "dof": robot.dof,
        "sequence": robot.sequence,
        "library": robot.library.name,
        "urdf": f"urdf/{robot.file_stem}.urdf",
        "mass": _r(desc.total_mass),
        "library_mass": _r(library_mass(robot)),
        "joints": [{
            "name": j.name, "variant": j.variant, "lower": _r(j.limits.lower), "upper": _r(j.limits.upper),
            "effort": _r(j.limits.effort), "velocity": _r(j.limits.velocity),
        } for j in desc.joints if j.limits is not None],
        "poses": {p.name: [_r(x) for x in p.q] for p in robot.poses},
        "tool0_at_home": [_r(x) for x in T[:3, 3]],
        "targets": {t.name: [_r(x) for x in t.xyz] for t in robot.targets},
        "dh": compare(robot),  # realised standard DH at q = 0 (and the requested table, if any)
        "torque": None if robot.torque is None else [j.to_json() for j in robot.torque],
    }


@register("report", "report.json: robots, joints, masses, outputs and warnings",
          reads=("meshes", "urdf", "srdf", "mjcf", "ros", "xacro"))
def emit(build: Build):
    outputs = sorted([*build.files, REPORT])
    doc = {
        "generator": f"modc {__version__}",
        "source": build.source_name,
        "robots": [robot_report(build, r) for r in build.robots],
        "diagnostics": [d.to_json() for d in build.diagnostics],
        "outputs": outputs,
    }
    return {REPORT: json.dumps(doc, indent=2) + "\n"}
