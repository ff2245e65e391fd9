"""`modc play FILE --traj T.json --engine mujoco [--record X.gif]`: play a trajectory in MuJoCo, on
the compiled MJCF scene (mjcf/scene_*.xml, the bytes `modc FILE -o OUT` writes).

The arm starts at rest at the first point; its servos (the MJCF's position actuators: kp, kv, the
peak-torque force limit) follow the trajectory (linear between points, trajectory.py) at the
model's 1 ms step, then hold the last point for play.HOLD_AFTER.

Feed-forward. A bare position servo lags: kv pulls the velocity towards 0, and gravity and inertia
are carried only by position error (up to ERROR_AT_PEAK, 5 mrad, at peak torque; 0.046 rad seen
on the examples). So the servos are fed the trajectory and what it takes to follow it:

  reference  linear between points has velocity steps at every point, which no bounded torque
             follows; the servos get the trajectory averaged over SMOOTH (10 ms, centred), whose
             velocity is continuous and which stays within |Δv| · SMOOTH / 8 of the file's motion
             (0.2 rad/s steps: 2.5e-4 rad). The run starts SMOOTH / 2 early, at rest at the first
             point, where the averaged reference starts.
  torque     each step mj_inverse at the reference state (q, q̇ over the last step, and the q̈ that
             reaches the next step's q as MuJoCo's integrator steps) gives τ, and the command is

                 ctrl = q_ref + (τ + kv · q̇_next) / kp,  so that
                 force = kp (q_ref − q) + kv (q̇_next − q̇) + τ

             through the actuator, clamped to its peak torque (a run that saturates says so).
             The MJCF's ctrlrange (the joint range) is lifted for the offset only.

The tracking error is measured against the file's motion (linear between points), every step
from its first point to its last. Contacts are off: as in PyBullet's playback obstacles do not
push the arm; self and environment contacts are looked for play.CHECK_HZ times a second
geometrically (mujoco_engine's queries) and reported.

--record renders with MuJoCo's offscreen renderer (EGL without a display; MUJOCO_GL chooses)
from one camera fitted to the whole motion (physical.camera, as `modc render`), captioned, and writes
the GIF with play.save_gif.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from ..physical.camera import FOV, fit_camera, project
from . import caption

GIF_SIZE = (800, 600)
SMOOTH = 0.01  # s: the servos are fed the trajectory averaged over this window (see above)
CAMERA_SAMPLES = 9
SHADOW_SIZE = 1024  # px: the scene's default 4096 costs twice the time per frame in a software renderer


@dataclass
class MujocoRun:
    frames: list = field(default_factory=list)
    contacts: dict = field(default_factory=dict)  # (link, other) -> (first time, deepest)
    worst: Any = None  # rad per joint, during the motion
    final: Any = None  # rad per joint after HOLD_AFTER
    peak_force: Any = None  # N·m per joint, the largest servo force
    saturated: Any = None  # steps per joint at the force limit
    obstacles: tuple[str, ...] = ()


def play_in_mujoco(checked, r, traj, record, fps: float, size: tuple[int, int] | None, hold_after: float,
                   check_hz: float) -> MujocoRun:
    from . import mujoco_engine
    from .scene import compiled

    mujoco_engine.import_mujoco()
    with compiled(checked, "mjcf") as xmls:
        s = mujoco_engine.load(r, xmls[r.name])
        renderer = _Recorder(s, r, traj, size or GIF_SIZE, hold_after) if record is not None else None
        try:
            return _run(s, r, traj, renderer, fps, hold_after, check_hz)
        finally:
            if renderer is not None:
                renderer.close()


def reference(traj, dt: float, hold_after: float, smooth: float):
    """(times, q_linear, q_smooth): the trajectory at every step from t0 - smooth / 2 (at rest at
    its first point) to its end + hold_after, linear between points (the file's meaning) and
    averaged over a centred window of `smooth` s (what the servos are fed)."""
    import numpy as np

    half = max(1, round(smooth / dt / 2))
    t0 = traj.t[0] - half * dt
    n = int(round((traj.duration + hold_after) / dt)) + half
    times = t0 + dt * np.arange(-half, n + half + 3)
    q = np.array([traj.at(float(t)) for t in times])
    kernel = np.ones(2 * half + 1) / (2 * half + 1)
    smooth_q = np.stack([np.convolve(q[:, j], kernel, mode="valid") for j in range(q.shape[1])], axis=1)
    return times[half:-half], q[half:-half], smooth_q


def _run(s, r, traj, recorder, fps: float, hold_after: float, check_hz: float) -> MujocoRun:
    import mujoco
    import numpy as np

    m = s.model
    m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT
    m.actuator_ctrllimited[:] = 0  # the feed-forward offset may pass the joint range (see above)
    d, ref = mujoco.MjData(m), mujoco.MjData(m)
    kp, kv = m.actuator_gainprm[:, 0].copy(), -m.actuator_biasprm[:, 2].copy()
    limit = m.actuator_forcerange[:, 1].copy()
    dt = float(m.opt.timestep)
    times, linear, fed = reference(traj, dt, hold_after, SMOOTH)
    run = MujocoRun(worst=np.zeros(r.dof), peak_force=np.zeros(r.dof), saturated=np.zeros(r.dof, dtype=int),
                    obstacles=tuple(s.obstacles))
    d.qpos[:] = fed[1]
    mujoco.mj_forward(m, d)
    next_frame, next_check = traj.t[0], traj.t[0]
    for k in range(1, len(times) - 2):
        t = float(times[k])
        if t + 1e-12 >= next_check:
            s.set_q(d.qpos)
            for c in s.self_collisions() + s.environment_collisions():
                key = (c.a, c.b)
                if key not in run.contacts or c.depth > run.contacts[key][1]:
                    run.contacts[key] = (run.contacts.get(key, (t,))[0], c.depth)
            next_check += 1.0 / check_hz
        if recorder is not None and t + 1e-12 >= next_frame:
            run.frames.append(recorder.frame(d, t))
            next_frame += 1.0 / fps
        # the reference state now (its velocity over the last step) and the acceleration that brings
        # it to the next point in one step, as MuJoCo integrates: v' = v + a dt, q' = q + v' dt
        v0, v1 = (fed[k] - fed[k - 1]) / dt, (fed[k + 1] - fed[k]) / dt
        ref.qpos[:], ref.qvel[:], ref.qacc[:] = fed[k], v0, (v1 - v0) / dt
        mujoco.mj_inverse(m, ref)
        d.ctrl[:] = fed[k] + (ref.qfrc_inverse + kv * v1) / kp  # implicitfast damps the new velocity
        mujoco.mj_step(m, d)
        force = np.abs(d.actuator_force)
        run.peak_force = np.maximum(run.peak_force, force)
        run.saturated += force >= limit * (1 - 1e-9)
        if traj.t[0] - 1e-12 <= times[k + 1] <= traj.t[-1] + 1e-12:
            run.worst = np.maximum(run.worst, np.abs(d.qpos - linear[k + 1]))
    run.final = np.abs(d.qpos - np.array(traj.q[-1]))
    return run


class _Recorder:
    """MuJoCo's offscreen renderer on the scene, one free camera fitted to CAMERA_SAMPLES
    configurations of the motion, frames captioned."""

    def __init__(self, s, r, traj, size: tuple[int, int], hold_after: float):
        import mujoco
        import numpy as np

        m = s.model
        w, h = size
        m.vis.global_.offwidth, m.vis.global_.offheight = max(w, int(m.vis.global_.offwidth)), \
            max(h, int(m.vis.global_.offheight))
        m.vis.global_.fovy = FOV
        m.vis.quality.shadowsize = SHADOW_SIZE
        self.size, self.robot, self.traj = size, r, traj
        try:
            self.renderer = mujoco.Renderer(m, h, w)
        except Exception as e:  # no GL: mujoco.FatalError, or ImportError/RuntimeError of the platform
            from .scene import UsageError

            raise UsageError(f"--record: MuJoCo cannot render offscreen here ({type(e).__name__}: {e}); "
                             f"install EGL (Debian: libegl1) or OSMesa (libosmesa6, MUJOCO_GL=osmesa)") from None
        pts = []
        for k in range(CAMERA_SAMPLES):
            s.set_q(traj.at(traj.t[0] + traj.duration * k / (CAMERA_SAMPLES - 1)))
            pts.append(_world_points(m, s.data))
        cam = fit_camera(np.concatenate(pts), 210.0, 30.0, w / h, fill=0.85)  # clear of the caption band
        from ..backends.mjcf import TARGET_PREFIX

        self.labels = [(t.name, project(cam, s.data.site(TARGET_PREFIX + t.name).xpos, w, h)[0]) for t in r.targets]
        self.camera = mujoco.MjvCamera()
        self.camera.type = mujoco.mjtCamera.mjCAMERA_FREE
        self.camera.lookat[:] = cam.target
        self.camera.distance = float(np.linalg.norm(np.subtract(cam.eye, cam.target)))
        self.camera.azimuth, self.camera.elevation = (cam.azimuth + 180.0) % 360.0, -cam.elevation
        self.option = mujoco.MjvOption()
        self.option.label = mujoco.mjtLabel.mjLABEL_NONE

    def frame(self, d, t: float):
        from PIL import Image

        self.renderer.update_scene(d, camera=self.camera, scene_option=self.option)
        img = Image.fromarray(self.renderer.render())
        r = self.robot
        return caption.draw(img, f"{r.name}  {r.sequence}", f"t = {t:.2f} s of {self.traj.duration:.2f} s  (MuJoCo)",
                            self.labels)

    def close(self) -> None:
        self.renderer.close()


def _world_points(m, d):
    """Corners of every geom's bounding box but planes' (arm, obstacles), and the sites."""
    import numpy as np

    pts = [d.site_xpos - 0.012, d.site_xpos + 0.012]
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
    for g in range(m.ngeom):
        if m.geom_type[g] == 0:  # mjGEOM_PLANE: the floor is infinite
            continue
        centre, half = m.geom_aabb[g, :3], m.geom_aabb[g, 3:]
        local = centre + signs * half
        pts.append(d.geom_xpos[g] + local @ d.geom_xmat[g].reshape(3, 3).T)
    return np.concatenate(pts)


def report_lines(r, traj, run: MujocoRun, dt: float, hold_after: float) -> list[str]:
    import numpy as np

    j = int(np.argmax(run.worst))
    per_joint = ", ".join(f"{v:.1e}" for v in run.worst)
    lines = [f"play: robot {r.name} ({r.sequence}), {len(traj.t)} points over {traj.duration:.2f} s, "
             f"simulated in MuJoCo at {1 / dt:.0f} Hz with inverse-dynamics feed-forward, headless",
             f"  worst tracking error {run.worst[j]:.2g} rad (joint_{j + 1}) during the motion, "
             f"{run.final.max():.1g} rad after {hold_after:g} s at the last point",
             f"  tracking error per joint (max, rad): {per_joint}"]
    if run.saturated.any():
        joints = ", ".join(f"joint_{i + 1}" for i in np.flatnonzero(run.saturated))
        lines.append(f"  warning: the servos of {joints} reached their peak torque (the motion asks for more)")
    return lines


__all__ = ["GIF_SIZE", "MujocoRun", "play_in_mujoco", "report_lines"]
