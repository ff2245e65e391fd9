"""Where the page's camera starts (and where "reset view" returns): looking at the arm and its
cell from render's canonical direction (front left, above, as RViz's orbit camera), as close as
lets everything fit in the part of the window the control panel leaves free.

The browser's window is not known when the scene is built, so the fit assumes a typical one
(ASPECT, the panel taking PANEL of its width); a wider window only shows more around the arm.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

FOV = math.radians(45.0)  # vertical field of view: less distortion than viser's 75°
ASPECT = 1.8  # width / height of the 3D canvas (a browser window below its toolbars)
PANEL = 0.33  # share of the width the control panel covers, on the right
HEIGHT = 700  # px: the canvas's height assumed when sizing things in pixels (labels)
MARGIN = 0.1  # of the half-width/height of the free area, kept empty around the scene


@dataclass(frozen=True)
class Camera:
    position: np.ndarray
    look_at: np.ndarray
    fov: float


def basis(direction: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(forward, right, up) of a camera looking along -direction, z up."""
    f = -direction / np.linalg.norm(direction)
    r = np.cross(f, (0.0, 0.0, 1.0))
    r /= np.linalg.norm(r)
    return f, r, np.cross(r, f)


def project(points: np.ndarray, cam: Camera, aspect: float = ASPECT) -> np.ndarray:
    """Normalised device coordinates (x right, y up, -1..1 across the canvas) of world points."""
    f, r, u = basis(cam.position - cam.look_at)
    rel = points - cam.position
    depth = rel @ f
    t = math.tan(cam.fov / 2)
    return np.stack([(rel @ r) / (depth * t * aspect), (rel @ u) / (depth * t)], axis=1)


def frame(points: np.ndarray, azimuth: float, elevation: float, aspect: float = ASPECT, panel: float = PANEL,
          fov: float = FOV) -> Camera:
    """The closest camera from (azimuth, elevation) (rad) showing every point inside the free part
    of the canvas (x from -1 to 1 - 2 panel), centred there."""
    pts = np.asarray(points, dtype=float)
    direction = np.array((math.cos(elevation) * math.cos(azimuth), math.cos(elevation) * math.sin(azimuth),
                          math.sin(elevation)))
    _, r, u = basis(direction)
    centre = (pts.min(axis=0) + pts.max(axis=0)) / 2
    x_lo, x_hi = -1.0 + MARGIN, 1.0 - 2 * panel - MARGIN
    y_lo, y_hi = -1.0 + MARGIN, 1.0 - MARGIN
    t_v = math.tan(fov / 2)
    t_h = t_v * aspect

    def placed(d: float) -> tuple[Camera, bool]:
        """At distance d, slide the camera sideways until the points sit in the middle of the free area."""
        look = centre.copy()
        for _ in range(4):  # perspective makes the slide slightly nonlinear: a few corrections settle it
            cam = Camera(look + direction * d, look, fov)
            p = project(pts, cam, aspect)
            dx = (p[:, 0].min() + p[:, 0].max()) / 2 - (x_lo + x_hi) / 2
            dy = (p[:, 1].min() + p[:, 1].max()) / 2 - (y_lo + y_hi) / 2
            look = look + r * dx * d * t_h + u * dy * d * t_v
        cam = Camera(look + direction * d, look, fov)
        rel = pts - cam.position
        if ((rel @ -direction) <= 1e-6).any():  # a point behind the camera: too close
            return cam, False
        p = project(pts, cam, aspect)
        fits = p[:, 0].min() >= x_lo and p[:, 0].max() <= x_hi and p[:, 1].min() >= y_lo and p[:, 1].max() <= y_hi
        return cam, bool(fits)

    radius = max(float(np.linalg.norm(pts - centre, axis=1).max()), 0.05)
    near, far = 0.0, radius / math.sin(min(t_v, t_h, math.atan(t_h * (x_hi - x_lo) / 2))) * 1.5
    for _ in range(60):  # far enough to fit (the bound above nearly always is); from afar everything fits
        if placed(far)[1]:
            break
        near, far = far, far * 2
    for _ in range(40):
        mid = (near + far) / 2
        near, far = (near, mid) if placed(mid)[1] else (mid, far)
    return placed(far)[0]
