"""How the cell is shown: obstacles and target markers look the same in every picture and model
(PyBullet scenes and renders, the MJCF), and what a picture of a robot must hold (extent_points)."""
from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from ..model import ResolvedRobot

TARGET_RADIUS = 0.012  # m, the visual-only sphere marking a target
OBSTACLE_RGBA = (0.62, 0.70, 0.78, 1.0)
TARGET_RGBA = (0.86, 0.12, 0.22, 1.0)


MODULE_RADIUS = 0.06  # m: a joint module reaches about this far from its frames


def extent_points(robot: ResolvedRobot, q=None, T_world_base=None):
    """Points (world) that bound what a picture of the robot shows at q: every frame of the
    chain widened by a module's radius, each obstacle's bounding sphere, each target."""
    import numpy as np

    from ..kinematics import Chain, transform

    T = transform(robot.base.xyz, robot.base.rpy) if T_world_base is None else T_world_base
    chain = Chain(robot)
    q = robot.home() if q is None else q
    pts, radii = [np.zeros(3)], [MODULE_RADIUS]
    for f in chain.frames(q):
        for k in ("T_base_twist1", "T_base_joint", "T_base_end"):
            pts.append(f[k][:3, 3])
            radii.append(MODULE_RADIUS)
    pts.append(chain.T_base_tool(q)[:3, 3])
    radii.append(MODULE_RADIUS)
    for ob in robot.obstacles:
        half = {"box": lambda s: float(np.linalg.norm(s)) / 2.0, "sphere": lambda s: s[0],
                "cylinder": lambda s: float(np.hypot(s[0], s[1] / 2.0))}[ob.shape](ob.size)
        pts.append(np.array(ob.origin.xyz))
        radii.append(half)
    for t in robot.targets:
        pts.append(np.array(t.xyz))
        radii.append(TARGET_RADIUS)
    out = []
    for p, r in zip(pts, radii, strict=True):
        w = (T @ np.array([*p, 1.0]))[:3]
        out += [w - r, w + r]
    return np.array(out)
