"""`modc play FILE --traj TRAJ.json [--record OUT.gif] [--engine mujoco]`: play a trajectory in
PyBullet (this module) or MuJoCo (mujoco_play.py: the MJCF scene, servos with inverse-dynamics
feed-forward; this module reads the trajectory, reports and writes the GIF for both).

The arm starts at rest at the first point and its actuators follow the trajectory (linear in
joint space between points, trajectory.py) with the same position control as `modc sim`
(force = peak torque, maxVelocity = rated speed, feed-forward velocity of the segment), at 1 kHz,
and then hold the last point for HOLD_AFTER. Obstacles do not push the arm; contacts with them
and between links are looked for CHECK_HZ times a second and reported, as is the worst tracking
error. With a display (DISPLAY set and PyBullet's GUI connects) it runs in the GUI in real time;
otherwise headless, as fast as it goes.

--record renders frames with the TinyRenderer (the `modc render` stage: ground, obstacles,
targets, a tool0 triad) at FPS frames per second of simulated time from a camera fitted to the
whole motion, captioned (robot, chain, time) with the targets labelled, and writes a looping
GIF (one shared palette, no dithering, optimised): same input, same bytes.
"""
from __future__ import annotations

import time as wallclock
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .. import trajectory
from ..model import ResolvedRobot
from ..physical.constants import TIME_STEP
from . import scene
from .render import Stage

FPS = 12.5  # frames per second of simulated time (80 ms: a whole number of GIF centiseconds)
GIF_SIZE = (640, 480)
GIF_SUPERSAMPLE = 1.5  # rendered at 720x540 and downsampled: smooth edges at half the cost of 2x
HOLD_AFTER = 0.5  # s at the last point after the motion
LAST_FRAME_MS = 1000  # the GIF rests on its last frame before looping
CHECK_HZ = 50.0
CAMERA_SAMPLES = 9  # configurations of the motion the camera is fitted to


def pick_robot(checked, traj: trajectory.Trajectory, robot: str | None) -> ResolvedRobot:
    """The robot named on the command line, else the trajectory's, else the file's only robot."""
    from ..model.select import choose_robot

    return choose_robot(checked.design, robot or traj.robot, say='--robot NAME, or "robot" in the trajectory file')


def _palette(img) -> list[int]:
    pal = img.getpalette()
    assert pal is not None  # a quantised image is a palette image
    return pal


def save_gif(frames, out: str | Path, fps: float = FPS) -> None:
    """A looping GIF, every frame on one adaptive palette (deterministic)."""
    from PIL import Image

    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    # one palette for the whole animation, from up to 8 frames spread over it (stacked): 200
    # median-cut colours for the large smooth areas (background, ground, links; no banding) and
    # 55 octree colours, which keep the saturated hues of small parts (tool0 triad, targets)
    picks = [frames[round(k * (len(frames) - 1) / 7)] for k in range(8)] if len(frames) > 8 else frames
    sheet = Image.new("RGB", (picks[0].width, picks[0].height * len(picks)))
    for k, f in enumerate(picks):
        sheet.paste(f, (0, k * f.height))
    smooth = _palette(sheet.quantize(colors=200, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE))[:600]
    vivid = _palette(sheet.quantize(colors=55, method=Image.Quantize.FASTOCTREE, dither=Image.Dither.NONE))[:165]
    palette = Image.new("P", (1, 1))
    palette.putpalette(smooth + vivid + [0, 0, 0] * (256 - (len(smooth) + len(vivid)) // 3))
    pal = [f.quantize(palette=palette, dither=Image.Dither.NONE) for f in frames]
    ms = round(1000.0 / fps)
    durations = [ms] * len(pal)
    durations[-1] = max(ms, LAST_FRAME_MS)
    pal[0].save(out, format="GIF", save_all=True, append_images=pal[1:], duration=durations, loop=0, optimize=True,
                disposal=1)


ENGINES = ("pybullet", "mujoco")


def play(path, traj_json, record=None, robot: str | None = None, library: str | None = None, gui: bool | None = None,
         fps: float = FPS, size: tuple[int, int] | None = None, azimuth: float | None = None, engine: str = "pybullet"):
    """`modc play`. Returns (ok, report lines, checked).

    engine: "pybullet" (this module, on the URDF) or "mujoco" (mujoco_play.py, on the MJCF scene,
    with inverse-dynamics feed-forward; always headless). size: the GIF's, default GIF_SIZE or
    mujoco_play.GIF_SIZE.

    ok is False when the file has errors (see checked.diagnostics; lines empty) or the trajectory
    does not fit (lines: one error each, "TRAJ.json: points[3].t: …"); nothing is played then.
    gui: None = when a display exists, False = headless, True = ask for the GUI (falls back).
    Raises modc.compiler.InputError (unreadable .mod), scene.UsageError (unreadable trajectory),
    modc.model.select.RobotChoiceError (unknown or ambiguous robot) and OSError (cannot write the GIF).
    """
    if engine not in ENGINES:
        raise scene.UsageError(f"unknown engine '{engine}' (choose from {', '.join(ENGINES)})")
    checked = scene.load_checked(path, library)
    if not checked.ok:
        return False, [], checked
    r, traj, errors = _trajectory_for(checked, traj_json, robot)
    if errors:
        return False, [f"{traj_json}: {e}" for e in errors], checked
    if engine == "mujoco":
        return True, _play_mujoco(checked, r, traj, record, fps, size), checked
    size = size or GIF_SIZE
    want_gui = scene.display_available() if gui is None else gui
    with scene.compiled(checked) as urdfs, scene.connect(gui=want_gui) as client:
        client.setTimeStep(TIME_STEP)
        stage = Stage.build(client, [r], urdfs, {r.name: traj.q[0]})
        if record is not None or client.gui:
            _frame(client, stage, r, traj, size, azimuth)
        stage.scenes[r.name].set_q(traj.q[0])
        stage.place_axes()
        run = _run(client, stage, r, traj, record is not None, fps, size)
    lines = _report(r, traj, run)
    if record is not None:
        save_gif(run.frames, record, fps)
        lines.append(f"  wrote {record}: {len(run.frames)} frames at {fps:g} fps, {size[0]}x{size[1]}")
    return True, lines, checked


def _play_mujoco(checked, r, traj, record, fps: float, size) -> list[str]:
    from . import mujoco_play

    run = mujoco_play.play_in_mujoco(checked, r, traj, record, fps, size, HOLD_AFTER, CHECK_HZ)
    lines = mujoco_play.report_lines(r, traj, run, TIME_STEP, HOLD_AFTER) + _contact_lines(run)
    if record is not None:
        save_gif(run.frames, record, fps)
        w, h = run.frames[0].size
        lines.append(f"  wrote {record}: {len(run.frames)} frames at {fps:g} fps, {w}x{h}")
    return lines


def _trajectory_for(checked, traj_json, robot: str | None):
    """(robot, trajectory in joint_1 … joint_n order, errors): the file read, its robot chosen,
    the trajectory checked against that robot."""
    try:
        traj, errors = trajectory.load(traj_json)
    except OSError as e:
        raise scene.UsageError(f"cannot read {traj_json}: {e.strerror or e}") from None
    if traj is None:
        return None, None, errors
    r = pick_robot(checked, traj, robot)
    errors = trajectory.validate_for(traj, r)
    if errors:
        return r, traj, errors
    return r, traj.in_order([f"joint_{i}" for i in range(1, r.dof + 1)]), []


def _frame(client, stage, r, traj, size: tuple[int, int], azimuth: float | None) -> None:
    """Ground, tool0 axes and a camera fitted to CAMERA_SAMPLES configurations of the motion
    (the GUI's camera too)."""
    import numpy as np

    stage.add_tool_axes()
    samples = [traj.at(traj.t[0] + traj.duration * k / (CAMERA_SAMPLES - 1)) for k in range(CAMERA_SAMPLES)]
    per_sample = []
    for q in samples:
        stage.set({r.name: q})
        per_sample.append(stage.points())
    pts = np.concatenate(per_sample)
    stage.add_ground(pts)
    cam = stage.choose_camera(pts, size[0], _scene_height(size), azimuth, poses=[{r.name: q} for q in samples])
    if client.gui:
        client.resetDebugVisualizerCamera(float(np.linalg.norm(np.subtract(cam.eye, cam.target))),
                                          cam.azimuth + 90.0, -cam.elevation, list(cam.target))


def _scene_height(size: tuple[int, int]) -> int:
    """Pixels of a frame above its caption band."""
    from . import caption

    return size[1] - caption.band_height(size[1])


def _captioned(stage, r, traj, t: float, size: tuple[int, int]):
    """One GIF frame: the scene from the stage's camera, the caption band below, targets labelled."""
    from ..physical.camera import project
    from . import caption

    h = _scene_height(size)
    img = caption.below(stage.shoot(stage.camera, size[0], h, supersample=GIF_SUPERSAMPLE), size[1])
    s = stage.scenes[r.name]
    labels = [(name, tuple(project(stage.camera, stage.client.getBasePositionAndOrientation(body)[0], size[0], h)[0]))
              for name, body in s.targets.items()]
    return caption.draw(img, f"{r.name}  {r.sequence}", f"t = {t:.2f} s of {traj.duration:.2f} s  (PyBullet)", labels)


@dataclass
class _Run:
    """What playing the trajectory showed."""

    frames: list = field(default_factory=list)
    contacts: dict = field(default_factory=dict)  # (link, other) -> (first time, deepest)
    worst: Any = None  # worst tracking error per joint during the motion (rad)
    final: Any = None  # tracking error per joint after HOLD_AFTER at the last point (rad)
    mode: str = "headless"
    obstacles: tuple[str, ...] = ()


def _run(client, stage, r, traj, recording: bool, fps: float, size: tuple[int, int]) -> _Run:
    """The actuators follow the trajectory at 1 kHz (then hold its last point for HOLD_AFTER):
    contacts CHECK_HZ times a second, a frame every 1 / fps s when recording, real time in the GUI."""
    import numpy as np

    s = stage.scenes[r.name]
    run = _Run(worst=np.zeros(r.dof), obstacles=tuple(s.obstacles))
    t0, t_end = traj.t[0], traj.t[-1] + HOLD_AFTER
    steps = int(round((t_end - t0) / TIME_STEP))
    next_frame, next_check = 0.0, 0.0
    started = wallclock.monotonic()
    for k in range(steps + 1):
        t = k * TIME_STEP
        if t + 1e-12 >= next_check:
            for c in s.self_collisions() + s.environment_collisions():
                key = (c.a, c.b)
                if key not in run.contacts or c.depth > run.contacts[key][1]:
                    run.contacts[key] = (run.contacts.get(key, (t0 + t,))[0], c.depth)
            next_check += 1.0 / CHECK_HZ
        if recording and t + 1e-12 >= next_frame:
            stage.place_axes()
            run.frames.append(_captioned(stage, r, traj, t0 + t, size))
            next_frame += 1.0 / fps
        if k == steps:
            break
        q_cmd = traj.at(t0 + t)
        q_next = traj.at(t0 + t + TIME_STEP)
        s.hold(q_cmd, [(b - a) / TIME_STEP for a, b in zip(q_cmd, q_next, strict=True)])
        client.stepSimulation()
        if k % 10 == 0:
            run.worst = np.maximum(run.worst, np.abs(s.q() - np.array(traj.at(t0 + t + TIME_STEP))))
        if client.gui:
            ahead = (t + TIME_STEP) - (wallclock.monotonic() - started)
            if ahead > 0:
                wallclock.sleep(ahead)
    run.final = np.abs(s.q() - np.array(traj.q[-1]))
    run.mode = "in the PyBullet GUI" if client.gui else "headless"
    return run


def _report(r, traj, run: _Run) -> list[str]:
    import numpy as np

    j = int(np.argmax(run.worst))
    lines = [f"play: robot {r.name} ({r.sequence}), {len(traj.t)} points over {traj.duration:.2f} s, "
             f"simulated at {1 / TIME_STEP:.0f} Hz {run.mode}",
             f"  worst tracking error {run.worst[j]:.2g} rad (joint_{j + 1}) during the motion, "
             f"{run.final.max():.1g} rad after {HOLD_AFTER:g} s at the last point"]
    return lines + _contact_lines(run)


def _contact_lines(run) -> list[str]:
    """The contacts seen while playing (either engine's run: contacts, obstacles)."""
    lines = []
    for (a, b), (t_first, depth) in sorted(run.contacts.items(), key=lambda kv: kv[1][0]):
        what = f"obstacle {b}" if b in run.obstacles else b
        lines.append(f"  warning: {a} collides with {what} from t = {t_first:.2f} s "
                     f"({depth * 1000:.1f} mm deep at most)")
    return lines or ["  no collisions (between links, or with the environment)"]
