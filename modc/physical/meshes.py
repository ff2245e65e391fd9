"""Triangle meshes of the parts (numpy only) and their binary STL files, cached on disk by content.

One tessellation serves the STL files the URDF references and the collision geometry modc's own
analyses test (modc.physical.geometry builds coal BVH models from tessellate()), so what MoveIt
checks and what modc checks are the same triangles.

The tessellation is trimesh's (which made these files until trimesh left the compile path: its
import alone cost half a second), reproduced operation for operation so that the STL bytes are
unchanged: cylinders and tubes are profiles revolved in SECTIONS steps (trimesh.creation.revolve),
boxes trimesh's 12-triangle cube, each placed by the same 4x4 product, coincident vertices of a
revolved primitive merged on a 1e-8 m grid keeping the first (the Trimesh constructor's
merge_vertices), normals from the cross product of the first two edges (triangles.normals), the
cube's given normals in a part of several primitives. tests/test_physical.py checks the bytes against trimesh itself.
"""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from .. import cache
from .parts import Part, Primitive, mesh_primitives

SECTIONS = 48
_VERSION = "1"
_MERGE_DIGITS = 8  # trimesh's tol.merge = 1e-8 m
_TOL_ZERO = float(np.finfo(np.float64).resolution * 100)

# trimesh's unit cube (resources/templates/box.json): corners, triangles, outward normals
_CUBE_VERTICES = np.array([[0, 0, 0], [0, 0, 1], [0, 1, 0], [0, 1, 1], [1, 0, 0], [1, 0, 1], [1, 1, 0], [1, 1, 1]],
                          dtype=np.float64)
_CUBE_FACES = np.array([[1, 3, 0], [4, 1, 0], [0, 3, 2], [2, 4, 0], [1, 7, 3], [5, 1, 4], [5, 7, 1], [3, 7, 2],
                        [6, 4, 2], [2, 7, 6], [6, 5, 4], [7, 5, 6]], dtype=np.int64)
_CUBE_NORMALS = np.array([[-1, 0, 0], [0, -1, 0], [-1, 0, 0], [0, 0, -1], [0, 0, 1], [0, -1, 0], [0, 0, 1],
                          [0, 1, 0], [0, 0, -1], [0, 1, 0], [1, 0, 0], [1, 0, 0]], dtype=np.float64)


def _key(part: Part) -> str:
    return cache.key(_VERSION, str(SECTIONS), repr(mesh_primitives(part)))


def _transform_points(points: np.ndarray, T: np.ndarray) -> np.ndarray:
    if np.abs(T - np.eye(4)).max() < 1e-8:
        return points.copy()
    stack = np.column_stack((points, np.ones(len(points))))
    return np.dot(T, stack.T).T[:, :3]


def _unitize(v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    norm = np.sqrt(np.dot(v * v, [1.0, 1.0, 1.0]))
    valid = norm > _TOL_ZERO
    norm[valid] **= -1
    return v * norm.reshape((-1, 1)), valid


def _cross(triangles: np.ndarray) -> np.ndarray:
    edges = triangles[:, 1:, :] - triangles[:, :2, :]
    return np.cross(edges[:, 0], edges[:, 1])


def _normals(triangles: np.ndarray) -> np.ndarray:
    """Unit normals of the triangles; a degenerate triangle gets (0, 0, 0)."""
    unit, valid = _unitize(_cross(triangles))
    out = np.zeros((len(triangles), 3))
    out[valid] = unit[valid]
    return out


def _revolve(profile: list[list[float]], T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A closed (r, z) profile turned about z in SECTIONS steps, then placed by T."""
    line = np.asarray(profile, dtype=np.float64)
    theta = np.linspace(0, np.pi * 2.0, SECTIONS + 1)
    points = np.column_stack((np.cos(theta), np.sin(theta)))
    per = len(line)
    radius, height = line[:, 0], line[:, 1]
    ring = np.tile(points, (1, per)).reshape((-1, 2)) * np.tile(radius, len(points)).reshape((-1, 1))
    vertices = np.column_stack((ring, np.tile(height, len(points))))
    vertices = vertices[:-per]  # the last ring is the first one again
    quad = np.array([0, per, 1, 1, per, per + 1])
    single = np.tile(quad, per - 1).reshape((-1, 3))
    single += np.tile(np.arange(per - 1), (2, 1)).T.reshape((-1, 1))
    tri = vertices[single]
    area = np.sqrt((_cross(tri) ** 2).sum(axis=1)) / 2.0
    single = single[area > 1e-8]  # profile segments on the axis give no triangles
    offset = np.tile(np.arange(SECTIONS) * per, (len(single), 1)).T.reshape((-1, 1))
    faces = (np.tile(single.ravel(), SECTIONS).reshape((-1, 3)) + offset) % len(vertices)
    vertices = _transform_points(vertices, T)
    if np.linalg.det(T[:3, :3]) < 0.0:
        faces = np.ascontiguousarray(np.fliplr(faces))
    return _merge(vertices, faces)


def unique_rows(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(first, inverse) of np.unique(a, axis=0, return_index=True, return_inverse=True), the
    unique rows in another order (callers put them in order of first appearance): rows compared as
    bytes (a 1-D unique, 5x faster than axis=0 on a mesh), -0.0 made 0.0 first so that equal
    numbers stay equal. first holds each row's first occurrence."""
    rows = np.ascontiguousarray(a + 0 if a.dtype.kind == "f" else a)  # + 0: -0.0 -> 0.0 (a new array)
    keys = rows.view(np.dtype((np.void, rows.dtype.itemsize * rows.shape[1]))).ravel()
    _, first, inverse = np.unique(keys, return_index=True, return_inverse=True)
    return first, inverse.reshape(-1)


def _merge(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Vertices equal on a 1e-8 m grid become one (the first of them), as trimesh merges them."""
    referenced = np.zeros(len(vertices), dtype=bool)
    referenced[faces] = True
    grid = (vertices * (10 ** _MERGE_DIGITS)).round().astype(np.int64)[referenced]
    first, inverse = unique_rows(grid)
    order = np.argsort(first)  # unique rows in order of first appearance
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    remap = np.zeros(len(vertices), dtype=np.int64)
    remap[referenced] = rank[inverse.reshape(-1)]
    kept = np.nonzero(referenced)[0][first[order]]
    return vertices[kept], remap[faces]


def _primitive(prim: Primitive) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
    """(vertices, faces, normals or None when computed from the triangles) of one primitive."""
    T = np.eye(4)
    T[:3, :3] = np.array(prim.rotation)
    T[:3, 3] = prim.center
    if prim.shape == "cylinder":
        r, h = prim.dims
        half = abs(float(h)) / 2.0
        return (*_revolve([[0, -half], [r, -half], [r, half], [0, half]], T), None)
    if prim.shape == "tube":
        r_in, r_out, h = (abs(float(x)) for x in prim.dims)
        half = h / 2.0
        return (*_revolve([[r_in, -half], [r_out, -half], [r_out, half], [r_in, half], [r_in, -half]], T), None)
    vertices = (_CUBE_VERTICES - 0.5) * np.asarray(prim.dims, dtype=np.float64)
    faces, normals = _CUBE_FACES, _CUBE_NORMALS
    if not np.allclose(T, np.eye(4), rtol=0.0, atol=1e-8):
        vertices = _transform_points(vertices, T)
        linear = T[:3, :3]
        if not np.allclose(linear, np.eye(3), rtol=0.0, atol=1e-6):
            adjugate = np.cross(linear.T[[1, 2, 0]], linear.T[[2, 0, 1]])
            flip = np.linalg.det(linear) < 0.0
            normals = _unitize(np.dot(normals, -adjugate if flip else adjugate))[0]
            if flip:
                faces = np.ascontiguousarray(np.fliplr(faces))
    return vertices, faces, normals


@lru_cache(maxsize=256)
def _tessellate(prims: tuple[Primitive, ...]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    arrays = _arrays(prims)
    for a in arrays:  # shared by every caller: read-only
        a.setflags(write=False)
    return arrays


def _arrays(prims: tuple[Primitive, ...]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    vs, fs, ns = [], [], []
    offset = 0
    for prim in prims:
        v, f, n = _primitive(prim)
        vs.append(v)
        fs.append(f + offset)
        ns.append(_normals(v[f]) if n is None else n)
        offset += len(v)
    if len(prims) == 1:  # trimesh's concatenate of one mesh copies it without its cached normals
        return vs[0], fs[0], _normals(vs[0][fs[0]])
    return np.vstack(vs), np.vstack(fs), np.vstack(ns)


def tessellate(part: Part) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(vertices (V, 3), triangles (F, 3) int, unit normals (F, 3)) of the part's mesh, in the
    part's frame; link bars at unit length along x (the URDF scales them by part.scale_x)."""
    return _tessellate(mesh_primitives(part))


def stl(vertices: np.ndarray, faces: np.ndarray, normals: np.ndarray) -> bytes:
    """Binary STL: 80-byte zero header, triangle count, then per triangle a normal, three
    vertices (float32, little-endian) and a zero attribute word."""
    record = np.dtype([("normals", "<f4", 3), ("vertices", "<f4", (3, 3)), ("attributes", "<u2")])
    packed = np.zeros(len(faces), dtype=record)
    packed["normals"] = normals
    packed["vertices"] = vertices[faces]
    return bytes(80) + np.uint32(len(faces)).astype("<u4").tobytes() + packed.tobytes()


def build(part: Part) -> bytes:
    return stl(*tessellate(part))


def stl_bytes(part: Part) -> bytes:
    name = f"{part.mesh}-{_key(part)}.stl"
    data = cache.get("meshes", name)
    if data is None:
        data = build(part)
        cache.put("meshes", name, data)
    return data
