"""The pinocchio Model and collision GeometryModel of a Description, built in memory.

What pinocchio's URDF parser makes of the emitted URDF, without the URDF: the same joints
(JointModelRZ: every revolute joint of the arm turns about its frame's z), the same frames in the
same order (universe, base_link, then per joint its JOINT frame and its child's BODY frame, fixed
joints as FIXED_JOINT frames), inertias appended to the joints that carry them, limits from the
joints. tests/test_multibody.py compares both on every example (frames, masses, M(q), g(q)).

The collision geometry is the parts' tessellation (modc.physical.meshes: the triangles the STL
files hold) as coal BVH models, vertices rounded to float32 and merged as assimp merges them
when pinocchio loads the STL, so that collision results equal those on the emitted files.

pinocchio and coal are imported by the functions that need them (they cost 0.2 s to import).
"""
from __future__ import annotations

from functools import lru_cache
from typing import Any

import numpy as np

from ..kinematics import rpy_matrix
from ..model import Robot
from .assembly import Description
from .constants import GRAVITY_VECTOR
from .meshes import tessellate, unique_rows
from .parts import Part

ROOT = "base_link"
G_WORLD = np.array(GRAVITY_VECTOR)  # m/s², world z up


def gravity(robot: Robot) -> np.ndarray:
    """Gravity as seen in base_link: base_link may be mounted tilted (`base … rpy`)."""
    return rpy_matrix(robot.base.rpy).T @ G_WORLD


def _se3(pin, T: np.ndarray):
    return pin.SE3(np.ascontiguousarray(T[:3, :3]), np.ascontiguousarray(T[:3, 3]))


EYE4 = np.eye(4)


def link_frames(desc: Description) -> dict[str, tuple[int, np.ndarray]]:
    """Per link: the index of the joint that carries it (0: the universe, as pinocchio numbers
    joints) and the link frame's placement in that joint's frame (4x4)."""
    out = {ROOT: (0, EYE4)}
    n = 0
    for j in desc.joints:
        parent_joint, T = out[j.parent]
        if j.kind == "revolute":
            n += 1
            out[j.child] = (n, EYE4)
        else:
            out[j.child] = (parent_joint, T @ j.T_parent_child)
    return out


def model(desc: Description, gravity: np.ndarray | None = None) -> Any:
    """pin.Model of the arm (gravity in base_link, default -9.81 z)."""
    import pinocchio as pin

    m = pin.Model()
    m.name = desc.file_stem
    if gravity is not None:
        m.gravity.linear = np.asarray(gravity, float)
    links = {link.name: link for link in desc.links}
    placed = link_frames(desc)
    body_frame = {}  # link -> index of its BODY frame
    identity = pin.SE3.Identity()
    # a frame's inertia is added to its joint's by addFrame, as the URDF parser has it
    Y = _inertia(pin, links[ROOT].inertial)
    body_frame[ROOT] = m.addFrame(pin.Frame(ROOT, 0, 0, identity, pin.FrameType.BODY, Y or pin.Inertia.Zero()))
    for j in desc.joints:
        parent_joint, T_joint_parent = placed[j.parent]
        M = _se3(pin, T_joint_parent @ j.T_parent_child)
        Y = _inertia(pin, links[j.child].inertial)
        if j.kind == "revolute":
            lim = j.limits
            assert lim is not None
            jid = m.addJoint(parent_joint, pin.JointModelRZ(), M, j.name, np.array([lim.effort]),
                             np.array([lim.velocity]), np.array([lim.lower]), np.array([lim.upper]))
            fid = m.addJointFrame(jid, body_frame[j.parent])
            if Y is not None:
                m.appendBodyToJoint(jid, Y, identity)
            body_frame[j.child] = m.addBodyFrame(j.child, jid, identity, fid)
        else:
            fid = m.addFrame(pin.Frame(j.name, parent_joint, body_frame[j.parent], M, pin.FrameType.FIXED_JOINT,
                                       Y or pin.Inertia.Zero()))
            body_frame[j.child] = m.addBodyFrame(j.child, parent_joint, M, fid)
    return m


def _inertia(pin, inertial):
    if inertial is None:
        return None
    return pin.Inertia(float(inertial.mass), np.asarray(inertial.com, float), np.asarray(inertial.inertia, float))


@lru_cache(maxsize=512)
def _mesh_arrays(part: Part) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and triangles as pinocchio reads them from the STL: float32 corners, equal
    corners merged into one vertex in order of first appearance (assimp's JoinIdenticalVertices)."""
    vertices, faces, _ = tessellate(part)
    corners = vertices[faces].reshape(-1, 3).astype(np.float32)
    first, inverse = unique_rows(corners)
    order = np.argsort(first)
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    return corners[first[order]].astype(np.float64), rank[inverse.reshape(-1)].reshape(-1, 3).astype(np.int64)


def mesh_vertices(part: Part) -> np.ndarray:
    """The vertices of bvh(part), scaled as the URDF scales the part (no coal needed)."""
    return _mesh_arrays(part)[0] * np.array([part.scale_x, 1.0, 1.0])


@lru_cache(maxsize=512)
def bvh(part: Part) -> Any:
    """The part's collision mesh as a coal BVH model (OBBRSS, as pinocchio loads meshes), scaled
    as the URDF scales it. Shared by every geometry object that uses the part (read-only)."""
    import coal

    vertices, triangles = mesh_vertices(part), _mesh_arrays(part)[1]
    mesh = coal.BVHModelOBBRSS()
    mesh.beginModel(len(triangles), len(vertices))
    mesh.addVertices(vertices)
    mesh.addTriangles(triangles)
    mesh.endModel()
    return mesh


def hull_points(geometry) -> np.ndarray:
    """Points whose convex hull contains a coal geometry, in its own frame: a mesh's vertices,
    else the corners of its local bounding box (boxes, cylinders, spheres)."""
    if hasattr(geometry, "vertices"):
        return np.asarray(geometry.vertices(), float)
    geometry.computeLocalAABB()
    lo, hi = np.asarray(geometry.aabb_local.min_), np.asarray(geometry.aabb_local.max_)
    return np.array([[(lo, hi)[i][0], (lo, hi)[j][1], (lo, hi)[k][2]] for i in (0, 1) for j in (0, 1) for k in (0, 1)])


def enclosing_sphere(points: np.ndarray) -> tuple[np.ndarray, float]:
    """A sphere containing the points: the centre of their bounding box, the radius to the farthest."""
    c = (points.min(axis=0) + points.max(axis=0)) / 2
    return c, float(np.sqrt(((points - c) ** 2).sum(axis=1)).max())


@lru_cache(maxsize=512)
def bounding_sphere(part: Part) -> tuple[np.ndarray, float]:
    """A sphere containing the part's collision mesh (as scaled), in the part's frame."""
    return enclosing_sphere(mesh_vertices(part))


_MESHES: dict[int, tuple[Part, tuple[Any, np.ndarray, float]]] = {}


def collision_mesh(part: Part) -> tuple[Any, np.ndarray, float]:
    """(bvh(part), *bounding_sphere(part)), found by the part's identity first: the design
    search meets the same Part objects (cached per unit by describe()) thousands of times, and
    hashing a Part costs more than the lookup it keys."""
    hit = _MESHES.get(id(part))
    if hit is not None and hit[0] is part:
        return hit[1]
    value = (bvh(part), *bounding_sphere(part))
    if len(_MESHES) >= 4096:
        _MESHES.clear()
    _MESHES[id(part)] = (part, value)
    return value


def geometry(desc: Description, m: Any) -> Any:
    """pin.GeometryModel of the parts' collision meshes, named <link>_<k> as the URDF parser names them."""
    import pinocchio as pin

    gm = pin.GeometryModel()
    for link in desc.links:
        if not link.visuals:
            continue
        fid = m.getFrameId(link.name, pin.FrameType.BODY)
        frame = m.frames[fid]
        for k, v in enumerate(link.visuals):
            M = frame.placement * _se3(pin, v.T_link_part)
            go = pin.GeometryObject(f"{link.name}_{k}", frame.parentJoint, fid, M, bvh(v.part))
            go.meshScale = np.array([v.part.scale_x, 1.0, 1.0])
            gm.addGeometryObject(go)
    return gm


def obstacle_geometry(obstacle) -> tuple[Any, Any]:
    """coal geometry and pinocchio placement (in base_link) of one obstacle of the file: box
    (size = full extents), sphere (radius), cylinder (radius, full length along its z)."""
    import coal
    import pinocchio as pin

    s = obstacle.size
    if obstacle.shape == "box":
        g = coal.Box(float(s[0]), float(s[1]), float(s[2]))
    elif obstacle.shape == "sphere":
        g = coal.Sphere(float(s[0]))
    elif obstacle.shape == "cylinder":
        g = coal.Cylinder(float(s[0]), float(s[1]))
    else:  # pragma: no cover - the model admits only the three shapes
        raise ValueError(f"unknown obstacle shape {obstacle.shape!r}")
    return g, pin.SE3(rpy_matrix(obstacle.origin.rpy), np.array(obstacle.origin.xyz, dtype=float))


__all__ = ["EYE4", "G_WORLD", "ROOT", "bounding_sphere", "bvh", "collision_mesh", "enclosing_sphere", "hull_points",
           "link_frames", "geometry", "gravity", "model", "obstacle_geometry"]
