"""The cell, the targets, the tool and the payload as the page draws them with viser, under an
arm's root node (base_link). Look: physical/cell.py, as every other picture of the cell.

A target is its marker (a sphere of TARGET_RADIUS), a translucent sphere of its position
tolerance when that is larger than the marker, the tool0 axes it asks for when it has an
orientation, and a label with its name and tolerances, lifted above the marker (and above the
labels of targets that would overlap it on screen). A region is its points (one point cloud: it
may hold thousands) inside its box's wireframe, labelled with its name at the box's centre.
"""
from __future__ import annotations

import math

import numpy as np

from ..kinematics import transform
from ..physical.assembly import PAYLOAD_RADIUS
from ..physical.cell import TARGET_RADIUS
from .arm import AXES, OBSTACLE_RGB, PAYLOAD_RGB, TARGET_RGB, TOOL_RGB, Arm
from .camera import ASPECT, HEIGHT, Camera, basis, project

# Labels are sized on screen: they are placed in pixels of the framed view (camera.py), then
# moved back into the scene along the camera's up direction.
LABEL_LIFT = 10  # px from a target's marker to the bottom of its label
LABEL_HEIGHT = 24  # px a label takes, with a gap to the next
CHAR_WIDTH = 8.5  # px of one character of a label (font_screen_scale 1.2)
TOOL_THICKNESS = 0.012  # m: the tool drawn as a bar from the flange to tool0


def wxyz(T: np.ndarray) -> np.ndarray:
    from viser.transforms import SO3

    return SO3.from_matrix(T[:3, :3]).wxyz


def target_label(t) -> str:
    text = f"{t.name} ±{t.position_tolerance * 1000:.3g} mm"
    if t.rpy is not None:
        text += f", ±{math.degrees(t.orientation_tolerance):.3g}°"
    return text


def label_lifts(targets, cam: Camera, T_world_base: np.ndarray) -> list[np.ndarray]:
    """Per target, where its label's anchor sits relative to it (m, base_link): above the marker
    on screen, and above the labels of earlier targets it would overlap."""
    if not targets:
        return []
    R = T_world_base[:3, :3]
    world = np.array([T_world_base[:3, 3] + R @ np.asarray(t.xyz, dtype=float) for t in targets])
    ndc = project(world, cam)
    px = np.stack([(ndc[:, 0] + 1) / 2 * HEIGHT * ASPECT, (1 - ndc[:, 1]) / 2 * HEIGHT], axis=1)
    _, _, up = basis(cam.position - cam.look_at)
    placed: list[tuple[float, float, float, float]] = []  # left, right, top, bottom (px, y down)
    out = []
    for t, (x, y), p in zip(targets, px, world, strict=True):
        half = CHAR_WIDTH * len(target_label(t)) / 2 + 6
        bottom = y - LABEL_LIFT
        moved = True
        while moved:
            moved = False
            for left, right, top, low in placed:
                if x - half < right and x + half > left and bottom - LABEL_HEIGHT < low and bottom > top:
                    bottom, moved = top, True
        placed.append((x - half, x + half, bottom - LABEL_HEIGHT, bottom))
        m_px = float(np.dot(p - cam.position, cam.look_at - cam.position) / np.linalg.norm(cam.look_at - cam.position))
        m_px *= 2 * math.tan(cam.fov / 2) / HEIGHT
        out.append(R.T @ (up * (y - bottom) * m_px))
    return out


def cell(scene, base: str, arm: Arm, cam: Camera) -> tuple[list, dict]:
    """Obstacles, targets and regions under base (base_link), labels placed for the view cam;
    returns the handles, and the targets' labels by name."""
    out, labels = [], {}
    for ob in arm.robot.obstacles:
        T_ob = transform(ob.origin.xyz, ob.origin.rpy)
        kw = dict(color=OBSTACLE_RGB, opacity=0.6, position=T_ob[:3, 3], wxyz=wxyz(T_ob))
        name = f"{base}/cell/{ob.name}"
        if ob.shape == "box":
            out.append(scene.add_box(name, dimensions=tuple(ob.size), **kw))
        elif ob.shape == "sphere":
            out.append(scene.add_icosphere(name, radius=ob.size[0], **kw))
        else:
            out.append(scene.add_cylinder(name, radius=ob.size[0], height=ob.size[1], **kw))
    targets = arm.robot.targets
    for t, lift in zip(targets, label_lifts(targets, cam, arm.T_world_base), strict=True):
        name = f"{base}/targets/{t.name}"
        T = transform(t.xyz, t.rpy if t.rpy is not None else (0.0, 0.0, 0.0))
        node = scene.add_frame(name, show_axes=t.rpy is not None, axes_length=AXES, axes_radius=0.003,
                               position=T[:3, 3], wxyz=wxyz(T))
        out.append(node)
        scene.add_icosphere(f"{name}/marker", radius=TARGET_RADIUS, color=TARGET_RGB)
        if t.position_tolerance > TARGET_RADIUS:
            scene.add_icosphere(f"{name}/tolerance", radius=t.position_tolerance, color=TARGET_RGB, opacity=0.2)
        # the label stays upright whatever the target's orientation: placed in base_link
        labels[t.name] = scene.add_label(f"{base}/target_labels/{t.name}", target_label(t), anchor="bottom-center",
                                         position=np.asarray(t.xyz) + lift, font_screen_scale=1.2)
        out.append(labels[t.name])
    return out + regions(scene, base, arm), labels


REGION_POINT = 0.012  # m: a region point's dot (a region may hold thousands: one point cloud each)
REGION_EDGE = 0.002  # m: the thickness a flat region's box is drawn with


def regions(scene, base: str, arm: Arm) -> list:
    """Each region as its points (one cloud) in its box (a wireframe, turned as the region's box
    is), labelled with its name and number of points at the box's centre; in base_link."""
    out = []
    for r in arm.robot.regions:
        name = f"{base}/regions/{r.name}"
        T = transform(r.center, r.turned if r.turned is not None else (0.0, 0.0, 0.0))
        out.append(scene.add_box(f"{name}/box", color=TARGET_RGB, dimensions=tuple(max(s, REGION_EDGE) for s in r.size),
                                 wireframe=True, position=T[:3, 3], wxyz=wxyz(T)))
        points = np.array([p.xyz for p in r.points()], dtype=np.float32)
        out.append(scene.add_point_cloud(f"{name}/points", points=points, colors=TARGET_RGB, point_size=REGION_POINT,
                                         point_shape="circle"))
        n = len(points)
        out.append(scene.add_label(f"{base}/region_labels/{r.name}", f"{r.name} ({n} point{'s' if n != 1 else ''})",
                                   anchor="bottom-center", position=T[:3, 3], font_screen_scale=1.2))
    return out


def tool_and_payload(scene, base: str, arm: Arm) -> list:
    """The tool (flange to tool0) on the last link, the payload on its own link; returns the handles."""
    out = []
    last = f"link_{arm.dof}"
    start, end = arm.tool_segment()
    if np.linalg.norm(end - start) > 1e-6:
        out.append(scene.add_line_segments(f"{base}/{last}/tool", np.array([[start, end]], dtype=np.float32),
                                           colors=TOOL_RGB, thickness=TOOL_THICKNESS))
    if arm.robot.payload is not None:
        out.append(scene.add_icosphere(f"{base}/payload/mass", radius=PAYLOAD_RADIUS, color=PAYLOAD_RGB))
    return out
