"""The xacro backend: `xacro` expands every robot's .urdf.xacro into a URDF equivalent to the .urdf.

Equivalent means, in pinocchio (which merges fixed joints, so the xacro form's extra links do
not matter): the same joints (joint_1..n, limits), the same frames (base_link, link_i, tool0,
payload) at random q, the same rigid bodies per joint (mass, centre of mass, inertia), hence the
same subtree masses, total mass, mass matrix, gravity torques and inverse dynamics; and the same
meshes at the same places. Tolerance 1e-9 (the consumers' tolerance); both files carry 12 significant
digits, so the measured differences are ~1e-13.

Also: the expansion passes check_urdf; the extra links are the paper's frames (unit base,
twist1, twist2); prefix and mesh_root args work; two arms in one robot (a wrapper that includes
the arm macro twice) expand, load and are independent; a hand-written xacro that uses the macro
library's defaults equals the compiled robot; random valid chains (hypothesis).
"""
from __future__ import annotations

import subprocess
import sys
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import xacro
from conftest import EXAMPLES, ROOT, checked_ok
from hypothesis import HealthCheck, given, settings
from strategies import robot_specs

from modc.backends import BACKENDS, Build, load_all
from modc.compiler import build, check_file, write_tree
from modc.kinematics import Chain, transform
from modc.model import Robot

# The backend registers itself on import. Until load_all() imports it, keep it out of the
# registry so that other tests' outputs (golden files, report.json) do not change under them.
_REGISTERED = "xacro" in load_all()
from modc.backends import xacro as xacro_backend  # noqa: E402

if not _REGISTERED:
    BACKENDS.pop("xacro", None)

TOL = 1e-9
N_Q = 5

CHAINS = {
    # narrowed limits, tool rotation, payload, every unit type, pivots at +-90, 180 deg port
    "corners": """
        robot corners {
            chain H1(pivot=-90deg) - H2(pivot=90deg) - H3(pivot=45deg, port=180deg, link=50mm)
                - L4(pivot=-15deg, port=-165deg, link=500mm) - L1(pivot=75deg) - L2
            tool at (0.01, -0.02, 0.05) m rpy (30, -45, 90) deg
            payload 0.3 kg at (0, 0.01, 0.02) m
            limit joint_2 (-90, 90) deg
            limit joint_6 (-30, 170) deg
        }""",
    # two robots, two module libraries in one file: one macro library file with both
    "two_libraries": """
        robot planar { chain H3 - L4(port=90deg, link=120mm) }
        robot strict {
            library mark2-strict
            chain H1 - H4(pivot=-45deg, port=60deg, link=180mm) - L3(pivot=90deg)
            tool at (0, 0, 0.05) m
        }""",
}


# ------------------------------------------------------------------------------------------------
# compiling and expanding


@dataclass(frozen=True)
class Pair:
    """One robot: its model, the Jinja URDF and the xacro expansion (both in OUT/urdf/)."""

    robot: Robot
    urdf: Path
    xacro_urdf: Path

    @property
    def out(self) -> Path:
        return self.urdf.parent.parent


def emit_all(checked) -> dict[str, str | bytes]:
    files = build(checked, only=["urdf", "meshes"])
    files.update(xacro_backend.emit(Build(checked.design)))
    return dict(sorted(files.items()))


def expand(path: Path, **args: str) -> str:
    """xacro's Python API, as `xacro FILE name:=value ...` does it."""
    doc = xacro.process_file(str(path), mappings=dict(args))
    return doc.toprettyxml(indent="  ")


def compile_pairs(checked, out: Path) -> list[Pair]:
    write_tree(emit_all(checked), out)
    pairs = []
    for r in checked.design.robots:
        target = out / "urdf" / f"{r.file_stem}.expanded.urdf"
        target.write_text(expand(out / "urdf" / f"{r.file_stem}.urdf.xacro"), encoding="utf-8")
        pairs.append(Pair(r, out / "urdf" / f"{r.file_stem}.urdf", target))
    return pairs


CASES = [f"example/{p.stem}" for p in EXAMPLES] + [f"chain/{k}" for k in CHAINS]


@pytest.fixture(scope="module", params=CASES)
def pairs(request, tmp_path_factory) -> list[Pair]:
    kind, name = request.param.split("/", 1)
    out = tmp_path_factory.mktemp(name) / "out"
    if kind == "example":
        c = check_file(next(p for p in EXAMPLES if p.stem == name))
        assert c.ok
    else:
        c = checked_ok(CHAINS[name], f"{name}.mod")
    return compile_pairs(c, out)


# ------------------------------------------------------------------------------------------------
# comparison helpers


def load(path: Path) -> pin.Model:
    return pin.buildModelFromUrdf(str(path))


def config(model: pin.Model, names: list[str], q) -> np.ndarray:
    qp = pin.neutral(model)
    for name, qi in zip(names, q, strict=True):
        qp[model.joints[model.getJointId(name)].idx_q] = qi
    return qp


def random_qs(robot: Robot, n: int, seed: int) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    lims = np.array([robot.joint_range(i) for i in range(1, robot.dof + 1)])
    return [np.zeros(robot.dof)] + [rng.uniform(lims[:, 0], lims[:, 1]) for _ in range(n)]


def frames(model: pin.Model, q: np.ndarray) -> dict[str, np.ndarray]:
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    return {f.name: data.oMf[i].homogeneous for i, f in enumerate(model.frames)}


def err(a, b) -> float:
    return float(np.max(np.abs(np.asarray(a, dtype=float) - np.asarray(b, dtype=float))))


def assert_close(a, b, what: str, tol: float = TOL) -> None:
    e = err(a, b)
    assert e <= tol, f"{what}: max |error| {e:.3g} > {tol:g}\nxacro\n{a}\nurdf\n{b}"


def joint_names(robot: Robot, prefix: str = "") -> list[str]:
    return [f"{prefix}joint_{i}" for i in range(1, robot.dof + 1)]


def assert_equivalent(robot: Robot, jinja: pin.Model, xm: pin.Model, seed: int = 0, prefix: str = "") -> None:
    """Kinematics, limits and dynamics of the xacro model `xm` equal those of the Jinja URDF."""
    names = joint_names(robot)
    xnames = joint_names(robot, prefix)
    assert list(jinja.names[1:]) == names
    assert sorted(n for n in xm.names[1:]) == sorted(xnames), "revolute joints of the expansion"
    ja = [jinja.getJointId(n) for n in names]
    jb = [xm.getJointId(n) for n in xnames]
    # limits (position, effort, velocity), per joint
    for a, b, n in zip(ja, jb, names, strict=True):
        ia, ib = jinja.joints[a].idx_q, xm.joints[b].idx_q
        got = [xm.lowerPositionLimit[ib], xm.upperPositionLimit[ib], xm.effortLimit[xm.joints[b].idx_v],
               xm.velocityLimit[xm.joints[b].idx_v]]
        want = [jinja.lowerPositionLimit[ia], jinja.upperPositionLimit[ia], jinja.effortLimit[jinja.joints[a].idx_v],
                jinja.velocityLimit[jinja.joints[a].idx_v]]
        assert_close(got, want, f"{n} limits")
        assert_close(xm.jointPlacements[b].homogeneous, jinja.jointPlacements[a].homogeneous, f"{n} placement")
    # the rigid body moving with each joint, and (index 0) what is fixed to the base
    for a, b in [(0, 0), *zip(ja, jb, strict=True)]:
        A, B = jinja.inertias[a], xm.inertias[b]
        what = f"body of {jinja.names[a]}"
        assert_close(B.mass, A.mass, f"{what}: mass")
        assert_close(B.lever, A.lever, f"{what}: centre of mass")
        assert_close(B.inertia, A.inertia, f"{what}: inertia")
    assert_close(pin.computeTotalMass(xm), pin.computeTotalMass(jinja), "total mass")
    da, db = jinja.createData(), xm.createData()
    pin.computeSubtreeMasses(jinja, da)
    pin.computeSubtreeMasses(xm, db)
    assert_close([db.mass[b] for b in jb], [da.mass[a] for a in ja], "subtree masses")
    va = [jinja.joints[a].idx_v for a in ja]  # the expansion's velocity indices may be a permutation
    vb = [xm.joints[b].idx_v for b in jb]
    rng = np.random.default_rng(seed + 1)
    for q in random_qs(robot, N_Q, seed):
        qa, qb = config(jinja, names, q), config(xm, xnames, q)
        fa, fb = frames(jinja, qa), frames(xm, qb)
        common = [f for f in fa if f != "universe"]
        assert all(prefix + f in fb for f in common), sorted(set(common) - {f[len(prefix):] for f in fb})
        for f in common:
            assert_close(fb[prefix + f], fa[f], f"FK of {f} at q={np.round(q, 3)}")
        Ma = pin.crba(jinja, da, qa)
        Mb = pin.crba(xm, db, qb)
        Ma = np.triu(Ma) + np.triu(Ma, 1).T
        Mb = np.triu(Mb) + np.triu(Mb, 1).T
        assert_close(Mb[np.ix_(vb, vb)], Ma[np.ix_(va, va)], f"mass matrix at q={np.round(q, 3)}")
        ga = pin.computeGeneralizedGravity(jinja, da, qa)
        gb = pin.computeGeneralizedGravity(xm, db, qb)
        assert_close(gb[vb], ga[va], f"gravity torques at q={np.round(q, 3)}")
        v = rng.uniform(-1, 1, robot.dof)
        acc = rng.uniform(-1, 1, robot.dof)
        va_, aa_ = np.zeros(jinja.nv), np.zeros(jinja.nv)
        vb_, ab_ = np.zeros(xm.nv), np.zeros(xm.nv)
        va_[va], aa_[va], vb_[vb], ab_[vb] = v, acc, v, acc
        assert_close(pin.rnea(xm, db, qb, vb_, ab_)[vb], pin.rnea(jinja, da, qa, va_, aa_)[va], "inverse dynamics")


def visuals(path: Path, model: pin.Model, q: np.ndarray) -> list[tuple[str, str, np.ndarray]]:
    """(mesh file, scale, pose in base_link) of every <visual>, placed with pinocchio's frames."""
    poses = frames(model, q)
    out = []
    for link in ET.parse(path).getroot().findall("link"):
        for vis in link.findall("visual"):
            o = vis.find("origin")
            xyz = [float(x) for x in o.get("xyz").split()]
            rpy = [float(x) for x in o.get("rpy").split()]
            mesh = vis.find("geometry/mesh")
            scale = mesh.get("scale") or "1 1 1"
            out.append((mesh.get("filename"), " ".join(f"{float(s):.9g}" for s in scale.split()),
                        poses[link.get("name")] @ transform(xyz, rpy)))
    return out


# ------------------------------------------------------------------------------------------------
# every example and hand-picked chain


@pytest.mark.slow
def test_expansion_passes_check_urdf(pairs):
    exe = Path(sys.executable).parent / "check_urdf"
    assert exe.is_file(), f"check_urdf is expected next to {sys.executable}"
    for p in pairs:
        res = subprocess.run([str(exe), str(p.xacro_urdf)], capture_output=True, text=True, timeout=300)
        assert res.returncode == 0, (
            f"check_urdf rejects the expansion of {p.robot.file_stem}:\n{res.stdout}\n{res.stderr}"
        )
        assert "Successfully Parsed XML" in res.stdout and "root Link: base_link" in res.stdout


def test_expansion_is_equivalent_to_the_urdf(pairs):
    for k, p in enumerate(pairs):
        assert_equivalent(p.robot, load(p.urdf), load(p.xacro_urdf), seed=k)


def test_names_and_joint_types(pairs):
    """joint_1..n are the only movable joints; every link of the .urdf exists in the expansion."""
    for p in pairs:
        a, b = ET.parse(p.urdf).getroot(), ET.parse(p.xacro_urdf).getroot()
        assert b.get("name") == p.robot.file_stem
        movable = [j.get("name") for j in b.findall("joint") if j.get("type") != "fixed"]
        assert movable == joint_names(p.robot)
        assert all(j.get("type") == "revolute" and j.find("axis").get("xyz") == "0 0 1"
                   for j in b.findall("joint") if j.get("type") != "fixed")
        links_a = {link.get("name") for link in a.findall("link")}
        links_b = {link.get("name") for link in b.findall("link")}
        assert links_a <= links_b
        assert "base_link" in links_b and "tool0" in links_b
        # every link of the expansion is a body (no massless frames: PyBullet would give them 1 kg)
        assert all(
            link.find("inertial") is not None for link in b.findall("link") if link.get("name") != "base_link"
        )


def test_extra_links_are_the_papers_frames(pairs):
    """unit_n_base / unit_n_twist1 / link_n / unit_n_twist2 sit where modc.kinematics.Chain puts them."""
    for p in pairs:
        model = load(p.xacro_urdf)
        chain = Chain(p.robot)
        for q in random_qs(p.robot, 2, seed=7):
            f = frames(model, config(model, joint_names(p.robot), q))
            for n, (fr, u) in enumerate(zip(chain.frames(q), chain.units, strict=True), start=1):
                assert_close(f[f"unit_{n}_base"], fr["T_base_unit"], f"unit_{n}_base")
                assert_close(f[f"unit_{n}_twist1"], fr["T_base_twist1"], f"unit_{n}_twist1")
                assert_close(f[f"link_{n}"], fr["T_base_joint"], f"link_{n}")
                if u.has_link:
                    assert_close(f[f"unit_{n}_twist2"], fr["T_base_end"], f"unit_{n}_twist2")
            assert_close(f["tool0"], chain.T_base_tool(q), "tool0")


def test_same_meshes_at_the_same_places(pairs):
    for p in pairs:
        ma, mb = load(p.urdf), load(p.xacro_urdf)
        q = random_qs(p.robot, 1, seed=3)[-1]
        a = visuals(p.urdf, ma, config(ma, joint_names(p.robot), q))
        b = visuals(p.xacro_urdf, mb, config(mb, joint_names(p.robot), q))
        assert len(a) == len(b)
        left = list(a)
        for mesh, scale, T in b:
            hit = next((i for i, (m, s, U) in enumerate(left) if m == mesh and s == scale and err(T, U) <= TOL), None)
            assert hit is not None, f"{mesh} (scale {scale}) of the expansion is nowhere in the .urdf"
            left.pop(hit)
        # and every mesh is a file, relative to the expanded URDF (mesh_root's default)
        for mesh, _, _ in b:
            assert mesh.startswith("../meshes/") and (p.xacro_urdf.parent / mesh).resolve().is_file(), mesh


# ------------------------------------------------------------------------------------------------
# args, files, determinism


@pytest.fixture(scope="module")
def farm(tmp_path_factory) -> Pair:
    c = check_file(next(p for p in EXAMPLES if p.stem == "farm"))
    (pair,) = compile_pairs(c, tmp_path_factory.mktemp("farm") / "out")
    return pair


def test_prefix_arg(farm, tmp_path):
    x = farm.urdf.parent / f"{farm.robot.file_stem}.urdf.xacro"
    path = farm.urdf.parent / "prefixed.urdf"
    path.write_text(expand(x, prefix="left_"), encoding="utf-8")
    root = ET.parse(path).getroot()
    names = [e.get("name") for e in root.findall("link") + root.findall("joint")]
    assert names and all(n.startswith("left_") for n in names)
    assert_equivalent(farm.robot, load(farm.urdf), load(path), prefix="left_")


def test_mesh_root_arg(farm):
    x = farm.urdf.parent / f"{farm.robot.file_stem}.urdf.xacro"
    root = ET.fromstring(expand(x, mesh_root="package://modc_farm/meshes"))
    meshes = [m.get("filename") for m in root.iter("mesh")]
    assert meshes and all(m.startswith("package://modc_farm/meshes/") and m.endswith(".stl") for m in meshes)
    default = [m.get("filename") for m in ET.parse(farm.xacro_urdf).getroot().iter("mesh")]
    assert [m.replace("package://modc_farm/meshes/", "../meshes/") for m in meshes] == default


def test_xacro_cli(farm, tmp_path):
    """The `xacro` console script (next to python) expands the file the same as the Python API."""
    exe = Path(sys.executable).parent / "xacro"
    assert exe.is_file()
    x = farm.urdf.parent / f"{farm.robot.file_stem}.urdf.xacro"
    res = subprocess.run([str(exe), str(x), "prefix:=r_"], capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    assert res.stdout == expand(x, prefix="r_")


def test_files_and_library_layout():
    c = checked_ok(CHAINS["two_libraries"], "two.mod")
    files = xacro_backend.emit(Build(c.design))
    assert sorted(files) == [
        "config/mod2_planar_macro.srdf.xacro",
        "config/mod3_strict_macro.srdf.xacro",
        "urdf/mod2_planar.urdf.xacro",
        "urdf/mod2_planar_macro.xacro",
        "urdf/mod3_strict.urdf.xacro",
        "urdf/mod3_strict_macro.xacro",
        "urdf/modc_modules.xacro",
    ]
    lib = files["urdf/modc_modules.xacro"]
    for ident in ("mark2", "mark2_strict"):
        for k in (1, 2, 3, 4):
            assert f'<xacro:macro name="{ident}_unit{k}" ' in lib
        assert f'<xacro:property name="{ident}_units" ' in lib
    assert "<xacro:mark2_strict_unit4 " in files["urdf/mod3_strict_macro.xacro"]
    assert "<xacro:mark2_unit3 " in files["urdf/mod2_planar_macro.xacro"]
    # byte-for-byte deterministic
    again = xacro_backend.emit(Build(checked_ok(CHAINS["two_libraries"], "two.mod").design))
    assert again == files


def test_libraries_with_the_same_name(tmp_path):
    """A custom library called mark2 next to the built-in one: two macro sets, each with its data."""
    import yaml

    data = yaml.safe_load((ROOT / "libraries" / "mark2.yaml").read_text(encoding="utf-8"))
    data["variants"]["L"]["actuator"]["mass"] = 0.5
    data["variants"]["L"]["link_module"]["mass_per_length"] = 0.7
    data["units"][3]["x23"] = 0.3
    (tmp_path / "heavy_l.yaml").write_text(yaml.safe_dump(data), encoding="utf-8")
    src = tmp_path / "same.mod"
    src.write_text("robot a { chain H1 - L3(port=30deg) }\n"
                   "robot b { library \"heavy_l.yaml\"\n chain H1 - L3(port=30deg) }\n"
                   "robot c { chain H4 - L3 }\n", encoding="utf-8")
    c = check_file(src)
    assert c.ok, [d.message for d in c.diagnostics]
    pairs = compile_pairs(c, tmp_path / "out")
    lib = (tmp_path / "out" / "urdf" / "modc_modules.xacro").read_text(encoding="utf-8")
    assert '<xacro:macro name="mark2_unit3" ' in lib and '<xacro:macro name="mark2_2_unit3" ' in lib
    assert '<xacro:macro name="mark2_3_unit3" ' not in lib, "equal libraries share one macro set"
    assert "<xacro:mark2_2_unit3 " in (tmp_path / "out" / "urdf" / "mod2_b_macro.xacro").read_text(encoding="utf-8")
    for k, p in enumerate(pairs):
        assert_equivalent(p.robot, load(p.urdf), load(p.xacro_urdf), seed=k)
    masses = [pin.computeTotalMass(load(p.xacro_urdf)) for p in pairs[:2]]
    assert masses[1] > masses[0] + 0.1


def test_pybullet_sees_the_same_masses(farm):
    """PyBullet does not merge fixed joints and gives a link without <inertial> 1 kg: every link
    of the expansion but the root carries one, so the arm weighs the same. base_link is empty on
    purpose (KDL, hence robot_state_publisher, warns about an inertia on the root link and ignores
    it); PyBullet's default mass there does not move a fixed base."""
    import pybullet
    from pybullet_utils.bullet_client import BulletClient

    client = BulletClient(connection_mode=pybullet.DIRECT)
    try:
        def masses(path: Path) -> list[float]:
            body = client.loadURDF(str(path), useFixedBase=True)
            return [client.getDynamicsInfo(body, i)[0] for i in range(-1, client.getNumJoints(body))]

        urdf_total = sum(float(m.get("value")) for m in ET.parse(farm.urdf).getroot().iter("mass"))
        assert abs(sum(masses(farm.xacro_urdf)[1:]) - urdf_total) < 1e-9
    finally:
        client.disconnect()


# ------------------------------------------------------------------------------------------------
# two arms in one robot; the library by hand

WRAPPER = """<?xml version="1.0"?>
<robot name="two_arms" xmlns:xacro="http://www.ros.org/wiki/xacro">
  {includes}
  <link name="world"/>
  <xacro:{left} prefix="left_" parent="world" xyz="0 0.4 0" rpy="0 0 0.5"/>
  <xacro:{right} prefix="right_" parent="world" xyz="0.1 -0.4 0.2" rpy="0.3 0 -1"/>
</robot>
"""


def two_arm_case(tmp_path: Path, left: Pair, right: Pair, name: str) -> None:
    includes = "\n  ".join(sorted({f'<xacro:include filename="{p.urdf.parent / (p.robot.file_stem + "_macro.xacro")}"/>'
                                   for p in (left, right)}))
    src = tmp_path / f"{name}.urdf.xacro"
    src.write_text(WRAPPER.format(includes=includes, left=xacro_backend.macro_name(left.robot),
                                  right=xacro_backend.macro_name(right.robot)), encoding="utf-8")
    out = left.urdf.parent / f"{name}.urdf"  # beside the meshes' ../meshes
    out.write_text(expand(src), encoding="utf-8")
    res = subprocess.run([str(Path(sys.executable).parent / "check_urdf"), str(out)], capture_output=True, text=True)
    assert res.returncode == 0 and "root Link: world" in res.stdout, res.stdout + res.stderr
    def names(path: Path) -> list[str]:
        root = ET.parse(path).getroot()
        return [e.get("name") for e in root.findall("link") + root.findall("joint")]

    got = names(out)
    assert len(got) == len(set(got)), "duplicate names"
    want = {"world", "left_base_joint", "right_base_joint"} | {f"left_{n}" for n in names(left.xacro_urdf)} \
        | {f"right_{n}" for n in names(right.xacro_urdf)}
    assert set(got) == want
    model = load(out)
    assert model.nq == left.robot.dof + right.robot.dof
    mounts = {"left": transform((0, 0.4, 0), (0, 0, 0.5)), "right": transform((0.1, -0.4, 0.2), (0.3, 0, -1))}
    rng = np.random.default_rng(11)
    for _ in range(3):
        qs = {
            side: random_qs(p.robot, 1, int(rng.integers(1 << 30)))[-1]
            for side, p in (("left", left), ("right", right))
        }
        qp = pin.neutral(model)
        for side, p in (("left", left), ("right", right)):
            for n, qi in zip(joint_names(p.robot, side + "_"), qs[side], strict=True):
                qp[model.joints[model.getJointId(n)].idx_q] = qi
        f = frames(model, qp)
        for side, p in (("left", left), ("right", right)):
            chain = Chain(p.robot)
            assert_close(f[f"{side}_tool0"], mounts[side] @ chain.T_base_tool(qs[side]), f"{side}_tool0")
    single = pin.computeTotalMass(load(left.urdf)) + pin.computeTotalMass(load(right.urdf)) \
        + load(left.urdf).inertias[0].mass + load(right.urdf).inertias[0].mass
    assert_close(pin.computeTotalMass(model) + model.inertias[0].mass, single, "total mass of both arms")


def test_two_instances_of_one_arm(farm, tmp_path):
    two_arm_case(tmp_path, farm, farm, "two_farms")


@pytest.mark.slow
def test_two_different_arms_from_one_file(tmp_path):
    c = checked_ok(CHAINS["two_libraries"], "two.mod")
    planar, strict = compile_pairs(c, tmp_path / "out")
    two_arm_case(tmp_path, planar, strict, "planar_and_strict")


HAND = """<?xml version="1.0"?>
<robot name="mod2_hand" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="{library}"/>
  <link name="base_link"/>
  <xacro:mark2_unit1 n="1" variant="H" parent="base_link"/>
  <xacro:mark2_unit3 n="2" variant="L" parent="link_1"/>
  <joint name="tool0_joint" type="fixed">
    <parent link="unit_2_twist2"/>
    <child link="tool0"/>
    <origin xyz="0 0 0" rpy="0 0 0"/>
  </joint>
  <link name="tool0">
    <inertial>
      <mass value="1e-06"/>
      <inertia ixx="4e-13" ixy="0" ixz="0" iyy="4e-13" iyz="0" izz="4e-13"/>
    </inertial>
  </link>
</robot>
"""


def test_library_by_hand_with_defaults(tmp_path):
    """The macros' defaults (pivot 0, port 0, link x23, the variant's limits) are the library's."""
    c = checked_ok("robot hand { chain H1 - L3 }", "hand.mod")
    (pair,) = compile_pairs(c, tmp_path / "out")
    src = tmp_path / "hand.urdf.xacro"
    src.write_text(HAND.format(library=pair.urdf.parent / "modc_modules.xacro"), encoding="utf-8")
    out = pair.urdf.parent / "hand.urdf"
    out.write_text(expand(src), encoding="utf-8")
    assert_equivalent(pair.robot, load(pair.urdf), load(out))


# ------------------------------------------------------------------------------------------------
# random valid chains


@pytest.mark.slow
@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(spec=robot_specs())
def test_random_chains(spec, tmp_path_factory):
    c = checked_ok(spec.text, "random.mod")
    (pair,) = compile_pairs(c, tmp_path_factory.mktemp("random") / "out")
    assert_equivalent(pair.robot, load(pair.urdf), load(pair.xacro_urdf), seed=len(spec.text))
