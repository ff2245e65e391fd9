"""`modc view` draws a robot's regions (the points a task visits), turned boxes included, and
frames the picture around them."""
from __future__ import annotations

import math

import numpy as np
import pytest

from modc.compiler import check_text
from modc.view.arm import Arm

CELL = """robot r {
    chain H1 - L3 - L3
    target plant at (0.3, 0.1, 0.25) m
    region tray box size (0.2, 0.1, 0) m at (0.1, -0.5, 0.1) m turned (0, 0, 30) deg grid 3 x 2 x 1
    task serve { visit plant, tray }
}
"""


class Scene:
    """What the page's scene is asked to add, by node name (viser's calls, recorded)."""

    def __init__(self):
        self.nodes: dict[str, dict] = {}

    def __getattr__(self, method):
        if not method.startswith("add_"):
            raise AttributeError(method)

        def add(name, *args, **kw):
            self.nodes[name] = {"kind": method, "args": args, **kw}
            return name

        return add


def _arm() -> Arm:
    checked = check_text(CELL, "r.mod")
    assert checked.ok, [d.message for d in checked.diagnostics]
    return Arm(checked.design.robots[0])


def test_a_region_is_drawn_as_its_points_in_its_turned_box():
    from modc.kinematics import rpy_matrix
    from modc.view import draw

    arm = _arm()
    scene = Scene()
    draw.regions(scene, "/arm", arm)
    region = arm.robot.regions[0]
    cloud = scene.nodes["/arm/regions/tray/points"]
    assert cloud["kind"] == "add_point_cloud"
    assert np.allclose(cloud["points"], [p.xyz for p in region.points()], atol=1e-6)  # float32
    box = scene.nodes["/arm/regions/tray/box"]
    assert box["wireframe"] and np.allclose(box["position"], region.center)
    w, x, y, z = box["wxyz"]
    assert math.degrees(2 * math.atan2(z, w)) == pytest.approx(30) and abs(x) + abs(y) < 1e-12
    assert box["dimensions"][:2] == (0.2, 0.1) and 0 < box["dimensions"][2] <= draw.REGION_EDGE
    # every point lies inside the drawn box, turned as the region's
    R = rpy_matrix(region.turned)
    local = (cloud["points"] - np.asarray(region.center)) @ R
    assert np.all(np.abs(local) <= np.asarray(box["dimensions"]) / 2 + 1e-6)
    assert scene.nodes["/arm/region_labels/tray"]["args"] == ("tray (6 points)",)


def test_the_picture_is_framed_around_the_region_too():
    arm = _arm()
    pts = arm.extent(arm.robot.home())
    for p in arm.robot.regions[0].points():  # the region lies far to the side of the arm
        assert np.all(pts.min(0) <= np.asarray(p.xyz) + 1e-9) and np.all(np.asarray(p.xyz) - 1e-9 <= pts.max(0))
