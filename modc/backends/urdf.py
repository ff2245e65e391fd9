"""URDF backend: urdf/mod<n>_<name>.urdf per robot (docs/conventions.md, docs/outputs.md)."""
from __future__ import annotations

from .build import Build
from .common import urdf_context
from .registry import register
from .templates import render

__all__ = ["emit", "urdf_text"]


def urdf_text(build: Build, robot, mesh_prefix: str = "../meshes/") -> str:
    return render("urdf.xml.j2", urdf_context(build.description(robot), robot, build.source_name, mesh_prefix))


@register("urdf", "URDF per robot: urdf/mod<n>_<name>.urdf")
def emit(build: Build):
    return {f"urdf/{r.file_stem}.urdf": urdf_text(build, r) for r in build.robots}
