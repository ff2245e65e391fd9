"""Binary STL meshes of the parts, made with trimesh and cached on disk by content.

trimesh takes most of a second to import, so generated files are kept in the user cache
(keyed by the primitives' numbers): later compiles copy bytes and never import it.
"""
from __future__ import annotations

import hashlib
import os
from pathlib import Path

import numpy as np

from .parts import Part, mesh_primitives

SECTIONS = 48
_VERSION = "1"


def _cache_dir() -> Path | None:
    root = os.environ.get("MODC_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache"), "modc")
    return Path(root) / "meshes"


def _key(part: Part) -> str:
    text = repr((_VERSION, SECTIONS, mesh_primitives(part)))
    return hashlib.sha256(text.encode()).hexdigest()[:24]


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
    cache = _cache_dir()
    path = cache / f"{part.mesh}-{_key(part)}.stl" if cache else None
    if path is not None and path.is_file():
        return path.read_bytes()
    data = build(part)
    if path is not None:
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            tmp = path.with_suffix(f".{os.getpid()}.tmp")
            tmp.write_bytes(data)
            os.replace(tmp, path)
        except OSError:
            pass  # a read-only home is fine: we just regenerate next time
    return data
