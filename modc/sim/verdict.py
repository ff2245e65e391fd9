"""The smoke test's verdicts, apart from the engine that measured them (smoke.py measures in
PyBullet; another engine fills the same Measured and gets the same checks and messages).

    measured = Measured(name, q, T_base_tool, self_contacts, environment_contacts, hold)
    result = judge_pose(robot, measured, Chain(robot), Dynamics(robot), engine="PyBullet")
    lines = describe(RobotResult(robot.name, robot.sequence, poses=[result, ...]))

An engine's hold loop keeps its books with a HoldRecorder (sampling, divergence, the settle
window), which makes the Measured's Hold.

The checks and their tolerances are explained in smoke.py's docstring.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from ..formatting import angle_text
from ..model import ResolvedRobot

TRACK_TOL = 1e-2  # rad
FK_POS_TOL = 1e-6  # m (PyBullet computes in single precision)
FK_ROT_TOL = 1e-5
TORQUE_TOL, TORQUE_REL = 1e-3, 1e-3  # N·m, and share of the gravity torque
SATURATION = 0.999  # |applied torque| >= this share of the effort: the motor is at its limit


@dataclass(frozen=True)
class Failure:
    kind: str  # load | fk | self-collision | environment | sag | unstable | torque
    message: str  # complete sentence, names the robot and pose
    joint: str | None = None
    links: tuple[str, ...] = ()


@dataclass
class PoseResult:
    name: str
    q: tuple[float, ...]
    track_error: list[float] = field(default_factory=list)  # rad per joint, worst over the window
    fk_pos_error: float = 0.0
    fk_rot_error: float = 0.0
    max_velocity: float = 0.0
    torque_error: float = 0.0  # N·m, the engine's holding torques against modc.dynamics' gravity torques
    failures: list[Failure] = field(default_factory=list)


@dataclass
class RobotResult:
    robot: str
    sequence: str
    poses: list[PoseResult] = field(default_factory=list)
    failures: list[Failure] = field(default_factory=list)  # load failures

    @property
    def all_failures(self) -> list[Failure]:
        return self.failures + [f for p in self.poses for f in p.failures]

    @property
    def ok(self) -> bool:
        return not self.all_failures


@dataclass(frozen=True)
class Hold:
    """What the engine saw while its actuators held a pose (position control limited to the
    actuators' peak torque and rated speed). Arrays are per joint, joint_1 first."""

    worst: Any  # |q - target|, worst over the settle window (rad)
    peak: Any  # |q - target|, worst over the whole hold (rad)
    max_velocity: float  # rad/s, over the hold
    diverged: str | None  # what blew up ("joint_2 reached 80 rad/s after 0.120 s"), or None
    applied: Any  # joint torques, mean over the settle window (N·m)
    q_end: Any  # where the arm rests at the end (rad)
    tau_end: Any  # joint torques at the end (N·m)
    efforts: tuple[float, ...]  # the engine's torque limits (the URDF effort: the actuator's peak)


@dataclass(frozen=True)
class Measured:
    """One pose as an engine measured it. Contacts: objects with .a, .b and .depth (m)."""

    name: str
    q: tuple[float, ...]
    T_base_tool: Any  # 4x4, tool0 in base_link with the joints at q
    self_contacts: list
    environment_contacts: list
    hold: Hold


SAMPLE_EVERY = 10  # steps between samples before the settle window (every step within it)
EXPLODE_VELOCITY = 50.0  # rad/s: no falling module comes near this; beyond it the simulation diverged


class HoldRecorder:
    """What an engine's hold loop records, the same for every engine: call step(k) for each
    step k of `steps`; when it says so, sample(k, q, qd, tau) (False: the simulation diverged,
    stop); then hold(q_end, tau_end, efforts)."""

    def __init__(self, target, joint_names: list[str], steps: int, window: int, time_step: float):
        import numpy as np

        n = len(target)
        self.target, self.joint_names, self.time_step = np.asarray(target, dtype=float), joint_names, time_step
        self.late_from = steps - window
        self.worst, self.peak = np.zeros(n), np.zeros(n)  # over the settle window / the whole hold
        self.tau_sum, self.tau_n = np.zeros(n), 0  # applied torques over the settle window
        self.vmax = 0.0
        self.diverged: str | None = None

    def wants(self, k: int) -> bool:
        return k >= self.late_from or k % SAMPLE_EVERY == 0

    def sample(self, k: int, q, qd, tau) -> bool:
        import numpy as np

        if not (np.all(np.isfinite(q)) and np.all(np.isfinite(qd))):
            self.diverged = f"joint states became NaN after {k * self.time_step:.3f} s"
            return False
        error = np.abs(np.asarray(q) - self.target)
        self.vmax = max(self.vmax, float(np.abs(qd).max()))
        self.peak = np.maximum(self.peak, error)
        if self.vmax > EXPLODE_VELOCITY:
            j = int(np.argmax(np.abs(qd)))
            self.diverged = f"{self.joint_names[j]} reached {abs(qd[j]):.0f} rad/s after {k * self.time_step:.3f} s"
            return False
        if k >= self.late_from:
            self.worst = np.maximum(self.worst, error)
            self.tau_sum += tau
            self.tau_n += 1
        return True

    def hold(self, q_end, tau_end, efforts) -> Hold:
        return Hold(worst=self.worst, peak=self.peak, max_velocity=self.vmax, diverged=self.diverged,
                    applied=self.tau_sum / max(self.tau_n, 1), q_end=q_end, tau_end=tau_end,
                    efforts=tuple(float(e) for e in efforts))


def judge_pose(robot: ResolvedRobot, m: Measured, chain, dyn, engine: str = "PyBullet",
               fk_tol: tuple[float, float] = (FK_POS_TOL, FK_ROT_TOL)) -> PoseResult:
    """Every check of one pose: FK against modc.kinematics (chain), collisions, the hold, and
    the holding torques against modc.dynamics (dyn)."""
    import numpy as np

    pr = PoseResult(m.name, m.q)
    at = f"robot {robot.name}, pose {m.name}"
    qv = np.array(m.q, dtype=float)
    T_ref = chain.T_base_tool(qv)
    pr.fk_pos_error = float(np.abs(m.T_base_tool[:3, 3] - T_ref[:3, 3]).max())
    pr.fk_rot_error = float(np.abs(m.T_base_tool[:3, :3] - T_ref[:3, :3]).max())
    pos_tol, rot_tol = fk_tol
    if pr.fk_pos_error > pos_tol or pr.fk_rot_error > rot_tol:
        pr.failures.append(
            Failure(
                "fk",
                f"{at}: {engine} puts tool0 {pr.fk_pos_error:.3g} m / {pr.fk_rot_error:.3g} (rotation) "
                f"away from modc's kinematics (tolerance {pos_tol:g} m, {rot_tol:g})",
            )
        )
    for c in m.self_contacts:
        pr.failures.append(
            Failure("self-collision", f"{at}: {c.a} and {c.b} collide ({c.depth * 1000:.1f} mm deep)", links=(c.a, c.b))
        )
    for c in m.environment_contacts:
        pr.failures.append(
            Failure(
                "environment", f"{at}: {c.a} is inside obstacle {c.b} ({c.depth * 1000:.1f} mm deep)", links=(c.a, c.b)
            )
        )
    h = m.hold
    pr.max_velocity = h.max_velocity
    pr.track_error = [float(e) for e in h.worst]
    if h.diverged:
        pr.failures.append(Failure("unstable", f"{at}: the simulation diverged: {h.diverged}"))
        return pr
    pr.failures += _hold_failures(robot, pr, h, qv, dyn, at, engine)
    return pr


def _hold_failures(robot: ResolvedRobot, pr: PoseResult, h: Hold, qv, dyn, at: str, engine: str) -> list[Failure]:
    """Joints that sag, and holding torques that disagree with modc's gravity torques (compared
    only when the whole arm is at rest, where it actually rests)."""
    import numpy as np

    out = []
    tau_g = dyn.gravity(qv)
    applied = np.asarray(h.applied)
    worst = np.asarray(h.worst)
    held = bool(np.all(worst <= TRACK_TOL))
    tau_here = dyn.gravity(h.q_end)
    pr.torque_error = float(np.abs(applied - tau_here).max()) if held else float("nan")
    for j in range(robot.dof):
        name = f"joint_{j + 1}"
        if held and abs(applied[j] - tau_here[j]) > TORQUE_TOL + TORQUE_REL * abs(tau_here[j]):
            out.append(Failure(
                "torque", f"{at}: {engine} holds {name} with {applied[j]:.4f} N·m, modc's dynamics (pinocchio) says "
                          f"gravity takes {tau_here[j]:.4f} N·m: the two models of the arm disagree", joint=name))
        if worst[j] <= TRACK_TOL:
            continue
        effort = h.efforts[j]
        variant = robot.units[j].variant
        actuator = robot.library.variants[variant].actuator
        if abs(tau_g[j]) > effort or abs(h.tau_end[j]) >= SATURATION * effort:
            why = (
                f"holding the pose needs {abs(tau_g[j]):.2f} N·m, the {variant} actuator ({actuator.model}) peaks at "
                f"{effort:g} N·m: it cannot hold the arm"
            )
        else:
            why = (
                f"the motor is below its {effort:g} N·m peak (needs {abs(tau_g[j]):.2f} N·m) "
                "yet the joint does not settle"
            )
        out.append(
            Failure(
                "sag",
                f"{at}: {name} sags {h.peak[j]:.2f} rad ({angle_text(h.peak[j])}) "
                f"from its target {angle_text(qv[j])}: {why}",
                joint=name,
            )
        )
    return out


def describe(res: RobotResult) -> list[str]:
    """Report lines: one for the robot, one per pose, then every failure."""
    lines = []
    state = "ok" if res.ok else f"{len(res.all_failures)} failure(s)"
    lines.append(f"robot {res.robot} ({res.sequence}): {state}")
    for f in res.failures:
        lines.append(f"  FAIL {f.message}")
    for p in res.poses:
        if p.failures:
            lines.append(f"  pose {p.name}: FAILED")
        else:
            j = max(range(len(p.track_error)), key=lambda i: p.track_error[i])
            lines.append(f"  pose {p.name}: ok; held to {p.track_error[j]:.1e} rad (worst: joint_{j + 1}), "
                         f"tool0 within {p.fk_pos_error:.1e} m of modc's kinematics, holding torques within "
                         f"{p.torque_error:.1e} N·m of modc's dynamics, no collisions")
        for f in p.failures:
            lines.append(f"  FAIL {f.message}")
    return lines


__all__ = ["EXPLODE_VELOCITY", "FK_POS_TOL", "FK_ROT_TOL", "SATURATION", "TORQUE_REL", "TORQUE_TOL", "TRACK_TOL",
           "Failure", "Hold", "HoldRecorder", "Measured", "PoseResult", "RobotResult", "describe", "judge_pose"]
