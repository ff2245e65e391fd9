"""The MJCF scene, mjcf/scene_mod<n>_<name>.xml (written by the mjcf backend beside the robot):
the robot file `<include>`d, as MuJoCo Menagerie's scene.xml includes its robot, and around it

    floor       a checkered plane at the world's z = 0, lowered under the lowest point of the
                arm in any keyframe and of the cell when something reaches below it
    light       a directional key light from above and the headlight, a gradient skybox
    camera      "overview": fixed, framing the arm in every keyframe and the targets (not the
                whole cell, which can dwarf the arm) at AZIMUTH / ELEVATION (physical.camera's
                fit_camera, as `modc render`), for ASPECT images; the free camera (statistic,
                visual/global) starts on the same view
    cell        each obstacle a world geom named as in the file (they collide: contype 1); each
                target a site target_<name>, oriented when the target gives rpy; both carried
                into the world through `base`, like `modc sim`

The robot file holds everything MuJoCo needs to simulate the arm (bodies, servos, keyframes);
the scene only adds what a picture and the environment need.
"""
from __future__ import annotations

import math

import numpy as np

from .._version import __version__
from ..kinematics import matrix_rpy, rpy_matrix, transform
from ..model import ResolvedRobot
from ..physical.cell import OBSTACLE_RGBA, TARGET_RADIUS, TARGET_RGBA
from .build import Build
from .mjcf import TARGET_PREFIX, num, placement, vec
from .templates import comment

CAMERA = "overview"
FLOOR = "scene-floor"  # not an identifier, so no obstacle of the file can have this name
AZIMUTH, ELEVATION = 210.0, 30.0  # degrees: `modc render`'s canonical view, from the front left, above
ASPECT = 4.0 / 3.0
OFFSCREEN = (1280, 960)  # px: the offscreen buffer, large enough for a slide
FLOOR_MARGIN = 1e-3  # m under the lowest point when the scene reaches below z = 0



def _cell(robot: ResolvedRobot, T_world_base) -> tuple[list[dict], list[dict]]:
    """Obstacles (world geoms) and targets (world sites), given in base_link, placed in the world."""
    geoms = []
    for ob in robot.obstacles:
        T = T_world_base @ transform(ob.origin.xyz, ob.origin.rpy)
        size = {"box": lambda s: [v / 2.0 for v in s], "sphere": lambda s: [s[0]],
                "cylinder": lambda s: [s[0], s[1] / 2.0]}[ob.shape](ob.size)
        geoms.append({"name": ob.name, "type": ob.shape, "size": vec(size), **placement(T)})
    sites = []
    for t in robot.targets:
        site = {"name": TARGET_PREFIX + t.name, "pos": vec((T_world_base @ np.array([*t.xyz, 1.0]))[:3]),
                "size": num(TARGET_RADIUS), "euler": None}
        if t.rpy is not None:
            site["euler"] = vec(matrix_rpy(T_world_base[:3, :3] @ rpy_matrix(t.rpy)))
        sites.append(site)
    return geoms, sites


def _keyframe_points(robot: ResolvedRobot, T_world_base):
    """World points bounding the arm in every keyframe, the obstacles and the targets."""
    from ..physical.cell import extent_points  # points in pairs: a centre widened by its radius either way

    poses = [q for _, q in robot.named_poses()]
    return np.concatenate([extent_points(robot, q, T_world_base) for q in poses])


def _camera(points) -> dict:
    from ..physical.camera import fit_camera

    cam = fit_camera(points, AZIMUTH, ELEVATION, ASPECT)
    eye, target = np.array(cam.eye), np.array(cam.target)
    forward = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(forward, cam.up)
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)  # a MuJoCo camera looks along its -z: x right, y up
    extent = float(np.linalg.norm(points - target, axis=1).max())
    return {"name": CAMERA, "pos": vec(eye), "xyaxes": vec(np.round([*right, *up], 12)), "fovy": num(cam.fov),
            "center": vec(target), "extent": num(max(extent, 0.1)),
            # MuJoCo's free camera: azimuth of its view direction (ours is of the eye), elevation negative down
            "azimuth": num((AZIMUTH + 180.0) % 360.0), "elevation": num(-ELEVATION),
            "distance": float(np.linalg.norm(eye - target))}


def scene_context(build: Build, robot: ResolvedRobot) -> dict:
    from ..physical import cell as scene

    T_world_base = transform(robot.base.xyz, robot.base.rpy)
    obstacles, targets = _cell(robot, T_world_base)
    pts = _keyframe_points(robot, T_world_base)
    arm = _keyframe_points(robot.model_copy(update={"obstacles": ()}), T_world_base)
    # the floor is the cell's z = 0 unless a frame of the arm, an obstacle or a target lies below it
    lowest = float(((pts[0::2] + pts[1::2]) / 2.0)[:, 2].min())
    floor_z = 0.0 if lowest >= 0.0 else lowest - scene.MODULE_RADIUS - FLOOR_MARGIN
    camera = _camera(arm)  # the arm and its targets: a large cell would leave the arm small
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    centre = (lo + hi) / 2.0
    return {
        "name": robot.file_stem, "robot_file": f"{robot.file_stem}.xml", "robot": comment(robot.name),
        "sequence": comment(robot.sequence), "source": comment(build.source_name), "version": __version__,
        "camera": camera, "offwidth": OFFSCREEN[0], "offheight": OFFSCREEN[1],
        "floor": {"name": FLOOR, "pos": vec((centre[0], centre[1], floor_z)),
                  "size": vec((max(1.0, math.ceil(float(np.abs(hi[:2] - lo[:2]).max()) * 1.5)),) * 2 + (0.05,))},
        "light": {"pos": vec((centre[0], centre[1], float(hi[2]) + 1.5))},
        "obstacle_rgba": vec(OBSTACLE_RGBA), "target_rgba": vec(TARGET_RGBA),
        "obstacles": obstacles, "targets": targets,
    }
