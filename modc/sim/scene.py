"""A PyBullet world built from a checked robot: the compiled URDF and meshes, the environment and
the targets. Shared by `modc sim`, `modc render`, `modc play` (and `modc plan`).

    from modc.sim import scene
    checked = scene.load_checked("examples/farm.mod")          # Checked (errors left to the caller)
    with scene.compiled(checked) as urdfs, scene.connect() as client:
        s = scene.load_robot(client, robot, urdfs[robot.name])  # arm + obstacles + target markers
        s.set_q(q)                                              # kinematic: joints teleported
        s.self_collisions(), s.environment_collisions()         # link pairs in contact, with depths
        s.T_base_link("tool0")                                  # 4x4 in base_link

Frames. The world is the cell frame: base_link is placed at robot.base (identity when the file
has no `base` line), gravity points along -z of the world, so a tilted base is felt by the
joints exactly as the torque analysis assumes. The file gives obstacles and targets in base_link
(docs/language.md); they are carried into the world through the same placement,
T_world_obstacle = T_world_base · T_base_obstacle. Results are reported in base_link.

Collision queries (Scene.self_collisions, environment_collisions, ...) live in contacts.py.
"""
from __future__ import annotations

import contextlib
import itertools
import os
import sys
import tempfile
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from ..model import ResolvedRobot
from ..physical.cell import MODULE_RADIUS, OBSTACLE_RGBA, TARGET_RADIUS, TARGET_RGBA, extent_points  # noqa: F401  (one home: physical/)
from ..physical.constants import GRAVITY
from .contacts import CollisionQueries

if TYPE_CHECKING:
    import numpy as np



class UsageError(Exception):
    """A request that cannot be served (unknown pose, unreadable trajectory): exit 2. An unknown
    robot is modc.model.select.RobotChoiceError."""


# ------------------------------------------------------------------------------------------------
# Loading and compiling


def load_checked(path, library: str | None = None):
    """check_file without the torque analysis (the simulator finds out for itself).
    Raises modc.compiler.InputError when the file cannot be read."""
    from ..compiler import check_file

    return check_file(path, library)


def select_robots(checked, robot: str | None = None) -> list[ResolvedRobot]:
    """Every robot of the file, or the one named (RobotChoiceError when there is none)."""
    from ..model.select import choose_robot

    return list(checked.design.resolved_robots()) if robot is None else [choose_robot(checked.design, robot)]


# what an engine loads: the backends to run, then the folder and suffix of the per-robot model
MODELS = {"urdf": (("urdf", "meshes"), "urdf", ".urdf"), "mjcf": (("urdf", "meshes", "mjcf"), "mjcf", ".xml")}


@contextlib.contextmanager
def compiled(checked, model: str = "urdf") -> Iterator[dict[str, Path]]:
    """The backends' output for one model kind (MODELS: the URDF and its meshes, or the MJCF)
    written into a temporary directory (removed on exit): robot name -> model path. The same
    bytes `modc FILE -o OUT` writes."""
    from ..compiler import build
    from ..files import write_files

    backends, folder, suffix = MODELS[model]
    files = build(checked, list(backends))
    with tempfile.TemporaryDirectory(prefix="modc-sim-") as tmp:
        root = Path(tmp)
        write_files(files, root)
        yield {r.name: root / folder / f"{r.file_stem}{suffix}" for r in checked.design.robots}


# ------------------------------------------------------------------------------------------------
# PyBullet's C-level output


@dataclass
class Captured:
    text: str = ""


@contextlib.contextmanager
def captured_output() -> Iterator[Captured]:
    """Redirect the process's stdout and stderr file descriptors (PyBullet prints from C, e.g.
    "pybullet build time" on import and b3Warning lines while loading) into a buffer."""
    out = Captured()
    sys.stdout.flush()
    sys.stderr.flush()
    saved = [os.dup(1), os.dup(2)]
    with tempfile.TemporaryFile(mode="w+b") as buf:
        try:
            os.dup2(buf.fileno(), 1)
            os.dup2(buf.fileno(), 2)
            yield out
        finally:
            with contextlib.suppress(Exception):
                sys.stdout.flush()
                sys.stderr.flush()
            _c_flush()
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            os.close(saved[0])
            os.close(saved[1])
            buf.seek(0)
            out.text = buf.read().decode("utf-8", "replace")


def _c_flush() -> None:
    """fflush(NULL): C stdio buffers what it prints into a pipe or file; flush it while the
    descriptors still point at the buffer."""
    with contextlib.suppress(Exception):
        import ctypes

        ctypes.CDLL(None).fflush(None)


def pybullet():
    """The pybullet module, imported quietly."""
    if "pybullet" not in sys.modules:
        with captured_output():
            import pybullet  # noqa: F401
    return sys.modules["pybullet"]


def display_available() -> bool:
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


_GUI_PROBE = "import pybullet as p, sys; sys.exit(0 if p.connect(p.GUI) >= 0 else 1)"


def gui_works(timeout: float = 20.0) -> bool:
    """A display is set and PyBullet's GUI opens on it. Probed in a child process: with an
    unreachable X server PyBullet may abort the whole process instead of failing."""
    import subprocess

    if not display_available():
        return False
    try:
        r = subprocess.run([sys.executable, "-c", _GUI_PROBE], capture_output=True, timeout=timeout)
    except (OSError, subprocess.TimeoutExpired):
        return False
    return r.returncode == 0


@contextlib.contextmanager
def connect(gui: bool = False) -> Iterator:
    """A PyBullet client (pybullet_utils BulletClient): DIRECT, or GUI when asked for and
    gui_works() (else DIRECT). Disconnected on exit. client.gui says which."""
    p = pybullet()
    from pybullet_utils.bullet_client import BulletClient

    client = None
    with captured_output():
        if gui and gui_works():
            try:
                client = BulletClient(connection_mode=p.GUI)
                client.gui = True
            except Exception:  # pybullet.error: cannot connect to the display
                client = None
        if client is None:
            client = BulletClient(connection_mode=p.DIRECT)
            client.gui = False
    try:
        client.setGravity(0, 0, -GRAVITY)
        yield client
    finally:
        with contextlib.suppress(Exception):
            client.disconnect()


# ------------------------------------------------------------------------------------------------
# Transforms


def transform(xyz, rpy):
    from ..kinematics import transform as t

    return t(xyz, rpy)


def pose_matrix(pos, quat):
    """4x4 from a PyBullet position and (x, y, z, w) quaternion."""
    import numpy as np

    x, y, z, w = quat
    T = np.eye(4)
    T[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                 [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                 [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    T[:3, 3] = pos
    return T


def matrix_pose(T) -> tuple[tuple[float, float, float], tuple[float, float, float, float]]:
    """Position and (x, y, z, w) quaternion of a 4x4 (Shepperd's method)."""
    import numpy as np

    R = np.asarray(T)[:3, :3]
    tr = np.trace(R)
    if tr > 0:
        s = 2.0 * np.sqrt(tr + 1.0)
        w, x, y, z = 0.25 * s, (R[2, 1] - R[1, 2]) / s, (R[0, 2] - R[2, 0]) / s, (R[1, 0] - R[0, 1]) / s
    elif R[0, 0] > R[1, 1] and R[0, 0] > R[2, 2]:
        s = 2.0 * np.sqrt(1.0 + R[0, 0] - R[1, 1] - R[2, 2])
        w, x, y, z = (R[2, 1] - R[1, 2]) / s, 0.25 * s, (R[0, 1] + R[1, 0]) / s, (R[0, 2] + R[2, 0]) / s
    elif R[1, 1] > R[2, 2]:
        s = 2.0 * np.sqrt(1.0 + R[1, 1] - R[0, 0] - R[2, 2])
        w, x, y, z = (R[0, 2] - R[2, 0]) / s, (R[0, 1] + R[1, 0]) / s, 0.25 * s, (R[1, 2] + R[2, 1]) / s
    else:
        s = 2.0 * np.sqrt(1.0 + R[2, 2] - R[0, 0] - R[1, 1])
        w, x, y, z = (R[1, 0] - R[0, 1]) / s, (R[0, 2] + R[2, 0]) / s, (R[1, 2] + R[2, 1]) / s, 0.25 * s
    p = np.asarray(T)[:3, 3]
    return (float(p[0]), float(p[1]), float(p[2])), (float(x), float(y), float(z), float(w))



LAYOUT_GAP = 0.15  # m between robots laid out side by side


def world_placements(robots: list[ResolvedRobot], qs: dict | None = None) -> dict[str, np.ndarray]:
    """robot name -> T_world_base. Each robot sits at its `base`; when two robots of one file
    share a placement (both at the default origin, say), they are laid out along the world's y
    axis instead, LAYOUT_GAP apart at the pose shown (qs: name -> q, default home), so that a
    picture shows them side by side rather than inside each other."""
    import numpy as np

    T = {r.name: transform(r.base.xyz, r.base.rpy) for r in robots}
    same = any(np.allclose(T[a.name], T[b.name], atol=1e-9) for a, b in itertools.combinations(robots, 2))
    if same:
        edge = None
        for r in robots:
            ext = extent_points(r, (qs or {}).get(r.name), T[r.name])
            lo, hi = float(ext[:, 1].min()), float(ext[:, 1].max())
            shift = np.eye(4)
            shift[1, 3] = 0.0 if edge is None else edge + LAYOUT_GAP - lo
            T[r.name] = shift @ T[r.name]
            edge = hi + shift[1, 3]
    return T


# ------------------------------------------------------------------------------------------------
# The scene


@dataclass
class Scene(CollisionQueries):
    client: Any  # a PyBullet client (pybullet_utils.bullet_client.BulletClient)
    robot: ResolvedRobot
    urdf: Path
    body: int
    T_world_base: np.ndarray  # 4x4
    joint_names: list[str]  # joint_1 … joint_n
    joints: dict[str, int]  # joint name -> PyBullet joint index
    links: dict[str, int]  # link name -> PyBullet link index (base_link = -1)
    parents: dict[str, str]  # link -> parent link
    geometry_links: list[str]  # links with collision shapes, in URDF order
    limits: dict[str, tuple[float, float, float, float]]  # joint -> (lower, upper, effort, velocity)
    obstacles: dict[str, int] = field(default_factory=dict)  # obstacle name -> body
    targets: dict[str, int] = field(default_factory=dict)  # target name -> visual-only body
    load_log: str = ""  # what PyBullet printed while loading

    # -- joints ----------------------------------------------------------------------------------
    def set_q(self, q) -> None:
        """Teleport the joints to q (joint_1 first), zero velocity."""
        for name, v in zip(self.joint_names, q, strict=True):
            self.client.resetJointState(self.body, self.joints[name], float(v), 0.0)

    def q(self):
        import numpy as np

        return np.array(
            [s[0] for s in self.client.getJointStates(self.body, [self.joints[n] for n in self.joint_names])]
        )

    def qd(self):
        import numpy as np

        return np.array(
            [s[1] for s in self.client.getJointStates(self.body, [self.joints[n] for n in self.joint_names])]
        )

    def applied_torques(self):
        import numpy as np

        return np.array(
            [s[3] for s in self.client.getJointStates(self.body, [self.joints[n] for n in self.joint_names])]
        )

    def release_motors(self) -> None:
        """PyBullet starts every joint with a velocity motor (a brake); switch them off."""
        p = pybullet()
        idx = [self.joints[n] for n in self.joint_names]
        self.client.setJointMotorControlArray(self.body, idx, p.VELOCITY_CONTROL, forces=[0.0] * len(idx))

    def hold(self, q, qd=None) -> None:
        """Position control towards q (with feed-forward velocity qd, default 0): force = the
        URDF effort (the actuator's peak torque), maxVelocity = the URDF velocity (its rated
        speed); PyBullet's default gains."""
        p = pybullet()
        qd = [0.0] * len(self.joint_names) if qd is None else qd
        for name, v, w in zip(self.joint_names, q, qd, strict=True):
            lo, hi, effort, vel = self.limits[name]
            self.client.setJointMotorControl2(self.body, self.joints[name], p.POSITION_CONTROL, targetPosition=float(v),
                                              targetVelocity=float(w), force=effort, maxVelocity=vel)

    # -- frames ----------------------------------------------------------------------------------
    def T_world_link(self, name: str):
        import numpy as np

        i = self.links[name]
        if i == -1:
            pos, orn = self.client.getBasePositionAndOrientation(self.body)
            local = self.client.getDynamicsInfo(self.body, -1)
            return pose_matrix(pos, orn) @ np.linalg.inv(pose_matrix(local[3], local[4]))
        s = self.client.getLinkState(self.body, i, computeForwardKinematics=True)
        return pose_matrix(s[4], s[5])  # the URDF link frame (not the inertial frame)

    def T_base_link(self, name: str):
        import numpy as np

        return np.linalg.inv(self.T_world_base) @ self.T_world_link(name)

    def remove(self) -> None:
        for b in [self.body, *self.obstacles.values(), *self.targets.values()]:
            self.client.removeBody(b)


def load_robot(client, robot: ResolvedRobot, urdf: Path, T_world_base=None, *, environment: bool = True,
               targets: bool = True) -> Scene:
    """Load the robot's URDF (fixed base at T_world_base, default robot.base), its obstacles as
    static bodies (collision + visual) and its targets as visual-only spheres. The arm is loaded
    with the URDF's inertias, without self-collision in the dynamics (checked geometrically),
    its motors released, and the obstacles do not push it (Scene.environment_physics)."""
    import numpy as np

    p = pybullet()
    T_world_base = (
        transform(robot.base.xyz, robot.base.rpy) if T_world_base is None else np.asarray(T_world_base, dtype=float)
    )
    pos, orn = matrix_pose(T_world_base)
    with captured_output() as log:
        body = client.loadURDF(str(urdf), basePosition=pos, baseOrientation=orn, useFixedBase=True,
                               flags=p.URDF_USE_INERTIA_FROM_FILE)
    links = {"base_link": -1}
    joints, parents, limits = {}, {}, {}
    names_by_index = {-1: "base_link"}
    for j in range(client.getNumJoints(body)):
        info = client.getJointInfo(body, j)
        link = info[12].decode()
        links[link] = j
        names_by_index[j] = link
        if info[2] == p.JOINT_REVOLUTE:
            jname = info[1].decode()
            joints[jname] = j
            limits[jname] = (float(info[8]), float(info[9]), float(info[10]), float(info[11]))
    for j in range(client.getNumJoints(body)):
        info = client.getJointInfo(body, j)
        parents[names_by_index[j]] = names_by_index[info[16]]
    joint_names = [f"joint_{i}" for i in range(1, robot.dof + 1)]
    missing = [n for n in joint_names if n not in joints]
    if missing:
        raise RuntimeError(f"{urdf.name}: PyBullet found no revolute joint(s) {', '.join(missing)}")
    geometry_links = [n for n, i in links.items() if client.getCollisionShapeData(body, i)]
    s = Scene(client, robot, Path(urdf), body, T_world_base, joint_names, joints, links, parents, geometry_links,
              limits, load_log=log.text)
    if environment:
        for ob in robot.obstacles:
            s.obstacles[ob.name] = add_obstacle(client, ob, T_world_base)
        s.environment_physics(False)
    if targets:
        for t in robot.targets:
            s.targets[t.name] = add_marker(client, (T_world_base @ np.array([*t.xyz, 1.0]))[:3])
    s.release_motors()
    s.set_q(robot.home())
    return s


def add_obstacle(client, ob, T_world_base, rgba=OBSTACLE_RGBA) -> int:
    """A static body for a box (full extents), sphere (radius) or cylinder (radius, length along
    its z), at T_world_base · origin."""
    p = pybullet()
    if ob.shape == "box":
        half = [v / 2.0 for v in ob.size]
        col = client.createCollisionShape(p.GEOM_BOX, halfExtents=half)
        vis = client.createVisualShape(p.GEOM_BOX, halfExtents=half, rgbaColor=rgba)
    elif ob.shape == "sphere":
        col = client.createCollisionShape(p.GEOM_SPHERE, radius=ob.size[0])
        vis = client.createVisualShape(p.GEOM_SPHERE, radius=ob.size[0], rgbaColor=rgba)
    elif ob.shape == "cylinder":
        col = client.createCollisionShape(p.GEOM_CYLINDER, radius=ob.size[0], height=ob.size[1])
        vis = client.createVisualShape(p.GEOM_CYLINDER, radius=ob.size[0], length=ob.size[1], rgbaColor=rgba)
    else:  # pragma: no cover - the model admits only these three
        raise ValueError(f"unknown obstacle shape {ob.shape}")
    pos, orn = matrix_pose(T_world_base @ transform(ob.origin.xyz, ob.origin.rpy))
    return client.createMultiBody(baseMass=0.0, baseCollisionShapeIndex=col, baseVisualShapeIndex=vis,
                                  basePosition=pos, baseOrientation=orn)


def add_marker(client, xyz_world, rgba=TARGET_RGBA, radius: float = TARGET_RADIUS) -> int:
    """A visual-only sphere (no collision shape: nothing ever touches it)."""
    p = pybullet()
    vis = client.createVisualShape(p.GEOM_SPHERE, radius=radius, rgbaColor=rgba)
    return client.createMultiBody(baseMass=0.0, baseCollisionShapeIndex=-1, baseVisualShapeIndex=vis,
                                  basePosition=[float(v) for v in xyz_world])
