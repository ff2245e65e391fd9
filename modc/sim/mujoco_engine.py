"""`modc sim FILE --engine mujoco`: the smoke test of smoke.py, measured in MuJoCo on the compiled
MJCF scene (backends/mjcf.py: exactly what `modc FILE -o OUT` writes as mjcf/scene_*.xml, which
includes the robot's mjcf/*.xml, with its meshes).

The checks and messages are verdict.py's, as for PyBullet; what differs is the measuring:

  load      MuJoCo compiles the model (its error is quoted), every moving body has positive mass
            and principal moments, and there is one hinge joint and one servo per module.
  per pose  home, then every other named pose:
    FK          the tool0 site in base_link against modc.kinematics to FK_TOL: MuJoCo computes in
                double precision, so 1e-9 as the URDF's consumers (the consumers' tolerance), not PyBullet's 1e-6.
    self        signed distances between the collision geoms of link pairs (mj_geomDistance on
                the parts' primitives; the visual meshes never collide), pairs adjacent
                or skipped by the collision matrix (smoke.allowed_pairs) left out, deeper than CONTACT_TOL. The
                MJCF excludes every SRDF pair from MuJoCo's own contacts, "Never" pairs too; the
                check asks the geometry directly, so a pose that brings a "Never" pair into
                contact is still reported.
    environment every arm collision geom against every obstacle geom (the file's obstacles: the
                scene's floor is not one), the same way.
    hold        ctrl = the pose, the arm resting there; contacts switched off (obstacles are checked
                geometrically, as in PyBullet), HOLD_TIME at the model's 1 ms step with its servos
                (kp, kv and the peak-torque force limit of the MJCF). Tracking, divergence and the
                servo torques against modc.dynamics are judged by verdict.py. A holdable load rests
                within mjcf.ERROR_AT_PEAK (5e-3 rad) of its target, inside TRACK_TOL (1e-2 rad); one
                the actuator cannot carry saturates it and falls by tenths of a radian.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..model import ResolvedRobot
from .contacts import CONTACT_TOL, CollisionQueries, Contact
from .smoke import HOLD_TIME, SETTLE_WINDOW
from .verdict import Failure, Hold, HoldRecorder, Measured, RobotResult, judge_pose

FK_TOL = (1e-9, 1e-9)  # m, rotation-matrix entries
ENGINE = "MuJoCo"


def import_mujoco():
    """mujoco, with an offscreen GL chosen before its first import when there is no display (its
    GL platform is fixed when the module loads): EGL, which Debian's libegl1 provides."""
    import os
    import sys

    if "mujoco" not in sys.modules and not os.environ.get("MUJOCO_GL"):
        from .scene import display_available

        if not display_available():
            os.environ["MUJOCO_GL"] = "egl"
    import mujoco

    return mujoco


@dataclass
class MujocoScene(CollisionQueries):
    """A loaded MJCF: body names play the URDF links' part in contacts.py's adjacency rule."""

    model: Any
    data: Any
    links: dict[str, int]  # body name -> body id (the arm's bodies only)
    parents: dict[str, str]
    geometry_links: list[str]
    joint_names: list[str]
    obstacles: dict[str, int] = field(default_factory=dict)  # obstacle geom name -> geom id

    def geoms(self, body: str) -> list[int]:
        """The body's collision geoms (visual geoms have contype = conaffinity = 0)."""
        import numpy as np

        m = self.model
        colliding = (m.geom_contype != 0) | (m.geom_conaffinity != 0)
        return [int(g) for g in np.flatnonzero((m.geom_bodyid == self.links[body]) & colliding)]

    def _distance(self, g1: list[int], g2: list[int]) -> float:
        import mujoco

        return min(mujoco.mj_geomDistance(self.model, self.data, a, b, 1.0, None) for a in g1 for b in g2)

    def set_q(self, q) -> None:
        import mujoco

        self.data.qpos[:] = q
        self.data.qvel[:] = 0.0
        mujoco.mj_kinematics(self.model, self.data)

    def self_collisions(self, allowed=(), tol: float = CONTACT_TOL) -> list[Contact]:
        out = []
        for a, b in self.self_collision_pairs(allowed):
            d = self._distance(self.geoms(a), self.geoms(b))
            if d < -tol:
                out.append(Contact(a, b, float(d)))
        return sorted(out, key=lambda c: (c.distance, c.a, c.b))

    def environment_collisions(self, tol: float = CONTACT_TOL) -> list[Contact]:
        out = []
        for oname, g in self.obstacles.items():
            for lname in self.geometry_links:
                d = self._distance(self.geoms(lname), [g])
                if d < -tol:
                    out.append(Contact(lname, oname, float(d)))
        return sorted(out, key=lambda c: (c.distance, c.a, c.b))

    def T_base_tool(self):
        import numpy as np

        def pose(xpos, xmat):
            T = np.eye(4)
            T[:3, :3] = np.asarray(xmat).reshape(3, 3)
            T[:3, 3] = xpos
            return T

        base = self.data.body("base_link")
        tool = self.data.site("tool0")
        return np.linalg.inv(pose(base.xpos, base.xmat)) @ pose(tool.xpos, tool.xmat)


def scene_path(robot: ResolvedRobot, xml: Path) -> Path:
    """The scene file beside the robot's MJCF."""
    from ..backends.mjcf import scene_name

    return xml.parent / scene_name(robot)


def load(robot: ResolvedRobot, xml: Path) -> MujocoScene:
    """Load the robot's MJCF scene (ValueError when MuJoCo rejects it); xml: the robot file."""
    mujoco = import_mujoco()

    m = mujoco.MjModel.from_xml_path(str(scene_path(robot, xml)))
    d = mujoco.MjData(m)
    names = {i: m.body(i).name for i in range(1, m.nbody)}
    links = {n: i for i, n in names.items()}
    parents = {n: (names.get(int(m.body_parentid[i])) or "world") for i, n in names.items() if m.body_parentid[i] != 0}
    colliding = (m.geom_contype != 0) | (m.geom_conaffinity != 0)
    geometry_links = [n for n, i in links.items() if bool((colliding & (m.geom_bodyid == i)).any())]
    cell = {ob.name for ob in robot.obstacles}
    obstacles = {m.geom(g).name: g for g in range(m.ngeom) if m.geom_bodyid[g] == 0 and m.geom(g).name in cell}
    return MujocoScene(m, d, links, parents, geometry_links, [f"joint_{i}" for i in range(1, robot.dof + 1)], obstacles)


def load_failures(s: MujocoScene, robot: ResolvedRobot, xml: Path) -> list[Failure]:
    import mujoco

    who = f"robot {robot.name}"
    m = s.model
    out = []
    for name, i in s.links.items():
        if m.body_weldid[i] == 0:
            continue  # welded to the world: its mass is carried by the ground
        mass, inertia = float(m.body_mass[i]), [float(v) for v in m.body_inertia[i]]
        if not mass > 0 or not all(v > 0 for v in inertia):
            out.append(Failure("load", f"{who}: MuJoCo gives body {name} mass {mass:g} kg, inertia {inertia}"))
    hinges = [m.joint(j).name for j in range(m.njnt) if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE]
    if hinges != s.joint_names or m.nu != robot.dof:
        out.append(Failure("load", f"{who}: MuJoCo finds hinge joints {hinges} and {m.nu} actuators in {xml.name}, "
                                   f"the chain has {robot.dof} modules"))
    return out


def measure_pose(s: MujocoScene, name: str, q, allowed, steps: int, window: int) -> Measured:
    import numpy as np

    qv = np.array(q, dtype=float)
    s.set_q(qv)
    T_tool = s.T_base_tool()
    self_contacts, env_contacts = s.self_collisions(allowed), s.environment_collisions()
    return Measured(name, tuple(q), T_tool, self_contacts, env_contacts, hold(s, qv, steps, window))


def hold(s: MujocoScene, qv, steps: int, window: int) -> Hold:
    """The servos hold qv from rest at qv, contacts off (see the module docstring)."""
    import mujoco

    m, d = s.model, s.data
    flags = m.opt.disableflags
    m.opt.disableflags = flags | mujoco.mjtDisableBit.mjDSBL_CONTACT
    try:
        mujoco.mj_resetData(m, d)
        d.qpos[:] = qv
        d.ctrl[:] = qv
        mujoco.mj_forward(m, d)
        rec = HoldRecorder(qv, s.joint_names, steps, window, float(m.opt.timestep))
        for k in range(steps):
            mujoco.mj_step(m, d)
            if rec.wants(k) and not rec.sample(k, d.qpos.copy(), d.qvel.copy(), d.qfrc_actuator.copy()):
                break
        return rec.hold(d.qpos.copy(), d.qfrc_actuator.copy(), m.actuator_forcerange[:, 1])
    finally:
        m.opt.disableflags = flags


def simulate_robot(robot: ResolvedRobot, xml: Path, allowed=(), hold_time: float = HOLD_TIME) -> RobotResult:
    from ..dynamics.model import Dynamics
    from ..kinematics import Chain

    res = RobotResult(robot.name, robot.sequence)
    try:
        s = load(robot, xml)
    except ValueError as e:  # MuJoCo's compiler error, e.g. a mesh it cannot read
        res.failures.append(Failure("load", f"robot {robot.name}: MuJoCo cannot load {xml.name}: {e}"))
        return res
    res.failures += load_failures(s, robot, xml)
    if res.failures:
        return res
    dt = float(s.model.opt.timestep)
    steps, window = max(1, round(hold_time / dt)), max(1, round(SETTLE_WINDOW / dt))
    chain, dyn = Chain(robot), Dynamics(robot)
    for pname, q in robot.named_poses():
        measured = measure_pose(s, pname, q, allowed, steps, window)
        res.poses.append(judge_pose(robot, measured, chain, dyn, engine=ENGINE, fk_tol=FK_TOL))
    return res


def simulate(checked, robot: str | None = None, out_dir: str | Path | None = None,
             hold_time: float = HOLD_TIME) -> list[RobotResult]:
    """Every (or the named) robot of a checked design without errors (as smoke.simulate)."""
    from .scene import compiled, select_robots
    from .smoke import allowed_pairs

    robots = select_robots(checked, robot)
    with compiled(checked, "mjcf") as xmls:
        return [simulate_robot(r, xmls[r.name], allowed_pairs(out_dir, r), hold_time) for r in robots]


__all__ = ["ENGINE", "FK_TOL", "MujocoScene", "import_mujoco", "load", "simulate", "simulate_robot"]
