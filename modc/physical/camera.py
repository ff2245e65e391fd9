"""The picture's camera, shared by `modc render` and `modc play` (PyBullet) and the MJCF scene's
named camera (backends/mjcf_scene.py): a view direction (azimuth from +x towards +y, elevation
above the horizon) and the closest distance at which given world points fit in the frame.
Pure numpy: the compiler imports it without PyBullet."""
from __future__ import annotations

import math

from ..records import Record

FOV = 35.0  # degrees, vertical
FILL = 0.9  # the scene's box fits inside this share of the frame


def vec3(v) -> tuple[float, float, float]:
    return float(v[0]), float(v[1]), float(v[2])


class Camera(Record, kw_only=False, frozen=False):
    eye: tuple[float, float, float]
    target: tuple[float, float, float]
    up: tuple[float, float, float]
    fov: float
    aspect: float
    near: float
    far: float
    azimuth: float
    elevation: float

    def matrices(self, client):
        view = client.computeViewMatrix(self.eye, self.target, self.up)
        proj = client.computeProjectionMatrixFOV(self.fov, self.aspect, self.near, self.far)
        return view, proj


def _basis(azimuth: float, elevation: float):
    """Unit vectors: d from the target towards the eye, right, up (camera frame in the world)."""
    import numpy as np

    az, el = math.radians(azimuth), math.radians(elevation)
    d = np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])
    right = np.cross([0.0, 0.0, 1.0], d)
    right /= np.linalg.norm(right)
    up = np.cross(d, right)
    return d, right, up


def fit_camera(points, azimuth: float, elevation: float, aspect: float, fov: float = FOV, fill: float = FILL) -> Camera:
    """The closest camera at this azimuth and elevation that sees every point inside `fill` of
    the frame, aimed so that the points' projection is centred."""
    import numpy as np

    pts = np.asarray(points, dtype=float)
    d, right, up = _basis(azimuth, elevation)
    ty = math.tan(math.radians(fov) / 2.0) * fill
    tx = ty * aspect
    target = (pts.min(axis=0) + pts.max(axis=0)) / 2.0
    radius = float(np.linalg.norm(pts - target, axis=1).max()) or 0.1
    dist = radius / math.sin(math.radians(fov) / 2.0)
    for _ in range(4):  # each round: centre the projection, then the smallest distance that fits
        rel = pts - target
        x, y, z = rel @ right, rel @ up, rel @ d  # z towards the eye
        # a point fits when |x| <= tx (dist - z) and |y| <= ty (dist - z): dist >= z + |x|/tx
        dist = float(max(np.max(z + np.abs(x) / tx), np.max(z + np.abs(y) / ty)))
        depth = dist - z
        u, v = x / depth, y / depth  # normalised screen coordinates (times the tangents)
        du = (u.max() + u.min()) / 2.0
        dv = (v.max() + v.min()) / 2.0
        if abs(du) < 1e-4 and abs(dv) < 1e-4:
            break
        # shift the target across the view so that the projection's centre moves to the middle
        # the median as np.median gives it, without its first call's import of numpy.ma (~15 ms a compile)
        s, n = np.sort(depth), len(depth)
        mean_depth = float(s[n // 2] if n % 2 else (s[n // 2 - 1] + s[n // 2]) / 2.0)
        target = target + right * du * mean_depth + up * dv * mean_depth
    rel = pts - target
    z = rel @ d
    dist = float(max(np.max(z + np.abs(rel @ right) / tx), np.max(z + np.abs(rel @ up) / ty)))
    eye = target + d * dist
    span = float(np.linalg.norm(pts - eye, axis=1).max())
    near = max(0.01, float((dist - (rel @ d).max()) * 0.5))
    return Camera(vec3(eye), vec3(target), vec3(up), fov, aspect,
                  near, span * 3.0 + 1.0, azimuth, elevation)


def project(cam: Camera, points, width: int, height: int):
    """Pixel coordinates (u right, v down; N x 2) of world points in a width x height picture
    taken with this camera (a pinhole with the vertical field of view cam.fov)."""
    import numpy as np

    eye, target = np.asarray(cam.eye), np.asarray(cam.target)
    fwd = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(fwd, cam.up)
    right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    rel = np.atleast_2d(np.asarray(points, dtype=float)) - eye
    depth = np.maximum(rel @ fwd, 1e-9)
    ty = math.tan(math.radians(cam.fov) / 2.0)
    x = (rel @ right) / depth / (ty * width / height)
    y = (rel @ up) / depth / ty
    return np.c_[(x + 1.0) / 2.0 * width, (1.0 - y) / 2.0 * height]
