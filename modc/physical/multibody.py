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

from .assembly import Description
from .meshes import tessellate
from .parts import Part

ROOT = "base_link"


def _se3(pin, T: np.ndarray):
    return pin.SE3(np.ascontiguousarray(T[:3, :3]), np.ascontiguousarray(T[:3, 3]))


def model(desc: Description, gravity: np.ndarray | None = None) -> Any:
    """pin.Model of the arm (gravity in base_link, default -9.81 z)."""
    import pinocchio as pin

    m = pin.Model()
    m.name = desc.file_stem
    if gravity is not None:
        m.gravity.linear = np.asarray(gravity, float)
    links = {link.name: link for link in desc.links}
    # where each link sits: (joint index, placement in the joint frame, index of its BODY frame)
    where: dict[str, tuple[int, Any, int]] = {}
    identity = pin.SE3.Identity()
    root = links[ROOT]
    Y = _inertia(pin, root.inertial)
    # a frame's inertia is added to its joint's by addFrame, as the URDF parser has it
    where[ROOT] = (0, identity, m.addFrame(pin.Frame(ROOT, 0, 0, identity, pin.FrameType.BODY, Y or pin.Inertia.Zero())))
    for j in desc.joints:
        parent_joint, M_joint_parent, parent_frame = where[j.parent]
        M = M_joint_parent * _se3(pin, j.T_parent_child)
        Y = _inertia(pin, links[j.child].inertial)
        if j.kind == "revolute":
            lim = j.limits
            assert lim is not None
            jid = m.addJoint(parent_joint, pin.JointModelRZ(), M, j.name, np.array([lim.effort]),
                             np.array([lim.velocity]), np.array([lim.lower]), np.array([lim.upper]))
            fid = m.addJointFrame(jid, parent_frame)
            if Y is not None:
                m.appendBodyToJoint(jid, Y, identity)
            where[j.child] = (jid, identity, m.addBodyFrame(j.child, jid, identity, fid))
        else:
            fid = m.addFrame(pin.Frame(j.name, parent_joint, parent_frame, M, pin.FrameType.FIXED_JOINT,
                                       Y or pin.Inertia.Zero()))
            where[j.child] = (parent_joint, M, m.addBodyFrame(j.child, parent_joint, M, fid))
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
    unique, first, inverse = np.unique(corners, axis=0, return_index=True, return_inverse=True)
    order = np.argsort(first)
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    return corners[first[order]].astype(np.float64), rank[inverse.reshape(-1)].reshape(-1, 3).astype(np.int64)


@lru_cache(maxsize=512)
def bvh(part: Part) -> Any:
    """The part's collision mesh as a coal BVH model (OBBRSS, as pinocchio loads meshes), scaled
    as the URDF scales it. Shared by every geometry object that uses the part (read-only)."""
    import coal

    vertices, triangles = _mesh_arrays(part)
    vertices = vertices * np.array([part.scale_x, 1.0, 1.0])
    mesh = coal.BVHModelOBBRSS()
    mesh.beginModel(len(triangles), len(vertices))
    mesh.addVertices(vertices)
    mesh.addTriangles(triangles)
    mesh.endModel()
    return mesh


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


__all__ = ["bvh", "geometry", "model"]
