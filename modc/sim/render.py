"""`modc render FILE -o OUT.png [--pose NAME]`: a picture of the arm, its environment and its
targets, in the manner of the paper's Rviz figures.

PyBullet's TinyRenderer (software, so it works headless and gives the same pixels on every run)
draws the compiled URDF's meshes in their URDF material colours, obstacles in light steel blue,
targets as small red spheres and an RGB triad at tool0. Pixels where no body was drawn (the
segmentation mask says which) show a white-to-light-grey gradient and a light ground with a
0.1 m grid at the world's z = 0 (lowered under the lowest point of the scene when something
reaches below it), fading out around the scene: computed per pixel by intersecting its ray with
the ground plane. The frame is rendered at SUPERSAMPLE times the size and downsampled (Lanczos),
which anti-aliases the edges.

Camera. Looking at the centre of the scene's bounding box (every link, obstacle and target),
from 30° above the horizon at one of eight azimuths (or 55° at two of them); the distance is the
smallest at which the whole box fits inside 90 % of the frame. With no azimuth given, each candidate view is
rendered small, with the obstacles, and the one showing the most of the arm (of the least
visible arm, when a file has several) and of the targets wins, a later candidate only when
clearly (5 %) better: the farm cell's walls do not hide the arm. The chosen view is then framed
on the rendered silhouette (centred, filling 90 % of the frame). One camera per file: the box,
the scores and the framing take every pose of the file (home and each named pose), so pictures
of two poses are taken from the same place.

Captions (caption.py): a band under the scene names the robot, its chain and the pose, and each
target carries a label beside its marker. WIDTH x HEIGHT (1280 x 960) reads on a slide.
"""
from __future__ import annotations

import builtins
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..model import ResolvedRobot
from ..physical.camera import FILL, Camera, fit_camera, vec3
from . import scene

if TYPE_CHECKING:
    import numpy as np

WIDTH, HEIGHT = 1280, 960  # reads on a slide
SUPERSAMPLE = 2
GRID = 0.1  # m, ground grid spacing
GRID_LINE = 0.004  # m, width of a grid line
GROUND_RGB = (236, 238, 240)
GRID_RGB = (200, 204, 210)
BACKGROUND_TOP = (255, 255, 255)
BACKGROUND_BOTTOM = (222, 226, 232)
# Candidate views (azimuth from +x towards +y, elevation above the horizon), in degrees; the first
# is the canonical one: from the front left, above, as Rviz's default orbit camera.
VIEWS = tuple((az, el) for el in (30.0,) for az in (210.0, 150.0, 240.0, 120.0, 300.0, 60.0, 330.0, 30.0)) + (
    (210.0, 55.0), (150.0, 55.0))
AXIS_LENGTH, AXIS_RADIUS = 0.06, 0.003  # m, the tool0 triad
AXIS_RGBA = ((0.85, 0.1, 0.1, 1.0), (0.1, 0.7, 0.1, 1.0), (0.1, 0.25, 0.9, 1.0))
LIGHT = dict(lightDirection=[-0.4, -0.6, 1.0], lightColor=[1.0, 1.0, 1.0], lightDistance=4.0,
             lightAmbientCoeff=0.55, lightDiffuseCoeff=0.5, lightSpecularCoeff=0.08)


@dataclass
class Stage:
    """A PyBullet world holding every robot of a file (at its world placement) with their
    environments and targets, a ground, and a camera fitted to what is shown."""

    client: Any  # a PyBullet client
    scenes: dict[str, scene.Scene]
    ground: bool = False  # drawn by backdrop() once add_ground() has placed it
    camera: Camera | None = None
    axes: dict = field(default_factory=dict)  # robot name -> tool0 triad body
    fade_centre: np.ndarray | None = None  # (x, y), set by add_ground()
    fade_radii: tuple[float, float] = (1.0, 2.0)
    ground_z: float = 0.0
    _backdrop: dict = field(default_factory=dict)

    @classmethod
    def build(cls, client, robots, urdfs: dict[str, Path], qs: dict | None = None) -> Stage:
        placements = scene.world_placements(robots, qs)
        scenes = {r.name: scene.load_robot(client, r, urdfs[r.name], placements[r.name]) for r in robots}
        return cls(client, scenes)

    def set(self, qs: dict[str, object]) -> None:
        for name, q in qs.items():
            self.scenes[name].set_q(q)
        self.place_axes()

    def add_tool_axes(self, length: float = AXIS_LENGTH, radius: float = AXIS_RADIUS) -> None:
        """An RGB triad (x red, y green, z blue) at every tool0, as Rviz draws frames."""
        p = scene.pybullet()
        for name in self.scenes:
            shapes = []
            for k, (rpy, rgba) in enumerate((((0, math.pi / 2, 0), AXIS_RGBA[0]), ((-math.pi / 2, 0, 0), AXIS_RGBA[1]),
                                             ((0, 0, 0), AXIS_RGBA[2]))):
                pos = [length / 2 if k == j else 0.0 for j in range(3)]
                orn = self.client.getQuaternionFromEuler(rpy)
                shapes.append(
                    self.client.createVisualShape(
                        p.GEOM_CYLINDER,
                        radius=radius,
                        length=length,
                        rgbaColor=rgba,
                        visualFramePosition=pos,
                        visualFrameOrientation=orn,
                    )
                )
            body = self.client.createMultiBody(
                baseMass=0.0,
                baseCollisionShapeIndex=-1,
                baseVisualShapeIndex=shapes[0],
                linkMasses=[0.0, 0.0],
                linkCollisionShapeIndices=[-1, -1],
                linkVisualShapeIndices=shapes[1:],
                linkPositions=[[0, 0, 0]] * 2,
                linkOrientations=[[0, 0, 0, 1]] * 2,
                linkInertialFramePositions=[[0, 0, 0]] * 2,
                linkInertialFrameOrientations=[[0, 0, 0, 1]] * 2,
                linkParentIndices=[0, 0],
                linkJointTypes=[p.JOINT_FIXED] * 2,
                linkJointAxis=[[0, 0, 1]] * 2,
            )
            self.axes[name] = body
        self.place_axes()

    def place_axes(self) -> None:
        for name, body in self.axes.items():
            pos, orn = scene.matrix_pose(self.scenes[name].T_world_link("tool0"))
            self.client.resetBasePositionAndOrientation(body, pos, orn)

    def points(self):
        """Corners of the bounding boxes of everything shown (arm links, obstacles, targets)."""
        import numpy as np

        boxes = []
        for s in self.scenes.values():
            for name, i in s.links.items():
                if name in s.geometry_links:
                    boxes.append(self.client.getAABB(s.body, i))
            for ob in s.obstacles.values():
                boxes.append(self.client.getAABB(ob))
            for t in s.targets.values():
                pos = np.array(self.client.getBasePositionAndOrientation(t)[0])
                boxes.append((pos - scene.TARGET_RADIUS, pos + scene.TARGET_RADIUS))
        corners = []
        for lo, hi in boxes:
            lo, hi = np.asarray(lo), np.asarray(hi)
            for k in range(8):
                corners.append([hi[0] if k & 1 else lo[0], hi[1] if k & 2 else lo[1], hi[2] if k & 4 else lo[2]])
        return np.array(corners)

    def add_ground(self, points) -> None:
        """A grid on z = 0 of the world (or just below the scene when it reaches lower), fading
        into the background from fade_radii[0] to fade_radii[1] around the scene's footprint.
        The ground is drawn behind the rendered bodies (backdrop()), not by PyBullet: nothing
        of the scene is below it, and a textured plane would double the TinyRenderer's time."""
        import numpy as np

        lo, hi = points.min(axis=0), points.max(axis=0)
        centre = (lo[:2] + hi[:2]) / 2.0
        footprint = float(np.linalg.norm(hi[:2] - lo[:2])) / 2.0
        size = float(np.linalg.norm(hi - lo))
        r0 = footprint + max(0.1, 0.15 * size)
        self.fade_centre, self.fade_radii = centre, (r0, r0 + max(0.3, 0.6 * size))
        self.ground_z = min(0.0, float(lo[2]) - 1e-3)
        self.ground = True
        self._backdrop = {}

    def backdrop(self, camera: Camera, W: int, H: int):
        """What is behind the bodies, per pixel (float RGB, H x W x 3): a white-to-light-grey
        gradient, and the ground where a pixel's ray meets it: GROUND_RGB with GRID_RGB lines
        every GRID metres, blended into the gradient with the distance r from the scene's
        centre (smoothstep between fade_radii). Cached per camera and size."""
        import numpy as np

        key = (camera.eye, camera.target, camera.up, camera.fov, W, H)
        if self._backdrop.get("key") == key:
            return self._backdrop["image"]
        t = np.linspace(0.0, 1.0, H)[:, None, None]
        bg = (np.array(BACKGROUND_TOP) * (1 - t) + np.array(BACKGROUND_BOTTOM) * t) * np.ones((1, W, 1))
        if self.ground:
            eye = np.array(camera.eye)
            fwd = np.array(camera.target) - eye
            fwd /= np.linalg.norm(fwd)
            right = np.cross(fwd, camera.up)
            right /= np.linalg.norm(right)
            up = np.cross(right, fwd)
            ty = math.tan(math.radians(camera.fov) / 2.0)
            tx = ty * W / H
            u = ((np.arange(W) + 0.5) / W * 2.0 - 1.0) * tx
            v = (1.0 - (np.arange(H) + 0.5) / H * 2.0) * ty
            ray = fwd + u[None, :, None] * right + v[:, None, None] * up
            down = ray[:, :, 2] < -1e-9
            s = np.where(down, (self.ground_z - eye[2]) / np.where(down, ray[:, :, 2], -1.0), 0.0)
            xy = eye[:2] + s[:, :, None] * ray[:, :, :2]
            off = np.abs(xy / GRID - np.round(xy / GRID)) * GRID  # m to the nearest grid line, per axis
            line = (off < GRID_LINE / 2).any(axis=2)
            ground = np.where(line[:, :, None], np.array(GRID_RGB, float), np.array(GROUND_RGB, float))
            r = np.linalg.norm(xy - self.fade_centre, axis=2)
            a = np.clip((r - self.fade_radii[0]) / (self.fade_radii[1] - self.fade_radii[0]), 0.0, 1.0)
            a = np.where(down, a * a * (3.0 - 2.0 * a), 1.0)[:, :, None]
            bg = ground * (1.0 - a) + bg * a
        self._backdrop = {"key": key, "image": bg}
        return bg

    def robot_bodies(self) -> builtins.set[int]:  # `set` is a method here
        return {s.body for s in self.scenes.values()}

    def target_bodies(self) -> builtins.set[int]:
        return {t for s in self.scenes.values() for t in s.targets.values()}

    def _objects(self, cam: Camera, W: int, H: int, poses) -> list:
        """Object-id images (-1 = background) of a small render per pose (None: as it stands)."""
        import numpy as np

        out = []
        for qs in poses or [None]:
            if qs is not None:
                self.set(qs)
            _, seg = self.shoot(cam, W, H, supersample=1, raw=True)
            out.append(np.where(seg >= 0, seg & ((1 << 24) - 1), -1))
        return out

    def choose_camera(self, points, width: int, height: int, azimuth: float | None = None,
                      elevation: float | None = None, poses=None) -> Camera:
        """The given view, or the candidate (VIEWS) that shows the most arm and target pixels;
        then framed on the silhouette. poses: configurations ({robot: q}) the camera must show
        (a trajectory's); default: the current one. Leaves the stage in the last pose given."""
        import numpy as np

        aspect = width / height
        best: Camera | None
        if azimuth is not None:
            best = fit_camera(points, azimuth, 30.0 if elevation is None else elevation, aspect)
        else:
            views = VIEWS if elevation is None else tuple((az, elevation) for az, _ in VIEWS[:8])
            robots, targets = sorted(self.robot_bodies()), list(self.target_bodies())
            best, best_score = None, -1.0
            for az, el in views:
                cam = fit_camera(points, az, el, aspect)
                score = 0.0
                for obj in self._objects(cam, 160, round(160 / aspect), poses):
                    # every arm must show: the least visible one counts (for each of them)
                    least = min(float((obj == b).sum()) for b in robots)
                    score += len(robots) * least + 4 * float(np.isin(obj, targets).sum())
                if score > best_score * 1.05:  # a clearly better view replaces an earlier (more canonical) one
                    best, best_score = cam, score
        assert best is not None  # views is not empty and every score is >= 0
        self.camera = self.refine(best, aspect, poses)
        return self.camera

    def refine(self, cam: Camera, aspect: float, poses=None, rounds: int = 3) -> Camera:
        """Frame the rendered silhouette (arms, obstacles, targets; over every pose given)
        instead of their bounding boxes: centre it and zoom until it fills FILL of the frame."""
        import numpy as np

        shown = list(self.robot_bodies() | self.target_bodies() | set(self.axes.values())
                     | {o for s in self.scenes.values() for o in s.obstacles.values()})
        for _ in range(rounds):
            W, H = 240, round(240 / aspect)
            mask = np.zeros((H, W), dtype=bool)
            for obj in self._objects(cam, W, H, poses):
                mask |= np.isin(obj, shown)
            if not mask.any():
                return cam
            rows, cols = np.nonzero(mask)
            u0, u1 = cols.min() / W * 2 - 1, (cols.max() + 1) / W * 2 - 1
            v0, v1 = 1 - (rows.max() + 1) / H * 2, 1 - rows.min() / H * 2
            touching = cols.min() == 0 or rows.min() == 0 or cols.max() == W - 1 or rows.max() == H - 1
            scale = max((u1 - u0) / 2, (v1 - v0) / 2) / FILL
            if touching:
                scale = max(scale, 1.25)  # cut off by the frame: back off before measuring again
            eye, target = np.array(cam.eye), np.array(cam.target)
            dist = float(np.linalg.norm(eye - target))
            fwd = (target - eye) / dist
            right = np.cross(fwd, cam.up)
            right /= np.linalg.norm(right)
            up = np.cross(right, fwd)
            ty = math.tan(math.radians(cam.fov) / 2.0)
            shift = right * (u0 + u1) / 2 * ty * aspect * dist + up * (v0 + v1) / 2 * ty * dist
            target = target + shift
            dist *= scale
            eye = target - fwd * dist
            cam = Camera(vec3(eye), vec3(target), cam.up, cam.fov, cam.aspect,
                         max(0.01, cam.near * scale), cam.far, cam.azimuth, cam.elevation)
            if abs(scale - 1.0) < 0.02 and abs(u0 + u1) < 0.02 and abs(v0 + v1) < 0.02:
                break
        return cam

    def shoot(self, camera: Camera, width: int, height: int, supersample: float = SUPERSAMPLE, raw: bool = False):
        """Render. raw: (rgb uint8 array, segmentation array) at the rendered size; else a PIL image
        of width x height with the background replaced by the gradient."""
        import numpy as np

        p = scene.pybullet()
        W, H = round(width * supersample), round(height * supersample)
        view, proj = camera.matrices(self.client)
        _, _, rgba, _, seg = self.client.getCameraImage(
            W, H, view, proj, shadow=0, renderer=p.ER_TINY_RENDERER,
            flags=p.ER_SEGMENTATION_MASK_OBJECT_AND_LINKINDEX, **LIGHT)
        rgb = np.asarray(rgba, dtype=np.uint8).reshape(H, W, 4)[:, :, :3]
        seg = np.asarray(seg, dtype=np.int64).reshape(H, W)
        if raw:
            return rgb, seg
        from PIL import Image

        out = np.where((seg < 0)[:, :, None], self.backdrop(camera, W, H), rgb.astype(float))
        out = out.round().astype(np.uint8)
        img = Image.fromarray(out, "RGB")
        if supersample != 1:
            img = img.resize((width, height), Image.Resampling.LANCZOS)
        return img


def save_png(img, out: str | Path, colors: int | None = None) -> None:
    """Optimised PNG, no metadata (deterministic bytes); colors: quantise to an adaptive
    palette of that many colours first (no dithering), for small files such as the README's."""
    from PIL import Image

    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    if colors is not None:
        img = img.quantize(colors=colors, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE)
    img.save(out, format="PNG", optimize=True)


def pose_of(robot: ResolvedRobot, pose: str | None) -> tuple[float, ...]:
    if pose is None or pose == "home":
        return robot.home()
    p = robot.pose(pose)
    if p is None:
        names = ", ".join(["home"] + [x.name for x in robot.poses if x.name != "home"])
        raise scene.UsageError(f"robot {robot.name} has no pose '{pose}' (poses: {names})")
    return tuple(p.q)


def render(path, out_png, pose: str | None = None, robot: str | None = None, library: str | None = None,
           width: int = WIDTH, height: int = HEIGHT, azimuth: float | None = None, elevation: float | None = None,
           colors: int | None = None, captions: bool = True):
    """`modc render FILE -o OUT.png`. Returns (ok, report lines, checked).

    Every robot of the file (or the one named) at `pose` (default home), with its obstacles and
    targets, seen by the file's one camera (chosen and framed over every pose, so that the
    pictures of two poses of one file match), captioned (robot, chain, pose) with target labels
    unless captions=False. ok is False only when the file has errors (checked.diagnostics say
    which; nothing is written). Raises modc.compiler.InputError (unreadable file),
    RobotChoiceError (unknown robot), scene.UsageError (unknown pose) and OSError (cannot write
    OUT.png).
    """
    checked = scene.load_checked(path, library)
    if not checked.ok:
        return False, [], checked
    robots = scene.select_robots(checked, robot)
    qs = {r.name: pose_of(r, pose) for r in robots}
    with scene.compiled(checked) as urdfs, scene.connect() as client:
        img, cam = picture(client, robots, urdfs, qs, width, height, azimuth, elevation,
                           frame=file_poses(robots), caption_pose=pose or "home" if captions else None)
    save_png(img, out_png, colors)
    who = ", ".join(f"{r.name} ({r.sequence}) at {pose or 'home'}" for r in robots)
    return (
        True,
        [
            f"render: wrote {out_png} ({width}x{height}): {who}; "
            f"camera azimuth {cam.azimuth:g}°, elevation {cam.elevation:g}°"
        ],
        checked,
    )


def file_poses(robots: list[ResolvedRobot]) -> list[dict]:
    """Every configuration a picture of these robots may show: home, then each pose name any of
    them has (a robot without it at home), as {robot name: q}."""
    each = [dict(r.named_poses()) for r in robots]
    names = ["home"]
    for poses in each:
        names += [n for n in poses if n not in names]
    return [{r.name: poses.get(n, poses["home"]) for r, poses in zip(robots, each, strict=True)} for n in names]


def picture(client, robots, urdfs, qs, width: int = WIDTH, height: int = HEIGHT,
            azimuth: float | None = None, elevation: float | None = None, frame: list[dict] | None = None,
            caption_pose: str | None = None):
    """(PIL image, camera) of the robots at qs in a fresh stage on this client. frame: the
    configurations the camera is chosen and framed for (default: qs alone). caption_pose: caption
    the picture (robots, chains, this pose name) and label the targets; None: no caption."""
    import numpy as np

    from . import caption

    stage = Stage.build(client, robots, urdfs, qs)
    stage.add_tool_axes()
    frame = frame or [qs]
    pts = []
    for f in frame:
        stage.set(f)
        pts.append(stage.points())
    stage.add_ground(np.concatenate(pts))
    scene_h = height - caption.band_height(height) if caption_pose is not None else height  # the band goes below
    cam = stage.choose_camera(np.concatenate(pts), width, scene_h, azimuth, elevation, poses=frame)
    stage.set(qs)
    img = stage.shoot(cam, width, scene_h)
    if caption_pose is not None:
        img = _captioned(stage, caption.below(img, height), cam, robots, caption_pose, scene_h)
    return img, cam


def _captioned(stage: Stage, img, cam: Camera, robots, pose: str, scene_h: int):
    from ..physical.camera import project
    from . import caption

    title = ", ".join(f"{r.name}  {r.sequence}" for r in robots)
    labels = []
    for s in stage.scenes.values():
        for name, body in s.targets.items():
            xyz = stage.client.getBasePositionAndOrientation(body)[0]
            labels.append((name, tuple(project(cam, xyz, img.width, scene_h)[0])))
    return caption.draw(img, title, f"pose {pose}", labels)
