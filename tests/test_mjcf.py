"""The MJCF backend, checked by MuJoCo itself, and `modc sim --engine mujoco`.

MuJoCo loads every example's model; its masses, tool0 and gravity torques at rest (mj_inverse)
equal pinocchio on the emitted URDF at random poses; the servos hold home; an overloaded arm
sags; the cell, targets, keyframes and contact exclusions are those of the file and the SRDF.
"""
from __future__ import annotations

import os
import re
import xml.etree.ElementTree as ET
from pathlib import Path

if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
    os.environ.setdefault("MUJOCO_GL", "egl")  # before mujoco's first import: its GL is fixed then
import mujoco  # noqa: E402
import numpy as np  # noqa: E402
import pinocchio as pin  # noqa: E402
import pytest  # noqa: E402
from conftest import EXAMPLES, ROOT
from test_sim import FOLD, HEAVY, WALL

from modc.backends import mjcf, mjcf_scene
from modc.compiler import build, check_file, check_text
from modc.files import write_files
from modc.kinematics import Chain, transform
from modc.sim import mujoco_engine, smoke
from modc.sim.contacts import srdf_disabled_pairs

YAML_EXAMPLES = sorted(p for p in (ROOT / "examples").iterdir() if p.suffix in (".yaml", ".yml"))
BACKENDS = ["urdf", "meshes", "srdf", "mjcf"]
POSES = 20  # random configurations per robot


def compiled(tmp_path: Path, checked) -> Path:
    assert checked.ok, [d.message for d in checked.diagnostics]
    write_files(build(checked, BACKENDS), tmp_path)
    return tmp_path


def load(root: Path, robot) -> mujoco.MjModel:
    return mujoco.MjModel.from_xml_path(str(root / "mjcf" / f"{robot.file_stem}.xml"))


def write(tmp_path: Path, text: str, name: str = "t.mod") -> Path:
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


def pin_model(root: Path, robot):
    """pinocchio on the emitted URDF, its gravity (-9.81 z of the world) turned into base_link as
    the base placement says."""
    model = pin.buildModelFromUrdf(str(root / "urdf" / f"{robot.file_stem}.urdf"))
    R_world_base = transform(robot.base.xyz, robot.base.rpy)[:3, :3]
    model.gravity.linear = R_world_base.T @ model.gravity.linear
    return model


@pytest.mark.parametrize("path", EXAMPLES + YAML_EXAMPLES, ids=lambda p: p.name)
def test_every_example_loads_in_mujoco_with_its_structure(path, tmp_path):
    checked = check_file(path)
    root = compiled(tmp_path, checked)
    for robot in checked.design.robots:
        m = load(root, robot)
        n = robot.dof
        assert [m.joint(i).name for i in range(m.njnt)] == [f"joint_{i}" for i in range(1, n + 1)]
        assert all(t == mujoco.mjtJoint.mjJNT_HINGE for t in m.jnt_type)
        for i in range(1, n + 1):
            lo, hi = robot.joint_range(i)
            assert np.allclose(m.jnt_range[i - 1], (lo, hi), atol=1e-11)
        # one servo per joint, force-limited to the actuator's peak torque
        assert m.nu == n and list(m.actuator_trnid[:, 0]) == list(range(n))
        peaks = [robot.library.variants[u.variant].actuator.torque_peak for u in robot.units]
        assert np.allclose(m.actuator_forcerange, np.c_[-np.array(peaks), peaks])
        assert all(m.actuator_forcelimited)
        kp, kv = m.actuator_gainprm[:, 0], -m.actuator_biasprm[:, 2]
        assert np.allclose(kp, np.array(peaks) / mjcf.ERROR_AT_PEAK) and np.allclose(kv, kp * 0.05 / 2)
        assert m.site("tool0").bodyid[0] == m.body("tool0").id
        # the robot file is the robot alone (it loads by itself); its scene adds the cell
        assert not any(m.geom_bodyid == 0) and m.nsite == 1
        sc = mujoco.MjModel.from_xml_path(str(root / "mjcf" / mjcf.scene_name(robot)))
        world = sorted(sc.geom(g).name for g in range(sc.ngeom) if sc.geom_bodyid[g] == 0)
        assert world == sorted([o.name for o in robot.obstacles] + [mjcf_scene.FLOOR])
        for t in robot.targets:
            assert sc.site(mjcf.TARGET_PREFIX + t.name).bodyid[0] == 0
        assert sc.cam(mjcf_scene.CAMERA).id == 0 and sc.nlight >= 1 and sc.nbody == m.nbody
        _visual_collision_split(m)
        keys = [m.key(k).name for k in range(m.nkey)]
        assert keys == ["home"] + [p.name for p in robot.poses if p.name != "home"]
        assert np.allclose(m.key_qpos[0], robot.home()) and np.allclose(m.key_ctrl[0], robot.home())
        # contact exclusions: exactly the SRDF's disabled pairs, every reason
        srdf = root / "config" / f"{robot.file_stem}.srdf"
        excluded = {frozenset((m.body(int(s) >> 16).name, m.body(int(s) & 0xFFFF).name)) for s in m.exclude_signature}
        assert excluded == srdf_disabled_pairs(srdf, include_never=True)


def _visual_collision_split(m):
    """Every mesh geom is visual only (contype = conaffinity = 0, group 2); every link with meshes
    has collision geoms of its own (group 3), primitives, none of them a mesh."""
    for g in range(m.ngeom):
        if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_MESH:
            assert m.geom_contype[g] == 0 and m.geom_conaffinity[g] == 0 and m.geom_group[g] == 2
        elif m.geom_bodyid[g] != 0:
            assert m.geom_contype[g] == 1 and m.geom_conaffinity[g] == 1 and m.geom_group[g] == 3
            assert m.geom_type[g] in (int(mujoco.mjtGeom.mjGEOM_BOX), int(mujoco.mjtGeom.mjGEOM_CYLINDER))
    for b in range(1, m.nbody):
        geoms = m.geom_bodyid == b
        if geoms.any():
            assert (geoms & (m.geom_contype != 0)).any(), m.body(b).name


def test_u_bracket_collides_as_its_plate_and_cheeks(tmp_path):
    """A box between the cheeks of a twist unit's U-bracket touches nothing: with the mesh's
    convex hull (before) it was inside a solid block."""
    checked = check_text("robot r { chain H1 - L3 }", "u.mod")
    root = compiled(tmp_path, checked)
    (robot,) = checked.design.robots
    m = load(root, robot)
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    # base_link's twist unit: a plate (the lowest cylinder) and two cheeks (boxes) rising from it
    base = [g for g in range(m.ngeom) if m.geom_bodyid[g] == m.body("base_link").id and m.geom_contype[g]]
    cheeks = [g for g in base if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_BOX]
    plate = min((g for g in base if m.geom_type[g] == mujoco.mjtGeom.mjGEOM_CYLINDER), key=lambda g: d.geom_xpos[g][2])
    assert len(cheeks) == 2
    middle = (d.geom_xpos[cheeks[0]] + d.geom_xpos[cheeks[1]]) / 2.0  # inside the U, above the plate
    spec = mujoco.MjSpec.from_file(str(root / "mjcf" / f"{robot.file_stem}.xml"))
    spec.worldbody.add_body(name="probe", pos=middle.tolist()).add_geom(
        type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[0.005, 0, 0])
    m2 = spec.compile()
    d2 = mujoco.MjData(m2)
    mujoco.mj_forward(m2, d2)
    probe = m2.ngeom - 1
    assert m2.geom_bodyid[probe] == m2.body("probe").id
    for g in [*cheeks, plate]:
        assert mujoco.mj_geomDistance(m2, d2, g, probe, 1.0, None) > 0.0, m2.geom(g)


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_mass_tool0_and_gravity_torques_equal_pinocchio_on_the_urdf(path, tmp_path):
    checked = check_file(path)
    root = compiled(tmp_path, checked)
    _agrees_with_pinocchio(root, checked)


def test_tilted_base_agrees_with_pinocchio(tmp_path):
    """A wall-mounted arm: gravity reaches the joints through the base placement."""
    checked = check_text(WALL, "wall.mod")
    _agrees_with_pinocchio(compiled(tmp_path, checked), checked)


def _agrees_with_pinocchio(root: Path, checked):
    rng = np.random.default_rng(7)
    for robot in checked.design.robots:
        m, pm = load(root, robot), pin_model(root, robot)
        m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONTACT  # at random poses links may overlap
        d, pd = mujoco.MjData(m), pm.createData()
        # total mass: pinocchio keeps base_link's inertia on the universe joint, MuJoCo on a world-welded body
        assert abs(mujoco.mj_getTotalmass(m) - sum(i.mass for i in pm.inertias)) < 1e-9
        moving = sum(m.body_mass[b] for b in range(m.nbody) if m.body_weldid[b] != 0)
        assert abs(moving - pin.computeTotalMass(pm)) < 1e-9
        T_world_base = transform(robot.base.xyz, robot.base.rpy)
        tool = pm.getFrameId("tool0")
        lo, hi = m.jnt_range[:, 0], m.jnt_range[:, 1]
        for q in rng.uniform(lo, hi, size=(POSES, robot.dof)):
            d.qpos[:], d.qvel[:], d.qacc[:] = q, 0.0, 0.0
            mujoco.mj_inverse(m, d)
            tau = pin.computeGeneralizedGravity(pm, pd, q)
            assert np.abs(d.qfrc_inverse - tau).max() < 1e-6, (robot.name, q)
            pin.framesForwardKinematics(pm, pd, q)
            T_pin = T_world_base @ pd.oMf[tool].homogeneous
            assert np.abs(d.site("tool0").xpos - T_pin[:3, 3]).max() < 1e-6
            assert np.abs(d.site("tool0").xmat.reshape(3, 3) - T_pin[:3, :3]).max() < 1e-6


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_servos_hold_home_for_a_second(path, tmp_path):
    checked = check_file(path)
    root = compiled(tmp_path, checked)
    for robot in checked.design.robots:
        m = load(root, robot)
        d = mujoco.MjData(m)
        mujoco.mj_resetDataKeyframe(m, d, 0)
        drift = 0.0
        for _ in range(round(1.0 / m.opt.timestep)):
            mujoco.mj_step(m, d)
            drift = max(drift, float(np.abs(d.qpos - robot.home()).max()))
        assert drift < 0.02, (robot.name, drift)
        assert drift < mjcf.ERROR_AT_PEAK  # a carried load rests within the servo's error at peak torque


def test_overloaded_arm_sags(tmp_path):
    """HEAVY holds home but not `out`: joint_2 needs 11.7 N·m, its KA-58 peaks at 6.8 N·m."""
    checked = check_text(HEAVY, "heavy.mod")
    root = compiled(tmp_path, checked)
    (robot,) = checked.design.robots
    m = load(root, robot)
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, m.key("out").id)
    target = d.qpos.copy()
    for _ in range(1000):
        mujoco.mj_step(m, d)
    sag = np.abs(d.qpos - target)
    assert sag[1] > 0.3, sag  # tenths of a radian, not a servo error
    assert abs(d.actuator_force[1]) == pytest.approx(6.8)  # saturated at the peak


def test_mesh_references_are_relative_and_exist(tmp_path):
    checked = check_file(ROOT / "examples" / "farm.mod")
    root = compiled(tmp_path, checked)
    xml = root / "mjcf" / "mod3_farm.xml"
    tree = ET.parse(xml).getroot()
    assert tree.find("compiler").get("meshdir") == "../meshes"
    for mesh in tree.iter("mesh"):
        assert (xml.parent / "../meshes" / mesh.get("file")).is_file()


def test_source_name_cannot_break_the_xml(tmp_path):
    checked = check_text("robot r { chain H1 - L3 }", "a & <b> --> ${x}.mod")
    files = build(checked, ["mjcf"])
    for text in (files["mjcf/mod2_r.xml"], files["mjcf/scene_mod2_r.xml"]):
        assert ET.fromstring(text).tag == "mujoco"
        comments = re.findall(r"<!--(.*?)-->", text, flags=re.S)
        assert comments and all("--" not in c and "${" not in c for c in comments)


# ------------------------------------------------------------------------------------------------
# modc sim --engine mujoco


@pytest.mark.parametrize("path", EXAMPLES + YAML_EXAMPLES, ids=lambda p: p.name)
def test_every_example_passes_sim_in_mujoco(path):
    ok, lines, checked = smoke.run_sim(path, engine="mujoco")
    assert checked.ok and ok, "\n".join(lines)
    for res in mujoco_engine.simulate(checked):
        for p in res.poses:
            assert max(p.track_error) < mjcf.ERROR_AT_PEAK
            assert p.fk_pos_error < 1e-9 and p.fk_rot_error < 1e-9
            assert p.torque_error < 1e-6


def test_mujoco_overloaded_arm_fails_naming_the_sagging_joint(tmp_path):
    ok, lines, checked = smoke.run_sim(write(tmp_path, HEAVY), engine="mujoco")
    assert checked.ok and not ok
    (res,) = mujoco_engine.simulate(checked)
    home, out = res.poses
    assert not home.failures
    sags = [f for f in out.failures if f.kind == "sag"]
    assert [f.joint for f in sags] == ["joint_2"], out.failures
    assert sags[0].message.startswith("robot heavy, pose out: joint_2 sags")
    assert "6.8 N·m" in sags[0].message and "cannot hold the arm" in sags[0].message
    needs = float(re.search(r"needs ([0-9.]+) N·m", sags[0].message).group(1))
    assert 11.0 < needs < 12.5
    assert any("joint_2 sags" in line for line in lines)


def test_mujoco_self_collision_and_srdf_pairs(tmp_path):
    path = write(tmp_path, FOLD)
    ok, lines, checked = smoke.run_sim(path, engine="mujoco")
    assert not ok
    (res,) = mujoco_engine.simulate(checked, hold_time=0.2)
    cols = [f for f in res.poses[1].failures if f.kind == "self-collision"]
    assert [f.links for f in cols] == [("base_link", "link_2")]
    assert not res.poses[0].failures
    out = tmp_path / "out"
    (out / "config").mkdir(parents=True)
    srdf = out / "config" / "mod3_fold.srdf"
    for reason, passes in (("Default", True), ("Never", False)):
        pair = f'<disable_collisions link1="base_link" link2="link_2" reason="{reason}"/>'
        srdf.write_text(f'<robot name="mod3_fold">{pair}</robot>')
        ok, lines, _ = smoke.run_sim(path, out_dir=out, engine="mujoco", hold_time=0.2)
        assert ok == passes, (reason, lines)


def test_mujoco_pose_inside_an_obstacle_fails(tmp_path):
    base = "robot boxed {\n    chain H1 - H4(pivot=-90deg) - L4\n"
    robot = check_text(base + "}", "t.mod").design.robots[0]
    p = Chain(robot).frames([0.0, 0.0, 0.0])[2]["T_base_joint"][:3, 3]  # joint 3, inside link_2's actuator
    text = base + f"    box wall size (0.05, 0.05, 0.05) m at ({p[0]:.4f}, {p[1]:.4f}, {p[2]:.4f}) m\n}}\n"
    ok, lines, checked = smoke.run_sim(write(tmp_path, text), engine="mujoco", hold_time=0.2)
    assert not ok
    env = [line for line in lines if "is inside obstacle wall" in line]
    assert env and any("link_2 is inside obstacle wall" in line for line in env), lines


def test_mujoco_tilted_base(tmp_path):
    ok, lines, _ = smoke.run_sim(write(tmp_path, WALL), engine="mujoco")
    assert ok, lines


def _tampered(tmp_path: Path, edit):
    checked = check_text("robot t { chain H1 - L4(pivot=-90deg, port=45deg) - L1 }", "t.mod")
    root = compiled(tmp_path, checked)
    (robot,) = checked.design.robots
    xml = root / "mjcf" / f"{robot.file_stem}.xml"
    xml.write_text(edit(xml.read_text()))
    return mujoco_engine.simulate_robot(robot, xml, hold_time=1.0)


def test_mujoco_catches_tampered_kinematics_and_inertials(tmp_path):
    res = _tampered(tmp_path / "fk", lambda t: t.replace('<body name="link_1" pos="0 0 0.147"',
                                                         '<body name="link_1" pos="0 0 0.1475"', 1))
    assert any(f.kind == "fk" and "MuJoCo puts tool0" in f.message for f in res.all_failures)
    res = _tampered(tmp_path / "mass", lambda t: re.sub(r'(<body name="link_2".*?<inertial pos="[^"]*" mass=")([^"]*)"',
                                                         r'\g<1>0.9"', t, count=1, flags=re.S))
    assert any(f.kind == "torque" for f in res.all_failures), res.all_failures
    res = _tampered(tmp_path / "load", lambda t: t.replace('file="actuator_L.stl"', 'file="nothing.stl"'))
    assert [f.kind for f in res.failures] == ["load"] and "MuJoCo cannot load" in res.failures[0].message


def test_cli_engine_option(tmp_path):
    from click.testing import CliRunner

    from modc.cli import app

    runner = CliRunner()
    r = runner.invoke(app, ["sim", str(ROOT / "examples" / "table3_planar.mod"), "--engine", "mujoco"])
    assert r.exit_code == 0 and "sim: 1 robot(s)" in r.output, r.output
    r = runner.invoke(app, ["sim", str(write(tmp_path, HEAVY)), "--engine", "mujoco"])
    assert r.exit_code == 1 and "joint_2 sags" in r.output
    r = runner.invoke(app, ["sim", str(ROOT / "examples" / "table3_planar.mod"), "--engine", "ode"])
    assert r.exit_code == 2 and "unknown engine 'ode'" in r.output
    traj = write(tmp_path, '{"joint_names": ["joint_1", "joint_2"], "points": [{"t": 0, "q": [0, 0]}, '
                           '{"t": 0.2, "q": [0.2, -0.1]}]}', "t.json")
    r = runner.invoke(app, ["play", str(ROOT / "examples" / "table3_planar.mod"), "--traj", str(traj),
                            "--engine", "ode"])
    assert r.exit_code == 2 and "unknown engine 'ode'" in r.output
    r = runner.invoke(app, ["play", str(ROOT / "examples" / "table3_planar.mod"), "--traj", str(traj),
                            "--engine", "mujoco"])
    assert r.exit_code == 0 and "in MuJoCo" in r.output and "tracking error per joint" in r.output, r.output


def test_home_keyframe_is_robot_home_within_narrowed_limits(tmp_path):
    """No `pose home` and a `limit` that excludes 0: the keyframe is MoveIt's default (mid-range),
    the one Robot.home, and the joint range is the narrowed one."""
    from test_home import EXPECTED, LIMITED

    checked = check_text(LIMITED, "limited.mod")
    root = compiled(tmp_path, checked)
    (robot,) = checked.design.robots
    m = load(root, robot)
    assert m.key(0).name == "home"
    assert np.allclose(m.key_qpos[0], EXPECTED, atol=1e-11) and np.allclose(m.key_ctrl[0], EXPECTED, atol=1e-11)
    assert np.allclose(m.jnt_range[1], np.radians([10.0, 90.0]), atol=1e-11)


def _library(tmp_path: Path, **replace) -> Path:
    text = (ROOT / "libraries" / "mark2.yaml").read_text(encoding="utf-8")
    for old, new in replace.items():
        text = re.sub(old, lambda _m, new=new: new, text, count=1, flags=re.M)
    return write(tmp_path, text, "lib.yaml")


def test_a_number_mujoco_cannot_hold_is_a_diagnostic_not_inf(tmp_path):
    """A peak torque near the float limit made kp = inf in the MJCF; now compile refuses, at the
    robot's library statement, and writes nothing."""
    from click.testing import CliRunner

    from modc.cli import app

    _library(tmp_path, **{r"torque_peak: 30\.5.*$": "torque_peak: 1e307"})
    mod = write(tmp_path, 'robot a {\n  library "lib.yaml"\n  chain H1 - H4(pivot=-90deg) - L3(port=45deg)\n}\n')
    res = CliRunner().invoke(app, ["compile", str(mod), "-o", str(tmp_path / "out")])
    assert res.exit_code == 1, res.output
    # the library's own range check (out-of-range, at the YAML line) catches it first; the MJCF's
    # not-finite check below is the backstop for any number that still overflows
    assert "error[out-of-range]" in res.output or "error[not-finite]" in res.output, res.output
    assert "inf" not in res.output.replace("infinite", "") and "Traceback" not in res.output
    assert not (tmp_path / "out").exists()


def test_the_mjcf_refuses_a_number_that_overflows(tmp_path):
    """Whatever the library check lets through, a number MuJoCo cannot hold is a not-finite
    diagnostic at the robot's library statement, never kp="inf" in the file."""
    from modc.backends import mjcf
    from modc.diagnostics.errors import InputError

    mod = write(tmp_path, 'robot a {\n  chain H1 - L3\n}\n')
    checked = check_file(mod)
    (robot,) = checked.design.robots

    def overflowing():
        return mjcf.num(float("inf"))

    with pytest.raises(InputError) as e:
        mjcf._finite(robot, overflowing)
    assert e.value.diagnostic.code == "not-finite"
    assert "inf" not in e.value.diagnostic.message.replace("infinite", "")


def test_library_name_goes_through_the_comment_sanitiser(tmp_path):
    _library(tmp_path, **{r"^name: mark2.*$": "name: evil--x-"})  # a valid label that would end an XML comment
    mod = write(tmp_path, 'robot a {\n  library "lib.yaml"\n  chain H1 - L3\n}\n')
    checked = check_file(mod)
    assert checked.ok, [d.message for d in checked.diagnostics]
    files = build(checked, ["mjcf"])
    for rel in ("mjcf/mod2_a.xml", "mjcf/scene_mod2_a.xml"):
        text = files[rel]
        assert ET.fromstring(text).tag == "mujoco"
        comments = re.findall(r"<!--(.*?)-->", text, flags=re.S)
        assert comments and all("--" not in c and not c.endswith("-") for c in comments), rel
    assert "(library evil- -x- )" in files["mjcf/mod2_a.xml"]


# ------------------------------------------------------------------------------------------------
# The scene in MuJoCo's offscreen renderer, and plans played in MuJoCo


def _renderer(m, h=240, w=320):
    try:
        return mujoco.Renderer(m, h, w)
    except Exception as e:  # no EGL/OSMesa on this machine
        pytest.skip(f"MuJoCo cannot render offscreen here: {e}")


@pytest.mark.parametrize("name", ["cellarm", "farm", "table3_wrist"])
def test_scene_renders_lit_and_shows_the_arm(name, tmp_path):
    checked = check_file(ROOT / "examples" / f"{name}.mod")
    root = compiled(tmp_path, checked)
    (robot,) = checked.design.robots
    m = mujoco.MjModel.from_xml_path(str(root / "mjcf" / mjcf.scene_name(robot)))
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, 0)
    mujoco.mj_forward(m, d)
    r = _renderer(m)
    shown = mujoco.MjvOption()
    r.update_scene(d, camera=mjcf_scene.CAMERA, scene_option=shown)
    img = r.render().astype(float)
    hidden = mujoco.MjvOption()
    hidden.geomgroup[mjcf.VISUAL_GROUP] = 0  # the arm's meshes
    r.update_scene(d, camera=mjcf_scene.CAMERA, scene_option=hidden)
    bare = r.render().astype(float)
    r.enable_segmentation_rendering()
    r.update_scene(d, camera=mjcf_scene.CAMERA, scene_option=shown)
    seg = r.render()
    r.close()
    assert img.mean() > 120  # lit: a dark void (the robot file alone, no light) is near 0
    geom = seg[:, :, 1] == int(mujoco.mjtObj.mjOBJ_GEOM)
    arm = geom & (m.geom_bodyid[np.clip(seg[:, :, 0], 0, m.ngeom - 1)] != 0)
    assert arm.mean() > 0.02, arm.mean()  # the arm is drawn ...
    assert np.abs(img - bare).sum(axis=2)[arm].mean() > 60  # ... and shows there (hidden, the floor does)
    rows, cols = np.nonzero(arm)
    assert 0 < rows.min() and rows.max() < img.shape[0] - 1 and 0 < cols.min() and cols.max() < img.shape[1] - 1
    box = (rows.max() - rows.min()) * (cols.max() - cols.min()) / arm.size
    assert box > 0.08, box  # framed: wholly inside the picture, and not a speck in it
    # ... wholly inside it: the camera frames it; and the robot file alone is dark
    alone = load(root, robot)
    r = _renderer(alone)
    da = mujoco.MjData(alone)
    mujoco.mj_forward(alone, da)
    r.update_scene(da)
    assert r.render().mean() < img.mean() / 2
    r.close()


def _plan_file(tmp_path: Path, path: Path, target: str) -> Path:
    from modc.plan import plan

    out = tmp_path / f"{path.stem}_{target}.json"
    out.write_text(plan(path, target, seed=0).dumps(), encoding="utf-8")
    return out


@pytest.mark.slow
@pytest.mark.parametrize("name, target", [("cellarm", "p1"), ("farm", "plant"), ("farm", "tray")])
def test_plans_play_in_mujoco_within_5_mrad(name, target, tmp_path):
    from modc.sim.play import play

    path = ROOT / "examples" / f"{name}.mod"
    ok, lines, _ = play(path, _plan_file(tmp_path, path, target), engine="mujoco")
    assert ok, lines
    text = "\n".join(lines)
    per_joint = [float(v) for v in re.search(r"tracking error per joint \(max, rad\): (.*)", text).group(1).split(", ")]
    assert len(per_joint) == 3 and max(per_joint) < 0.005, text
    assert "MuJoCo" in lines[0] and "peak torque" not in text and "no collisions" in text


def test_play_in_mujoco_records_a_captioned_gif_and_reports_collisions(tmp_path):
    """farm's straight sweep from home to ready cuts the right wall (as in PyBullet); the GIF
    is lit, moves, and carries its caption band."""
    import json
    import math

    from PIL import Image

    from modc.sim.play import play

    doc = {"joint_names": ["joint_1", "joint_2", "joint_3"],
           "points": [{"t": 0.0, "q": [0, 0, 0]}, {"t": 1.0, "q": [math.pi / 4, -math.pi / 8, -math.pi / 4]},
                      {"t": 2.0, "q": [math.pi / 2, -math.pi / 4, -math.pi / 2]}]}
    traj = tmp_path / "sweep.json"
    traj.write_text(json.dumps(doc), encoding="utf-8")
    gif = tmp_path / "sweep.gif"
    probe = mujoco.MjModel.from_xml_string("<mujoco/>")
    _renderer(probe, 8, 8).close()
    ok, lines, _ = play(ROOT / "examples" / "farm.mod", traj, engine="mujoco", record=gif, size=(320, 240), fps=5.0)
    assert ok, lines
    text = "\n".join(lines)
    assert "warning: link_3 collides with obstacle right" in text
    assert float(re.search(r"worst tracking error ([0-9.e-]+) rad", text).group(1)) < 0.005
    img = Image.open(gif)
    assert img.size == (320, 240) and img.n_frames >= 10
    frames = []
    for k in range(img.n_frames):
        img.seek(k)
        frames.append(np.asarray(img.convert("RGB"), dtype=float))
    assert frames[0].mean() > 120
    assert np.abs(frames[0] - frames[-1]).mean() > 1.0  # the arm moved
    band = frames[0][-12:, :, :]
    assert band.mean() > 200 and band.min() < 100  # a light caption band with dark text
