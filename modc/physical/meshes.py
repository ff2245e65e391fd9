"""Binary STL meshes of the parts, made with trimesh and cached on disk by content.

trimesh takes most of a second to import, so generated files are kept in the user cache
(keyed by the primitives' numbers): later compiles copy bytes and never import it.
"""
from __future__ import annotations

import numpy as np

from .. import cache
from .parts import Part, mesh_primitives

SECTIONS = 48
_VERSION = "1"


def _key(part: Part) -> str:
    return cache.key(_VERSION, str(SECTIONS), repr(mesh_primitives(part)))


def build(part: Part) -> bytes:
    import trimesh
    from trimesh.creation import annulus, box, cylinder

    meshes = []
    for prim in mesh_primitives(part):
        T = np.eye(4)
        T[:3, :3] = np.array(prim.rotation)
        T[:3, 3] = prim.center
        if prim.shape == "cylinder":
            meshes.append(cylinder(radius=prim.dims[0], height=prim.dims[1], sections=SECTIONS, transform=T))
        elif prim.shape == "tube":
            meshes.append(annulus(r_min=prim.dims[0], r_max=prim.dims[1], height=prim.dims[2], sections=SECTIONS, transform=T))
        else:
            meshes.append(box(extents=prim.dims, transform=T))
    mesh = trimesh.util.concatenate(meshes)
    return trimesh.exchange.stl.export_stl(mesh)


def stl_bytes(part: Part) -> bytes:
    name = f"{part.mesh}-{_key(part)}.stl"
    data = cache.get("meshes", name)
    if data is None:
        data = build(part)
        cache.put("meshes", name, data)
    return data
