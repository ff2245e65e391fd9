"""The emitted URDF loads in the real consumers and means what docs/conventions.md says.

Consumers: `check_urdf` (urdfdom, shipped with `pin`), pinocchio (+ coal for meshes), yourdfpy,
PyBullet. Every example in examples/ is covered automatically, plus a few hand-picked chains that
reach the corners of the library (all unit kinds, +-90 deg pivots, 180 deg ports, shortest and
longest links, tool offset, payload, two robots in one file) and a property test over random valid
chains (tests/strategies.py).

Reference for kinematics: `modc.kinematics.Chain` (the product stated in docs/conventions.md); the
property test also checks `Chain` itself against an independent transcription of the paper's equations.
"""
from __future__ import annotations

import math
import os
import shutil
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin
import pybullet
import pytest
import yourdfpy
from conftest import EXAMPLES, ROOT, checked_ok
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from pybullet_utils.bullet_client import BulletClient
from strategies import RobotSpec, robot_specs

from modc.compiler import build, check_file, write_tree
from modc.kinematics import Chain
from modc.model import Robot
from modc.physical.assembly import FRAME_MASS, library_mass

FK_TOL = 1e-9  # FK from the URDF equals the paper's product to 1e-9
# The pip wheel of PyBullet is built in single precision (btScalar = float): getLinkState returns
# float32-rounded poses. Measured over every example and 300 random q each: positions off by up to
# 3e-8 m, rotation-matrix entries by up to 5e-7 (float32 quaternions composed along the chain).
# So PyBullet is held to 1e-6 m and 1e-5 in rotation, not 1e-9; that still catches any wrong
# origin, axis or twist (a 15 deg twist step is 0.26 in rotation, module offsets are >= 1 cm).
BULLET_POS_TOL = 1e-6
BULLET_ROT_TOL = 1e-5
MASS_TOL = 1e-9  # kg; PyBullet returns masses exactly as the URDF gives them (measured)
N_RANDOM_Q = 5

# Hand-picked robots (name -> .mod text), compiled once per module.
CHAINS = {
    "corners": """
        robot corners {
            chain H1(pivot=-90deg) - H2(pivot=90deg) - H3(pivot=45deg, port=180deg, link=50mm)
                - L4(pivot=-15deg, port=-165deg, link=500mm) - L1(pivot=75deg) - L2
            tool at (0.01, -0.02, 0.05) m rpy (30, -45, 90) deg
            payload 0.3 kg at (0, 0.01, 0.02) m
        }""",
    "gimbal": """
        robot gimbal {
            chain H4(pivot=90deg, port=90deg) - H3(pivot=-90deg, port=-90deg) - L3(pivot=90deg, port=180deg)
            tool rpy (0, 90, 0) deg
        }""",
    "long_reach": """
        robot long_reach {
            chain H3(port=15deg, link=500mm) - H4(pivot=30deg, port=-90deg, link=0.5 m) - H3(link=450mm)
                - L4(port=135deg) - L3(pivot=-45deg, link=0.4 m) - L4(port=-30deg, link=300mm)
        }""",
    "two_robots": """
        robot planar { chain H3 - L4 }
        robot spatial { chain H1 - H4(pivot=-90deg, port=45deg, link=180mm) - L4 tool at (0, 0, 0.05) m }
        """,
}
# .mod examples come compiled from conftest; YAML forms of examples are compiled here.
YAML_EXAMPLES = sorted(p for p in (ROOT / "examples").iterdir() if p.suffix in (".yaml", ".yml"))
CASES = ([f"example/{p.stem}" for p in EXAMPLES] + [f"example/{p.name}" for p in YAML_EXAMPLES]
         + [f"chain/{k}" for k in CHAINS])


@dataclass(frozen=True)
class Arm:
    """One compiled robot: its checked model and where its URDF was written."""

    robot: Robot
    urdf: Path

    @property
    def dof(self) -> int:
        return self.robot.dof

    @property
    def joint_names(self) -> list[str]:
        return [f"joint_{i}" for i in range(1, self.dof + 1)]


def arms_in(design, out: Path) -> list[Arm]:
    arms = [Arm(r, out / "urdf" / f"{r.file_stem}.urdf") for r in design.robots]
    for a in arms:
        assert a.urdf.is_file(), f"{a.urdf} was not written"
    return arms


def compile_arms(text: str, out: Path, path: str) -> list[Arm]:
    c = checked_ok(text, path)
    write_tree(build(c), out)
    return arms_in(c.design, out)


@pytest.fixture(scope="module", params=CASES)
def arms(request, compiled_examples, tmp_path_factory) -> list[Arm]:
    """The robots of one example file or hand-picked chain, compiled."""
    kind, name = request.param.split("/", 1)
    if kind == "example" and name in compiled_examples:
        return arms_in(check_file(ROOT / "examples" / f"{name}.mod").design, compiled_examples[name])
    out = tmp_path_factory.mktemp(name) / "out"
    if kind == "example":
        src = ROOT / "examples" / name
        return compile_arms(src.read_text(encoding="utf-8"), out, str(src))
    return compile_arms(CHAINS[name], out, f"{name}.mod")


def random_qs(robot: Robot, n: int, seed: int) -> list[np.ndarray]:
    """q = 0 and n random configurations inside the joint limits."""
    rng = np.random.default_rng(seed)
    lims = np.array([robot.joint_range(i) for i in range(1, robot.dof + 1)])
    return [np.zeros(robot.dof)] + [rng.uniform(lims[:, 0], lims[:, 1]) for _ in range(n)]


def assert_close(actual, expected, tol: float, what: str) -> None:
    err = float(np.max(np.abs(np.asarray(actual) - np.asarray(expected))))
    assert err <= tol, f"{what}: max |error| = {err:.3g} > {tol:g}\nactual\n{actual}\nexpected\n{expected}"


def assert_pose_close(actual, expected, pos_tol: float, rot_tol: float, what: str) -> None:
    assert_close(actual[:3, 3], expected[:3, 3], pos_tol, f"{what} (position, m)")
    assert_close(actual[:3, :3], expected[:3, :3], rot_tol, f"{what} (rotation)")


def urdf_elements(path: Path, tag: str) -> dict[str, list[ET.Element]]:
    """link name -> its <visual> or <collision> elements, straight from the XML."""
    root = ET.parse(path).getroot()
    return {link.get("name"): link.findall(tag) for link in root.findall("link")}


# ------------------------------------------------------------------------------------------------
# check_urdf (urdfdom)


def check_urdf_exe() -> list[str]:
    """The urdfdom CLI that `pin` ships via cmeel: the wrapper next to python, else the prefix."""
    wrapper = Path(sys.executable).parent / "check_urdf"
    if wrapper.is_file():
        return [str(wrapper)]
    found = shutil.which("check_urdf")
    if found:
        return [found]
    import cmeel.consts

    prefix = Path(cmeel.consts.__file__).resolve().parent.parent / cmeel.consts.CMEEL_PREFIX
    binary = prefix / "bin" / "check_urdf"
    assert binary.is_file(), "check_urdf not found: it ships with `pin` (cmeel); is `pin` installed?"
    return [str(binary)]


def run_check_urdf(path: Path) -> subprocess.CompletedProcess:
    exe = check_urdf_exe()
    env = dict(os.environ)
    if "cmeel.prefix" in exe[0]:  # the raw binary needs the prefix's libraries (the wrapper sets this)
        env["LD_LIBRARY_PATH"] = str(Path(exe[0]).parent.parent / "lib") + os.pathsep + env.get("LD_LIBRARY_PATH", "")
    return subprocess.run([*exe, str(path)], capture_output=True, text=True, env=env, timeout=300)  # a hang guard


def assert_check_urdf_accepts(arm: Arm) -> None:
    res = run_check_urdf(arm.urdf)
    assert res.returncode == 0, f"check_urdf rejects {arm.urdf.name}:\n{res.stdout}\n{res.stderr}"
    assert "Successfully Parsed XML" in res.stdout
    assert "root Link: base_link" in res.stdout
    for name in [f"link_{i}" for i in range(1, arm.dof + 1)] + ["tool0"]:
        assert f"child(1):  {name}" in res.stdout, f"check_urdf does not see {name} in the tree"


@pytest.mark.slow
def test_check_urdf_accepts_every_urdf(arms):
    """urdfdom's check_urdf parses the URDF and sees base_link -> link_1 ... link_n -> tool0."""
    for arm in arms:
        assert_check_urdf_accepts(arm)


# ------------------------------------------------------------------------------------------------
# Forward kinematics


def pin_frames(model: pin.Model, arm: Arm, q: np.ndarray) -> dict[str, np.ndarray]:
    """Frame name -> 4x4 pose in base_link, as pinocchio computes it from the URDF."""
    data = model.createData()
    qp = pin.neutral(model)
    for name, qi in zip(arm.joint_names, q, strict=True):
        qp[model.joints[model.getJointId(name)].idx_q] = qi
    pin.framesForwardKinematics(model, data, qp)
    names = ["tool0"] + arm.joint_names + [f"link_{i}" for i in range(1, arm.dof + 1)]
    return {n: data.oMf[model.getFrameId(n)].homogeneous for n in names}


def check_fk_pinocchio(arm: Arm, qs, tol: float = FK_TOL) -> None:
    model = pin.buildModelFromUrdf(str(arm.urdf))
    assert list(model.names)[1:] == arm.joint_names, "joints must be joint_1 .. joint_n from the base"
    assert model.nq == arm.dof
    chain = Chain(arm.robot)
    for q in qs:
        got = pin_frames(model, arm, q)
        assert_close(got["tool0"], chain.T_base_tool(q), tol, f"pinocchio T_base_tool at q={q}")
        for i, f in enumerate(chain.frames(q), start=1):
            assert_close(got[f"joint_{i}"], f["T_base_joint"], tol, f"pinocchio joint_{i} at q={q}")
            assert_close(got[f"link_{i}"], f["T_base_joint"], tol, f"pinocchio link_{i} at q={q}")


def check_fk_yourdfpy(arm: Arm, qs, tol: float = FK_TOL) -> None:
    urdf = yourdfpy.URDF.load(str(arm.urdf), load_meshes=False)
    assert urdf.actuated_joint_names == arm.joint_names
    chain = Chain(arm.robot)
    for q in qs:
        urdf.update_cfg(dict(zip(arm.joint_names, q, strict=True)))
        # get_transform(frame_to, frame_from): pose of frame_to expressed in frame_from
        assert_close(
            urdf.get_transform("tool0", "base_link"), chain.T_base_tool(q), tol, f"yourdfpy T_base_tool at q={q}"
        )
        for i, f in enumerate(chain.frames(q), start=1):
            assert_close(
                urdf.get_transform(f"link_{i}", "base_link"), f["T_base_joint"], tol, f"yourdfpy link_{i} at q={q}"
            )


def test_fk_pinocchio_matches_spec(arms):
    """Pinocchio's FK of tool0 and of every joint_i / link_i frame equals docs/conventions.md to 1e-9."""
    for k, arm in enumerate(arms):
        check_fk_pinocchio(arm, random_qs(arm.robot, N_RANDOM_Q, seed=k))


def test_fk_yourdfpy_matches_spec(arms):
    """yourdfpy's FK of tool0 and every link_i equals docs/conventions.md to 1e-9."""
    for k, arm in enumerate(arms):
        check_fk_yourdfpy(arm, random_qs(arm.robot, N_RANDOM_Q, seed=k))


@pytest.fixture(scope="module")
def bullet():
    client = BulletClient(connection_mode=pybullet.DIRECT)
    client.setPhysicsEngineParameter(enableFileCaching=0)  # PyBullet caches files by path otherwise
    yield client
    client.disconnect()


def bullet_pose(pos, orn) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = np.reshape(pybullet.getMatrixFromQuaternion(orn), (3, 3))
    T[:3, 3] = pos
    return T


def bullet_links(client, body: int) -> dict[str, int]:
    """link name -> PyBullet link index (base_link is -1)."""
    out = {client.getBodyInfo(body)[0].decode(): -1}
    for j in range(client.getNumJoints(body)):
        out[client.getJointInfo(body, j)[12].decode()] = j
    return out


def bullet_link_pose(client, body: int, link: int, T_world_base: np.ndarray) -> np.ndarray:
    """The URDF frame of a link (PyBullet link index) in base_link, from the last FK state."""
    s = client.getLinkState(body, link, computeForwardKinematics=True)
    return np.linalg.inv(T_world_base) @ bullet_pose(s[4], s[5])  # 4/5: URDF link frame


def test_fk_pybullet_matches_spec(arms, bullet):
    """PyBullet's link frames of tool0 and every link_i match docs/conventions.md (to float32 precision)."""
    for k, arm in enumerate(arms):
        body = bullet.loadURDF(str(arm.urdf), useFixedBase=True, flags=pybullet.URDF_USE_INERTIA_FROM_FILE)
        try:
            links = bullet_links(bullet, body)
            joints = {bullet.getJointInfo(body, j)[1].decode(): j for j in range(bullet.getNumJoints(body))}
            for name in arm.joint_names:
                assert bullet.getJointInfo(body, joints[name])[2] == pybullet.JOINT_REVOLUTE
            # base_link's URDF frame = its inertial frame composed with the inverse inertial offset
            _, _, _, local_pos, local_orn, *_ = bullet.getDynamicsInfo(body, -1)
            T_world_base = bullet_pose(*bullet.getBasePositionAndOrientation(body)) @ np.linalg.inv(
                bullet_pose(local_pos, local_orn)
            )
            chain = Chain(arm.robot)
            for q in random_qs(arm.robot, N_RANDOM_Q, seed=k):
                for name, qi in zip(arm.joint_names, q, strict=True):
                    bullet.resetJointState(body, joints[name], float(qi))
                assert_pose_close(
                    bullet_link_pose(bullet, body, links["tool0"], T_world_base),
                    chain.T_base_tool(q),
                    BULLET_POS_TOL,
                    BULLET_ROT_TOL,
                    f"PyBullet T_base_tool at q={q}",
                )
                for i, f in enumerate(chain.frames(q), start=1):
                    assert_pose_close(
                        bullet_link_pose(bullet, body, links[f"link_{i}"], T_world_base),
                        f["T_base_joint"],
                        BULLET_POS_TOL,
                        BULLET_ROT_TOL,
                        f"PyBullet link_{i} at q={q}",
                    )
        finally:
            bullet.removeBody(body)


# ------------------------------------------------------------------------------------------------
# Meshes


def test_mesh_paths_are_relative_and_inside_the_output(arms):
    """Every mesh the URDF names is a relative path to a file in OUT/meshes (docs/outputs.md)."""
    for arm in arms:
        out = arm.urdf.parent.parent.resolve()
        for tag in ("visual", "collision"):
            for link, elems in urdf_elements(arm.urdf, tag).items():
                for e in elems:
                    fn = e.find("geometry/mesh").get("filename")
                    assert not os.path.isabs(fn) and "://" not in fn, f"{link}: mesh path {fn} is not relative"
                    target = (arm.urdf.parent / fn).resolve()
                    assert target.is_file(), f"{link}: {fn} does not exist"
                    assert target.is_relative_to(out / "meshes"), f"{link}: {fn} is outside OUT/meshes"


@pytest.mark.parametrize("kind", ["COLLISION", "VISUAL"])
def test_pinocchio_loads_every_mesh(arms, kind):
    """pinocchio/coal load one non-empty mesh per <collision>/<visual>, on the right link."""
    tag = kind.lower()
    for arm in arms:
        model = pin.buildModelFromUrdf(str(arm.urdf))
        geom = pin.buildGeomFromUrdf(
            model, str(arm.urdf), getattr(pin.GeometryType, kind), package_dirs=[str(arm.urdf.parent)]
        )
        expected = {link: len(elems) for link, elems in urdf_elements(arm.urdf, tag).items() if elems}
        got: dict[str, int] = {}
        for obj in geom.geometryObjects:
            assert Path(obj.meshPath).is_file(), obj.meshPath
            assert obj.geometry.num_vertices > 0, f"{obj.name}: empty mesh {obj.meshPath}"
            link = model.frames[obj.parentFrame].name
            got[link] = got.get(link, 0) + 1
        assert got == expected


def test_yourdfpy_loads_every_mesh(arms):
    """yourdfpy finds and loads every visual and collision mesh file."""
    for arm in arms:
        urdf = yourdfpy.URDF.load(str(arm.urdf), load_meshes=True, build_collision_scene_graph=True,
                                  load_collision_meshes=True, force_collision_mesh=False)
        for scene, tag in ((urdf.scene, "visual"), (urdf.collision_scene, "collision")):
            n = sum(len(e) for e in urdf_elements(arm.urdf, tag).values())
            assert len(scene.geometry) == n, f"{tag}: {len(scene.geometry)} meshes loaded of {n}"
            assert all(len(g.vertices) > 0 for g in scene.geometry.values())


def test_pybullet_has_collision_shapes_for_every_link(arms, bullet):
    """PyBullet builds one mesh collision shape per <collision> of every link that has geometry."""
    for arm in arms:
        body = bullet.loadURDF(str(arm.urdf), useFixedBase=True)
        try:
            links = bullet_links(bullet, body)
            for link, elems in urdf_elements(arm.urdf, "collision").items():
                shapes = bullet.getCollisionShapeData(body, links[link])
                assert len(shapes) == len(elems), f"{link}: {len(shapes)} collision shapes, URDF has {len(elems)}"
                for s in shapes:
                    assert s[2] == pybullet.GEOM_MESH, f"{link}: collision shape is not a mesh"
                    assert Path(s[4].decode()).is_file(), f"{link}: {s[4]!r}"
        finally:
            bullet.removeBody(body)


# ------------------------------------------------------------------------------------------------
# Mass and inertia


def test_total_mass_pinocchio(arms):
    """The arm's mass in pinocchio (tool0's placeholder excluded) is what the library says."""
    for arm in arms:
        model = pin.buildModelFromUrdf(str(arm.urdf))
        # inertias[0] holds base_link (fixed to the universe); fixed tool0/payload merge into the last body
        total = sum(b.mass for b in model.inertias) - FRAME_MASS
        assert total == pytest.approx(library_mass(arm.robot), abs=MASS_TOL)


def test_total_mass_pybullet(arms, bullet):
    """PyBullet's link masses (free base, so base_link keeps its mass) sum to the library's mass."""
    for arm in arms:
        body = bullet.loadURDF(str(arm.urdf), useFixedBase=False, flags=pybullet.URDF_USE_INERTIA_FROM_FILE)
        try:
            masses = {link: bullet.getDynamicsInfo(body, idx)[0] for link, idx in bullet_links(bullet, body).items()}
        finally:
            bullet.removeBody(body)
        assert masses["tool0"] == pytest.approx(FRAME_MASS, rel=1e-6)
        total = sum(m for link, m in masses.items() if link != "tool0")
        assert total == pytest.approx(library_mass(arm.robot), abs=MASS_TOL)


def assert_physical(mass: float, com, inertia: np.ndarray, what: str) -> None:
    """Positive mass, symmetric positive-definite inertia about the COM, triangle inequality on
    the principal moments, and a positive-definite pseudo-inertia (a real mass distribution)."""
    assert mass > 0, f"{what}: mass {mass}"
    assert_close(inertia, inertia.T, 0.0, f"{what}: inertia symmetric")
    eig = np.linalg.eigvalsh(inertia)
    assert eig.min() > 0, f"{what}: principal moments {eig} not positive"
    slack = 1e-12 * eig.max()
    for k in range(3):
        assert eig[k] <= eig[(k + 1) % 3] + eig[(k + 2) % 3] + slack, (
            f"{what}: principal moments {eig} break the triangle inequality"
        )
    pseudo = pin.Inertia(mass, np.asarray(com, dtype=float), inertia).toPseudoInertia().toMatrix()
    assert np.linalg.eigvalsh(pseudo).min() > 0, f"{what}: pseudo-inertia not positive definite"


def test_inertias_are_physical(arms):
    """Every link's inertial in the URDF, and every body pinocchio assembles from them, is a
    physically possible rigid body."""
    for arm in arms:
        urdf = yourdfpy.URDF.load(str(arm.urdf), load_meshes=False)
        for name, link in urdf.link_map.items():
            assert link.inertial is not None, f"{arm.urdf.name}: {name} has no <inertial>"
            o = link.inertial.origin
            inertia = o[:3, :3] @ link.inertial.inertia @ o[:3, :3].T  # in the link frame, about the COM
            assert_physical(link.inertial.mass, o[:3, 3], inertia, f"{arm.urdf.name} {name}")
        model = pin.buildModelFromUrdf(str(arm.urdf))
        for j, body in enumerate(model.inertias):
            assert_physical(body.mass, body.lever, body.inertia, f"{arm.urdf.name} pinocchio body {model.names[j]}")


# ------------------------------------------------------------------------------------------------
# Property test over random valid chains


def spec_T_base_tool(spec: RobotSpec, q) -> np.ndarray:
    """The paper's product transcribed independently of modc (constants from the paper's Table 1 and section 3.1)."""
    table = {1: (0.0, 0.074, 0.073), 2: (-0.0297, 0.075, 0.073), 3: (0.0, 0.074, 0.073), 4: (-0.0297, 0.075, 0.073)}

    def H(R, p):
        T = np.eye(4)
        T[:3, :3], T[:3, 3] = R, p
        return T

    def rot(axis: int, a: float) -> np.ndarray:
        c, s = math.cos(a), math.sin(a)
        i, j = [(1, 2), (2, 0), (0, 1)][axis]
        R = np.eye(3)
        R[i, i], R[i, j], R[j, i], R[j, j] = c, -s, s, c
        return R

    T = np.eye(4)
    for u, qi in zip(spec.units, q, strict=True):
        x01, z01, z12 = table[u.kind]
        T = T @ H(rot(1, math.radians(u.pivot_deg or 0)), (x01, 0, z01)) @ H(rot(2, qi), (0, 0, z12))
        if u.has_link:
            x23 = 0.22 if u.link_mm is None else u.link_mm / 1000
            T = T @ H(rot(0, math.radians(u.port_deg or 0)), (x23, 0, 0))
    r, p, y = spec.tool_rpy
    return T @ H(rot(2, y) @ rot(1, p) @ rot(0, r), spec.tool_xyz)


@pytest.mark.slow
@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(spec=robot_specs(), seed=st.integers(0, 2**32 - 1))
def test_random_valid_chains_load_with_spec_kinematics(spec: RobotSpec, seed: int):
    """Any valid chain compiles to a URDF that check_urdf accepts and whose FK in pinocchio and
    yourdfpy equals docs/conventions.md (checked against modc's Chain and an independent transcription)."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "out"
        (arm,) = compile_arms(spec.text, out, "fuzz.mod")
        assert arm.robot.sequence == spec.sequence and arm.urdf.name == f"{spec.file_stem}.urdf"
        qs = random_qs(arm.robot, 3, seed)[1:]
        for q in qs:
            assert_close(Chain(arm.robot).T_base_tool(q), spec_T_base_tool(spec, q), FK_TOL, "Chain vs transcription")
        check_fk_pinocchio(arm, qs)
        check_fk_yourdfpy(arm, qs)
        assert_check_urdf_accepts(arm)
        model = pin.buildModelFromUrdf(str(arm.urdf))
        assert sum(b.mass for b in model.inertias) - FRAME_MASS == pytest.approx(library_mass(arm.robot), abs=MASS_TOL)
