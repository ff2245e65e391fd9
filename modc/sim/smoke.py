"""`modc sim FILE`: a PyBullet smoke test of every robot in a file.

For each robot, its URDF and meshes (exactly what `modc FILE -o OUT` writes) are loaded into a
headless PyBullet world (scene.py: base_link at `base`, gravity -z of the world, obstacles as
static bodies), then:

  load      PyBullet prints nothing while loading (any b3Warning / b3Error / "failed" line is a
            failure, quoted), every URDF link has an <inertial> with positive mass and principal
            moments, and PyBullet sees one revolute joint per module.
  per pose  `home` (Robot.home: the pose named home, else MoveIt's default values), then every other named pose:
    FK          PyBullet's tool0 frame equals modc.kinematics (docs/conventions.md) to FK_POS_TOL /
                FK_ROT_TOL: the pip wheel of PyBullet computes in single precision, so 1e-6 m and
                1e-5 (rotation-matrix entries), not the 1e-9 the double-precision consumers meet.
    self        no two links collide, except the pairs the collision matrix skips (in memory, as
                `modc plan`; or the SRDF of --srdf-from OUT): Adjacent (parent-child, and
                neighbours of a link without geometry such as tool0) / Default / Always ("Never"
                pairs are checked: they are disabled for MoveIt's speed, a pose that brings them
                into contact is a collision).
    environment no link is inside an obstacle.
    hold        the joints are put at the pose at rest, every actuator holds its target with
                POSITION_CONTROL (force = the URDF effort = the actuator's peak torque,
                maxVelocity = the URDF velocity = its rated speed), and HOLD_TIME of simulated
                time passes at 1 kHz (TIME_STEP). Then:
                every joint stays within TRACK_TOL of its target over the last SETTLE_WINDOW,
                and nothing explodes (finite states, |velocity| < EXPLODE_VELOCITY).
    torque      when every joint holds: the torque PyBullet's motors apply (averaged over the
                settle window) equals the static gravity torque of modc.dynamics (pinocchio on
                the same URDF, gravity turned by the base placement: what `modc check` uses) at
                the resting configuration, to TORQUE_TOL + TORQUE_REL · |tau|: the two engines
                agree on masses, centres of mass and the direction of gravity (measured over
                the examples: within 1e-8 N·m).

Why TRACK_TOL = 1e-2 rad. PyBullet's POSITION_CONTROL is a velocity servo solved as a
constraint: it leaves a numerical steady-state error of about tau_gravity · dt² / (kp · inertia),
which is no property of the arm. At 1 kHz and PyBullet's default gains it is at most 1.5e-4 rad
over the examples (2.5e-3 rad at PyBullet's default 240 Hz, hence the finer step). A joint whose
actuator cannot hold the arm saturates at its peak torque and falls: tenths of a radian within
the first second. 1e-2 rad (0.57°, 2 mm at the end of a 0.22 m link) separates the two by more
than an order of magnitude on both sides. When a joint fails, the message gives the static
gravity torque at the pose (modc.dynamics; PyBullet's own calculateInverseDynamics ignores a
fixed base's orientation, so it is not used) next to the actuator's peak.

Measuring and judging are apart: load_failures and measure_pose ask PyBullet, verdict.judge_pose
turns a verdict.Measured into the checks above and their messages (tolerances in verdict.py), so
another engine reuses the checks by filling a Measured.
"""
from __future__ import annotations

import re
from pathlib import Path

from ..model import ResolvedRobot
from ..physical.constants import GRAVITY, TIME_STEP
from . import scene
from .contacts import srdf_disabled_pairs
from .verdict import (  # noqa: F401  (the tolerances are part of this module's story)
    EXPLODE_VELOCITY,
    FK_POS_TOL,
    FK_ROT_TOL,
    TRACK_TOL,
    Failure,
    Hold,
    HoldRecorder,
    Measured,
    RobotResult,
    describe,
    judge_pose,
)

HOLD_TIME = 2.0  # s of simulated time per pose
SETTLE_WINDOW = 0.5  # s: tracking is judged over the end of the hold
WARNING_LINE = re.compile(r"warning|error|failed|cannot|unable", re.IGNORECASE)


def check_urdf_inertials(urdf: Path) -> list[str]:
    """Links of the URDF without a usable <inertial> (PyBullet would silently give them 1 kg)."""
    import xml.etree.ElementTree as ET

    bad = []
    for link in ET.parse(urdf).getroot().iter("link"):
        name = link.get("name")
        inertial = link.find("inertial")
        mass_el = None if inertial is None else inertial.find("mass")
        inertia = None if inertial is None else inertial.find("inertia")
        if mass_el is None or inertia is None:
            bad.append(f"link {name} has no <inertial> with mass and inertia")
            continue
        mass = float(mass_el.get("value", "0"))
        diag = [float(inertia.get(k, "0")) for k in ("ixx", "iyy", "izz")]
        if not mass > 0 or not all(d > 0 for d in diag):
            bad.append(f"link {name} has mass {mass:g} kg and principal inertia {diag}")
    return bad


def simulate_robot(client, robot: ResolvedRobot, urdf: Path, allowed=(), hold_time: float = HOLD_TIME,
                   time_step: float = TIME_STEP) -> RobotResult:
    """Load one robot into an empty client and run every check (see the module docstring):
    PyBullet measures each pose (measure_pose), verdict.judge_pose judges it."""
    from ..dynamics.model import Dynamics
    from ..kinematics import Chain

    res = RobotResult(robot.name, robot.sequence)
    client.resetSimulation()
    client.setGravity(0, 0, -GRAVITY)
    client.setTimeStep(time_step)
    try:
        s = scene.load_robot(client, robot, urdf)
    except Exception as e:  # pybullet.error: a URDF or mesh PyBullet cannot read
        res.failures.append(Failure("load", f"robot {robot.name}: PyBullet cannot load {urdf.name}: {e}"))
        return res
    res.failures += load_failures(client, s, robot, urdf)
    chain, dyn = Chain(robot), Dynamics(robot)
    steps = max(1, round(hold_time / time_step))
    window = max(1, round(SETTLE_WINDOW / time_step))
    for pname, q in robot.named_poses():
        measured = measure_pose(client, s, pname, q, allowed, steps, window, time_step)
        res.poses.append(judge_pose(robot, measured, chain, dyn, engine="PyBullet"))
    s.remove()
    return res


def load_failures(client, s, robot: ResolvedRobot, urdf: Path) -> list[Failure]:
    """What PyBullet printed while loading, links without a usable inertial (in the URDF and
    as PyBullet sees them), and the number of revolute joints."""
    who = f"robot {robot.name}"
    out = []
    for line in s.load_log.splitlines():
        if WARNING_LINE.search(line):
            out.append(Failure("load", f"{who}: PyBullet, loading {urdf.name}: {line.strip()}"))
    for msg in check_urdf_inertials(urdf):
        out.append(Failure("load", f"{who}: {msg}"))
    for name, i in s.links.items():
        if i == -1:
            continue  # the fixed base: PyBullet reports mass 0 for it by design
        mass, _, inertia = client.getDynamicsInfo(s.body, i)[:3]
        if not mass > 0 or not all(v > 0 for v in inertia):
            out.append(Failure("load", f"{who}: PyBullet gives link {name} mass {mass:g} kg, inertia {inertia}"))
    if len(s.joints) != robot.dof:
        out.append(
            Failure("load", f"{who}: PyBullet finds {len(s.joints)} revolute joints, the chain has {robot.dof} modules")
        )
    return out


def measure_pose(client, s, name: str, q, allowed, steps: int, window: int, time_step: float) -> Measured:
    """The pose in PyBullet: tool0 and the contacts with the joints teleported to q, then the
    actuators holding q for `steps` steps (tracking over the last `window` of them)."""
    import numpy as np

    qv = np.array(q, dtype=float)
    s.set_q(qv)
    T_tool = s.T_base_link("tool0")
    self_contacts, env_contacts = s.self_collisions(allowed), s.environment_collisions()
    s.set_q(qv)
    s.hold(qv)
    return Measured(name, tuple(q), T_tool, self_contacts, env_contacts, _hold(client, s, qv, steps, window, time_step))


def _hold(client, s, qv, steps: int, window: int, time_step: float) -> Hold:
    rec = HoldRecorder(qv, s.joint_names, steps, window, time_step)
    for k in range(steps):
        client.stepSimulation()
        if rec.wants(k) and not rec.sample(k, s.q(), s.qd(), s.applied_torques()):
            break
    return rec.hold(s.q(), s.applied_torques(), [s.limits[j][2] for j in s.joint_names])


def allowed_pairs(out_dir: str | Path | None, robot: ResolvedRobot) -> set[frozenset[str]]:
    """The link pairs not checked for self-collision: the collision matrix in memory (the one the
    SRDF backend writes and `modc plan` uses, with the same defaults), or, given a compile
    output (--srdf-from OUT), the pairs its SRDF disables (compiled with other samples, say)."""
    if out_dir is not None:
        srdf = Path(out_dir) / "config" / f"{robot.file_stem}.srdf"
        if srdf.is_file():
            return srdf_disabled_pairs(srdf)
    from ..physical.assembly import describe
    from ..physical.collisions import cached_matrix

    return cached_matrix(describe(robot)).unchecked()


def simulate(checked, robot: str | None = None, out_dir: str | Path | None = None,
             hold_time: float = HOLD_TIME) -> list[RobotResult]:
    """Every (or the named) robot of a checked design without errors."""
    robots = scene.select_robots(checked, robot)
    results = []
    with scene.compiled(checked) as urdfs, scene.connect() as client:
        for r in robots:
            results.append(simulate_robot(client, r, urdfs[r.name], allowed_pairs(out_dir, r), hold_time))
    return results


ENGINES = ("pybullet", "mujoco")  # the first is the default


def run_sim(path, library: str | None = None, robot: str | None = None, out_dir: str | Path | None = None,
            hold_time: float = HOLD_TIME, engine: str = ENGINES[0]):
    """`modc sim FILE [--engine E]`. Returns (ok, report lines, checked).

    engine: "pybullet" (this module) or "mujoco" (mujoco_engine.py, on the compiled MJCF); the
    checks and messages are verdict.py's either way. Raises scene.UsageError for another name.

    checked: the modc.compiler.Checked of the file (its .diagnostics and .sources are for the
    caller to print). When it has errors nothing is simulated: (False, [], checked).
    out_dir: a compile output (OUT/) whose config/<stem>.srdf disabled pairs are honoured.
    Raises modc.compiler.InputError (unreadable file) and modc.model.select.RobotChoiceError
    (unknown robot).
    """
    if engine not in ENGINES:
        raise scene.UsageError(f"unknown engine '{engine}' (choose from {', '.join(ENGINES)})")
    checked = scene.load_checked(path, library)
    if not checked.ok:
        return False, [], checked
    if engine == "mujoco":
        from . import mujoco_engine

        results = mujoco_engine.simulate(checked, robot, out_dir, hold_time)
    else:
        results = simulate(checked, robot, out_dir, hold_time)
    lines = [line for r in results for line in describe(r)]
    failures = sum(len(r.all_failures) for r in results)
    poses = sum(len(r.poses) for r in results)
    if failures:
        lines.append(f"sim: {failures} failure(s) in {len(results)} robot(s)")
    else:
        lines.append(f"sim: {len(results)} robot(s), {poses} pose(s) held, no collisions, FK agrees")
    return not failures, lines, checked
