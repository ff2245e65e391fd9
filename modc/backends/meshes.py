"""Meshes backend: meshes/<part>.stl for every part the robots use (referenced relatively)."""
from __future__ import annotations

from ..physical.meshes import stl_bytes
from .build import Build
from .registry import register


@register("meshes", "binary STL meshes of the parts: meshes/*.stl")
def emit(build: Build):
    parts = {}
    for r in build.robots:
        parts.update(build.description(r).parts)
    return {f"meshes/{name}.stl": stl_bytes(part) for name, part in sorted(parts.items())}
