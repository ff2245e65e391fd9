"""The ROS package backend (modc/backends/ros.py): OUT/ is a ROS package a ROS user can build and launch.

Every example is checked and the backend's emit is called directly (with the URDF backend's
output, which the ROS description wraps). What is asserted is what a ROS user relies on:
every YAML parses and carries the library's numbers (PID gains [2, 0, 0.05], rated speed,
peak torque, position range, home pose) under the names MoveIt and ros_control expect;
package.xml is a valid format 3 manifest (catkin_pkg) that builds with ament_cmake under ROS 2
and catkin under ROS 1; CMakeLists.txt installs urdf, meshes, config and launch; the launch
files run (against stand-ins for the ROS launch API) and load only files that exist; the ROS
description processes with xacro into the same robot as the plain URDF, with package:// meshes.
"""
from __future__ import annotations

import math
import re
import shutil
import subprocess
import sys
import types
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
import yaml

from conftest import EXAMPLES, checked_ok
from modc.backends import BACKENDS, Build, load_all

load_all()  # the driver's registration order first
_WIRED = "ros" in BACKENDS
from modc.backends import ros  # noqa: E402
from modc.backends import urdf as urdf_backend  # noqa: E402

if not _WIRED:  # imported here but not (yet) listed in load_all(): keep other tests' compiles as they were
    BACKENDS.pop("ros", None)
from modc.compiler import check_file

# catkin_pkg's condition parser uses pyparsing's pre-3.0 names
pytestmark = pytest.mark.filterwarnings("ignore:.*deprecated.*:DeprecationWarning")



def catkin():
    """catkin_pkg (test extra): the ROS tools' own package.xml parser."""
    return pytest.importorskip("catkin_pkg.package", reason="catkin_pkg parses package.xml")

TWO_ROBOTS = """
robot left_arm {
    chain H1 - L4(port=45deg) - L1
    pose home (10, -20, 30) deg
    limit joint_2 (-90, 45) deg
}
robot Wrist2 {
    chain L1 - L4(pivot=-90deg, port=90deg) - L1
    allow first-variant
    sphere ball radius 0.05 m at (0.3, 0, 0.2) m
}
"""


def make_build(checked) -> Build:
    b = Build(checked.design, diagnostics=list(checked.diagnostics))
    b.files.update(urdf_backend.emit(b))  # the plain URDF, as the compile driver would have it
    return b


def emit(checked, **options) -> tuple[Build, dict[str, str]]:
    b = make_build(checked)
    for k, v in options.items():
        setattr(b, k, v)
    return b, ros.emit(b)


def write(files: dict, out: Path) -> Path:
    for rel, content in files.items():
        p = out / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(content, bytes):
            p.write_bytes(content)
        else:
            p.write_text(content, encoding="utf-8")
    return out


@pytest.fixture(scope="module")
def examples(tmp_path_factory):
    """example stem -> (Build, ros files, package directory with the URDF and the ros files)."""
    out = {}
    for ex in EXAMPLES:
        c = check_file(ex)
        assert c.ok, ex
        b, files = emit(c)
        d = write({**b.files, **files}, tmp_path_factory.mktemp(ex.stem) / "pkg")
        out[ex.stem] = (b, files, d)
    return out


def load(files: dict, rel: str):
    assert rel in files, f"{rel} missing; emitted: {sorted(files)}"
    return yaml.safe_load(files[rel])


def close(text_value, expected: float, what: str) -> None:
    assert isinstance(text_value, float), f"{what}: {text_value!r} is not a float (ROS 2 parameters are typed)"
    assert math.isclose(text_value, expected, rel_tol=1e-10, abs_tol=1e-12), f"{what}: {text_value} != {expected}"


# ------------------------------------------------------------------------------------------------
# Files and names


def test_every_example_gets_the_package_files(examples):
    for stem, (b, files, _) in examples.items():
        assert {"package.xml", "CMakeLists.txt"} <= set(files)
        for robot in b.design.robots:
            f = ros.robot_files(robot.file_stem)
            expected = {f[k] for k in ("ros_controllers", "ros2_controllers", "moveit_controllers",
                                       "simple_moveit_controllers", "kinematics", "joint_limits",
                                       "initial_positions", "description", "ros2_control", "demo_launch",
                                       "display_launch_ros2", "display_launch_ros1")}
            assert expected <= set(files), (stem, sorted(expected - set(files)))
            assert all(p.startswith(f"config/{robot.file_stem}") for p in expected if p.endswith(".yaml"))
            assert (f["scene"] in files) == bool(robot.obstacles)


def test_output_is_deterministic():
    c = check_file(EXAMPLES[0])
    assert emit(c)[1] == emit(c)[1]


def test_package_names_are_valid_ros_names():
    assert ros.package_name("farm.mod") == "farm_modc"
    assert ros.package_name("examples/table3_raven.mod") == "table3_raven_modc"
    assert ros.package_name("quickstart.yaml") == "quickstart_modc"
    assert ros.package_name("My-Arm v2.mod") == "my_arm_v2_modc"
    assert ros.package_name("3D arm.mod") == "modc_3d_arm"
    assert ros.package_name("__.mod") == "modc"
    for name in ["farm.mod", "My-Arm v2.mod", "3D arm.mod", "__.mod", "x__y.mod", "<string>", "é.mod"]:
        pkg = ros.package_name(name)
        assert ros.valid_package_name(pkg), (name, pkg)
        assert re.fullmatch(r"[a-z][a-z0-9_]*", pkg) and "__" not in pkg
    assert not ros.valid_package_name("Farm") and not ros.valid_package_name("1farm")
    assert not ros.valid_package_name("farm__modc") and not ros.valid_package_name("farm_")


def test_package_name_override_is_validated():
    c = check_file(EXAMPLES[0])
    _, files = emit(c, ros_package="my_cell")
    assert "<name>my_cell</name>" in files["package.xml"]
    with pytest.raises(ValueError, match="not a valid ROS package name"):
        emit(c, ros_package="My-Cell")


# ------------------------------------------------------------------------------------------------
# package.xml and CMakeLists.txt


def test_package_xml_parses_with_catkin_pkg(examples):
    catkin_pkg = catkin()
    for stem, (b, files, d) in examples.items():
        pkg = catkin_pkg.parse_package(str(d / "package.xml"))
        pkg.validate()  # raises InvalidPackage on errors
        assert pkg.package_format == 3
        assert pkg.name == ros.package_name(b.source_name) == f"{stem}_modc"
        assert ros.valid_package_name(pkg.name)
        assert pkg.maintainers and pkg.licenses
        for version, build_type, buildtool in [("2", "ament_cmake", "ament_cmake"), ("1", "catkin", "catkin")]:
            p = catkin_pkg.parse_package(str(d / "package.xml"))
            p.evaluate_conditions({"ROS_VERSION": version})
            assert p.get_build_type() == build_type
            tools = [x.name for x in p.buildtool_depends if x.evaluated_condition]
            assert tools == [buildtool]
            deps = {x.name for x in p.exec_depends if x.evaluated_condition}
            assert {"robot_state_publisher", "xacro", "joint_trajectory_controller", "trac_ik_kinematics_plugin",
                    "moveit_simple_controller_manager", "controller_manager"} <= deps
            if version == "2":
                assert {"rviz2", "joint_state_broadcaster", "launch_ros", "moveit_configs_utils",
                        "moveit_ros_move_group"} <= deps and "rviz" not in deps
            else:
                assert {"rviz", "effort_controllers", "joint_state_controller"} <= deps and "rviz2" not in deps


def _fake_cmake_packages(root: Path) -> Path:
    """Minimal ament_cmake and catkin CMake configs: enough for this data-only package."""
    (root / "ament_cmake").mkdir(parents=True)
    (root / "ament_cmake" / "ament_cmakeConfig.cmake").write_text(
        "macro(ament_package)\n  set(AMENT_PACKAGE_CALLED TRUE)\nendmacro()\n")
    (root / "catkin").mkdir(parents=True)
    (root / "catkin" / "catkinConfig.cmake").write_text(
        "macro(catkin_package)\n"
        "  set(CATKIN_PACKAGE_SHARE_DESTINATION share/${PROJECT_NAME})\n"
        "endmacro()\n")
    return root


@pytest.mark.skipif(shutil.which("cmake") is None, reason="needs cmake")
@pytest.mark.parametrize("ros_version", ["2", "1"])
def test_cmakelists_installs_the_package(compiled_examples, tmp_path, ros_version):
    """CMakeLists.txt configures under ROS 2 (ament_cmake) and ROS 1 (catkin) and installs the
    package's urdf, meshes, config and launch directories into share/<package>."""
    src = tmp_path / "src"
    shutil.copytree(compiled_examples["farm"], src)  # URDF, meshes, report, ... of the real compile
    c = check_file(next(e for e in EXAMPLES if e.stem == "farm"))
    _, files = emit(c)
    write(files, src)
    fake = _fake_cmake_packages(tmp_path / "cmake")
    env = {"PATH": "/usr/bin:/bin", "ROS_VERSION": ros_version}
    build, prefix = tmp_path / "build", tmp_path / "install"
    r = subprocess.run(["cmake", "-S", str(src), "-B", str(build), f"-DCMAKE_PREFIX_PATH={fake}/ament_cmake;{fake}/catkin",
                        f"-DCMAKE_INSTALL_PREFIX={prefix}"], capture_output=True, text=True, env=env, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    r = subprocess.run(["cmake", "--install", str(build)], capture_output=True, text=True, env=env, timeout=300)
    assert r.returncode == 0, r.stdout + r.stderr
    share = prefix / "share" / "farm_modc"
    for rel in ["urdf/mod3_farm.urdf", "urdf/mod3_farm_ros.urdf.xacro", "urdf/mod3_farm.ros2_control.xacro",
                "config/mod3_farm_ros2_controllers.yaml", "config/mod3_farm_kinematics.yaml",
                "launch/mod3_farm_demo.launch.py", "launch/mod3_farm_display.launch"]:
        assert (share / rel).is_file(), rel
    meshes = sorted(p.name for p in (share / "meshes").iterdir())
    assert meshes and all(m.endswith(".stl") for m in meshes)


# ------------------------------------------------------------------------------------------------
# Controllers: the library's gains, joints and limits


def test_ros1_controllers_use_the_library_gains(examples):
    for stem, (b, files, _) in examples.items():
        for robot in b.design.robots:
            y = load(files, ros.robot_files(robot.file_stem)["ros_controllers"])
            names = [f"joint_{i}" for i in range(1, robot.dof + 1)]
            assert y["joint_state_controller"]["type"] == "joint_state_controller/JointStateController"
            arm = y["arm_controller"]
            assert arm["type"] == "effort_controllers/JointTrajectoryController"
            assert arm["joints"] == names
            ctl = robot.library.control
            assert (ctl.p, ctl.i, ctl.d) == (2.0, 0.0, 0.05)  # paper section 4.4
            assert set(arm["gains"]) == set(names)
            for n in names:
                g = arm["gains"][n]
                close(g["p"], ctl.p, f"{stem} {n} p")
                close(g["i"], ctl.i, f"{stem} {n} i")
                close(g["d"], ctl.d, f"{stem} {n} d")
                assert arm["constraints"][n]["goal"] > 0
            assert arm["constraints"]["goal_time"] > 0


def test_ros2_controllers(examples):
    for stem, (b, files, _) in examples.items():
        for robot in b.design.robots:
            y = load(files, ros.robot_files(robot.file_stem)["ros2_controllers"])
            names = [f"joint_{i}" for i in range(1, robot.dof + 1)]
            cm = y["controller_manager"]["ros__parameters"]
            assert isinstance(cm["update_rate"], int) and cm["update_rate"] > 0
            assert cm["arm_controller"]["type"] == "joint_trajectory_controller/JointTrajectoryController"
            assert cm["joint_state_broadcaster"]["type"] == "joint_state_broadcaster/JointStateBroadcaster"
            arm = y["arm_controller"]["ros__parameters"]
            assert arm["joints"] == names
            assert arm["command_interfaces"] == ["position"]  # mock hardware mirrors position commands
            assert arm["state_interfaces"] == ["position", "velocity"]
            ctl = robot.library.control
            for n in names:
                close(arm["gains"][n]["p"], ctl.p, f"{stem} {n} p")
                close(arm["gains"][n]["i"], ctl.i, f"{stem} {n} i")
                close(arm["gains"][n]["d"], ctl.d, f"{stem} {n} d")
                assert isinstance(arm["constraints"][n]["goal"], float)
                assert isinstance(arm["constraints"][n]["trajectory"], float)
            assert isinstance(arm["constraints"]["goal_time"], float)
            assert isinstance(arm["constraints"]["stopped_velocity_tolerance"], float)


def test_effort_command_interface_option():
    """build.ros2_command_interface = "effort": the ROS 2 JTC commands effort (and closes the PID
    with the gains), and the ros2_control joints bound the command by the peak torque."""
    c = check_file(next(e for e in EXAMPLES if e.stem == "farm"))
    b, files = emit(c, ros2_command_interface="effort")
    arm = load(files, "config/mod3_farm_ros2_controllers.yaml")["arm_controller"]["ros__parameters"]
    assert arm["command_interfaces"] == ["effort"]
    x = ET.fromstring(files["urdf/mod3_farm.ros2_control.xacro"])
    robot = b.design.robots[0]
    for k, joint in enumerate(x.iter("joint"), start=1):
        cmd = joint.find("command_interface")
        assert cmd.get("name") == "effort"
        peak = robot.library.variants[robot.units[k - 1].variant].actuator.torque_peak
        params = {p.get("name"): float(p.text) for p in cmd.findall("param")}
        assert params == {"min": -peak, "max": peak}
    with pytest.raises(ValueError):
        emit(c, ros2_command_interface="velocity")


def test_moveit_controllers(examples):
    for stem, (b, files, _) in examples.items():
        for robot in b.design.robots:
            names = [f"joint_{i}" for i in range(1, robot.dof + 1)]
            y = load(files, ros.robot_files(robot.file_stem)["moveit_controllers"])
            assert y["moveit_controller_manager"] == "moveit_simple_controller_manager/MoveItSimpleControllerManager"
            m = y["moveit_simple_controller_manager"]
            assert m["controller_names"] == ["arm_controller"]
            arm = m["arm_controller"]
            assert arm == {"type": "FollowJointTrajectory", "action_ns": "follow_joint_trajectory",
                           "default": True, "joints": names}
            y1 = load(files, ros.robot_files(robot.file_stem)["simple_moveit_controllers"])
            assert y1["controller_list"] == [{"name": "arm_controller", "action_ns": "follow_joint_trajectory",
                                             "type": "FollowJointTrajectory", "default": True, "joints": names}]


def test_joint_limits_match_the_library(examples):
    for stem, (b, files, _) in examples.items():
        for robot in b.design.robots:
            y = load(files, ros.robot_files(robot.file_stem)["joint_limits"])
            assert 0 < y["default_velocity_scaling_factor"] <= 1
            assert 0 < y["default_acceleration_scaling_factor"] <= 1
            limits = y["joint_limits"]
            assert list(limits) == [f"joint_{i}" for i in range(1, robot.dof + 1)]
            urdf = ET.fromstring(b.files[f"urdf/{robot.file_stem}.urdf"])
            for k, unit in enumerate(robot.units, start=1):
                lim = limits[f"joint_{k}"]
                act = robot.library.variants[unit.variant].actuator
                lo, hi = robot.joint_range(k)
                assert lim["has_position_limits"] and lim["has_velocity_limits"]
                assert lim["has_acceleration_limits"] and lim["has_effort_limits"]
                close(lim["min_position"], lo, f"{stem} joint_{k} min")
                close(lim["max_position"], hi, f"{stem} joint_{k} max")
                close(lim["max_velocity"], act.rpm * 2 * math.pi / 60, f"{stem} joint_{k} velocity")
                close(lim["max_effort"], act.torque_peak, f"{stem} joint_{k} effort")
                close(lim["max_acceleration"], act.velocity / ros.ACCEL_RAMP_TIME, f"{stem} joint_{k} acceleration")
                # the same limits as the URDF's <limit>
                u = urdf.find(f"joint[@name='joint_{k}']/limit")
                for key, attr in [("min_position", "lower"), ("max_position", "upper"),
                                  ("max_velocity", "velocity"), ("max_effort", "effort")]:
                    assert math.isclose(lim[key], float(u.get(attr)), rel_tol=1e-11), (stem, k, key)


def test_heavy_and_light_velocities():
    """Paper Table 1: KA-75+ 12.2 RPM, KA-58 20.3 RPM."""
    c = check_file(next(e for e in EXAMPLES if e.stem == "farm"))
    _, files = emit(c)
    limits = load(files, "config/mod3_farm_joint_limits.yaml")["joint_limits"]
    assert math.isclose(limits["joint_1"]["max_velocity"], 12.2 * math.pi / 30, rel_tol=1e-11)  # H1
    assert math.isclose(limits["joint_2"]["max_velocity"], 20.3 * math.pi / 30, rel_tol=1e-11)  # L4
    assert limits["joint_1"]["max_effort"] == 30.5 and limits["joint_3"]["max_effort"] == 6.8


def test_kinematics_uses_trac_ik(examples):
    for stem, (b, files, _) in examples.items():
        for robot in b.design.robots:
            y = load(files, ros.robot_files(robot.file_stem)["kinematics"])
            assert list(y) == ["arm"]  # no SRDF backend ran: the default group name
            g = y["arm"]
            assert g["kinematics_solver"] == "trac_ik_kinematics_plugin/TRAC_IKKinematicsPlugin"
            assert g["kinematics_solver_timeout"] > 0 and g["kinematics_solver_search_resolution"] > 0
            assert g["position_only_ik"] is (robot.dof < 6)
            # the documented fallback is right there
            assert "# kinematics_solver: kdl_kinematics_plugin/KDLKinematicsPlugin" in files[
                ros.robot_files(robot.file_stem)["kinematics"]]


def test_kdl_option():
    c = check_file(next(e for e in EXAMPLES if e.stem == "farm"))
    b, files = emit(c, ik_solver="kdl")
    assert load(files, "config/mod3_farm_kinematics.yaml")["arm"]["kinematics_solver"] == \
        "kdl_kinematics_plugin/KDLKinematicsPlugin"
    pkg = catkin().parse_package_string(files["package.xml"])
    names = {d.name for d in pkg.exec_depends}
    assert "moveit_kinematics" in names and "trac_ik_kinematics_plugin" not in names
    with pytest.raises(ValueError):
        emit(c, ik_solver="ikfast")


def test_planning_group_and_world_frame_follow_the_srdf():
    """If the SRDF backend ran first, kinematics.yaml keys the SRDF's arm group and the demo
    publishes the virtual joint's parent frame."""
    c = check_file(next(e for e in EXAMPLES if e.stem == "farm"))
    b = make_build(c)
    b.files["config/mod3_farm.srdf"] = (
        '<?xml version="1.0"?><robot name="mod3_farm"><group name="gripper"><link name="tool0"/></group>'
        '<group name="manipulator"><chain base_link="base_link" tip_link="tool0"/></group>'
        '<virtual_joint name="v" type="fixed" parent_frame="cell" child_link="base_link"/></robot>')
    files = ros.emit(b)
    assert list(load(files, "config/mod3_farm_kinematics.yaml")) == ["manipulator"]
    assert '"--frame-id", "cell", "--child-frame-id", "base_link"' in files["launch/mod3_farm_demo.launch.py"]
    plain = ros.emit(make_build(c))
    assert list(load(plain, "config/mod3_farm_kinematics.yaml")) == ["arm"]
    assert '"--frame-id", "world", "--child-frame-id", "base_link"' in plain["launch/mod3_farm_demo.launch.py"]


def test_kinematics_group_matches_the_real_srdf_backend():
    srdf = pytest.importorskip("modc.backends.srdf", reason="the SRDF backend is not there yet")
    for ex in EXAMPLES:
        c = check_file(ex)
        b = make_build(c)
        b.files.update(srdf.emit(b))
        files = ros.emit(b)
        for robot in b.design.robots:
            doc = ET.fromstring(b.files[f"config/{robot.file_stem}.srdf"])
            groups = {g.get("name") for g in doc.findall("group")}
            group = list(load(files, ros.robot_files(robot.file_stem)["kinematics"]))[0]
            assert group in groups, (ex.stem, group, groups)


def test_initial_positions_are_the_home_pose():
    c = checked_ok(TWO_ROBOTS, "cell.mod")
    b, files = emit(c)
    left = b.design.robots[0]
    y = load(files, "config/mod3_left_arm_initial_positions.yaml")
    assert list(y["initial_positions"]) == ["joint_1", "joint_2", "joint_3"]
    for k, q in enumerate(left.home(), start=1):
        close(y["initial_positions"][f"joint_{k}"], q, f"joint_{k}")
    assert math.isclose(y["initial_positions"]["joint_3"], math.radians(30))
    lim = load(files, "config/mod3_left_arm_joint_limits.yaml")["joint_limits"]["joint_2"]
    assert math.isclose(lim["min_position"], math.radians(-90)) and math.isclose(lim["max_position"], math.radians(45))


def test_one_package_for_a_file_with_two_robots(tmp_path):
    c = checked_ok(TWO_ROBOTS, "cell.mod")
    b, files = emit(c)
    assert [r.file_stem for r in b.design.robots] == ["mod3_left_arm", "mod3_Wrist2"]
    pkg = catkin().parse_package_string(files["package.xml"])
    assert pkg.name == "cell_modc"
    assert "left_arm = H1-L4-L1" in pkg.description and "Wrist2 = L1-L4-L1" in pkg.description
    for stem in ["mod3_left_arm", "mod3_Wrist2"]:
        for rel in ros.robot_files(stem).values():
            if rel.startswith(("urdf/mod3_left_arm.urdf", "urdf/mod3_Wrist2.urdf", "config/mod3_left_arm.s",
                               "config/mod3_Wrist2.srdf", "config/mod3_left_arm.scene")):
                continue  # other backends' files, and left_arm has no obstacles
            assert rel in files, rel
    assert "config/mod3_Wrist2.scene" in files


# ------------------------------------------------------------------------------------------------
# Planning scene


def test_scene_holds_the_obstacles(examples):
    b, files, _ = examples["farm"]
    robot = b.design.robots[0]
    text = files["config/mod3_farm.scene"]
    lines = text.splitlines()
    assert lines[0] == "mod3_farm_environment" and lines[-1] == "."
    objects = {}
    i = 1
    while lines[i] != ".":  # MoveIt's scene format: object pose, shapes (shape, size, pose, colour), subframes
        assert lines[i].startswith("* ")
        name = lines[i][2:]
        assert lines[i + 1] == "0 0 0" and lines[i + 2] == "0 0 0 1" and lines[i + 3] == "1"
        shape, size = lines[i + 4], [float(x) for x in lines[i + 5].split()]
        xyz = [float(x) for x in lines[i + 6].split()]
        quat = [float(x) for x in lines[i + 7].split()]
        assert len(lines[i + 8].split()) == 4 and lines[i + 9] == "0"
        objects[name] = (shape, size, xyz, quat)
        i += 10
    assert list(objects) == [o.name for o in robot.obstacles]
    for o in robot.obstacles:
        shape, size, xyz, quat = objects[o.name]
        assert shape == o.shape and size == pytest.approx(list(o.size)) and xyz == pytest.approx(list(o.origin.xyz))
        assert quat == pytest.approx([0, 0, 0, 1])


def test_quaternion_of_rpy():
    from modc.kinematics import rpy_matrix

    for rpy in [(0, 0, 0), (0.3, -0.2, 1.1), (math.pi, 0, 0), (0, math.pi / 2, 0), (2.5, -1.2, -3.0)]:
        x, y, z, w = ros.quaternion(rpy)
        assert math.isclose(x * x + y * y + z * z + w * w, 1.0, rel_tol=1e-12)
        R = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
             [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
             [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
        assert sum(R, []) == pytest.approx(rpy_matrix(rpy).ravel().tolist(), abs=1e-12)


# ------------------------------------------------------------------------------------------------
# Descriptions: ROS xacro and ros2_control


def _canonical(elem: ET.Element, mesh_prefix: str) -> list:
    out = []
    for e in elem.iter():
        attrs = dict(e.attrib)
        if e.tag == "mesh":
            assert attrs["filename"].startswith(mesh_prefix), attrs["filename"]
            attrs["filename"] = attrs["filename"][len(mesh_prefix):]
        out.append((e.tag, sorted(attrs.items()), (e.text or "").strip()))
    return out


def test_ros_description_is_the_urdf_with_package_meshes(examples):
    xacro = pytest.importorskip("xacro")
    for stem, (b, files, d) in examples.items():
        for robot in b.design.robots:
            f = ros.robot_files(robot.file_stem)
            plain = ET.fromstring(b.files[f["urdf"]])
            for ros2_control in ("true", "false"):
                doc = xacro.process_file(str(d / f["description"]), mappings={"ros2_control": ros2_control})
                got = ET.fromstring(doc.toxml())
                assert got.get("name") == robot.file_stem
                for tag in ("material", "link", "joint"):
                    want = [_canonical(e, "../meshes/") for e in plain.findall(tag)]
                    have = [_canonical(e, f"package://{stem}_modc/meshes/") for e in got.findall(tag)]
                    assert have == want, (stem, tag)
                assert [t.find("joint").get("name") for t in got.findall("transmission")] == \
                    [f"joint_{i}" for i in range(1, robot.dof + 1)]
                blocks = got.findall("ros2_control")
                assert len(blocks) == (1 if ros2_control == "true" else 0)
            # the ros2_control block: mock hardware, joints, interfaces, initial values = home
            rc = blocks_of(xacro, d / f["description"])
            assert rc.find("hardware/plugin").text == "mock_components/GenericSystem"
            joints = rc.findall("joint")
            assert [j.get("name") for j in joints] == [f"joint_{i}" for i in range(1, robot.dof + 1)]
            for k, j in enumerate(joints, start=1):
                cmd = j.find("command_interface")
                assert cmd.get("name") == "position"
                lo, hi = robot.joint_range(k)
                params = {p.get("name"): float(p.text) for p in cmd.findall("param")}
                assert params["min"] == pytest.approx(lo, rel=1e-11) and params["max"] == pytest.approx(hi, rel=1e-11)
                assert [s.get("name") for s in j.findall("state_interface")] == ["position", "velocity"]
                init = j.find("state_interface[@name='position']/param[@name='initial_value']")
                assert float(init.text) == pytest.approx(robot.home()[k - 1], abs=1e-12)


def blocks_of(xacro, path: Path, **mappings) -> ET.Element:
    doc = xacro.process_file(str(path), mappings={"ros2_control": "true", **mappings})
    (rc,) = ET.fromstring(doc.toxml()).findall("ros2_control")
    return rc


def test_ros2_control_plugin_and_initial_positions_are_arguments(tmp_path):
    xacro = pytest.importorskip("xacro")
    c = checked_ok(TWO_ROBOTS, "cell.mod")
    _, files = emit(c)
    d = write(files, tmp_path / "pkg")
    # the file's own home pose reaches the mock hardware's initial values
    rc = blocks_of(xacro, d / "urdf/mod3_left_arm_ros.urdf.xacro")
    init = [float(j.find("state_interface/param").text) for j in rc.findall("joint")]
    assert init == pytest.approx([math.radians(10), math.radians(-20), math.radians(30)])
    # a real hardware interface and another start pose, given on the xacro command line
    other = tmp_path / "start.yaml"
    other.write_text("initial_positions: {joint_1: 0.5, joint_2: -0.25, joint_3: 1.0}\n")
    rc = blocks_of(xacro, d / "urdf/mod3_left_arm_ros.urdf.xacro", ros2_control_plugin="kinova/KortexSystem",
                   initial_positions_file=str(other))
    assert rc.find("hardware/plugin").text == "kinova/KortexSystem"
    assert [float(j.find("state_interface/param").text) for j in rc.findall("joint")] == [0.5, -0.25, 1.0]


# ------------------------------------------------------------------------------------------------
# Launch files


class _Action:
    def __init__(self, *args, **kwargs):
        self.args, self.kwargs = args, kwargs


class _LaunchConfiguration:
    def __init__(self, name):
        self.name = name

    def perform(self, context):
        return context[self.name]


class _Builder:
    """Stand-in for moveit_configs_utils.MoveItConfigsBuilder: records the files it is given."""

    instances: list = []

    def __init__(self, robot_name, robot_description="robot_description", package_name=None):
        self.robot_name, self.package_name, self.paths = robot_name, package_name, {}
        _Builder.instances.append(self)

    def _record(self, key, file_path=None, **kwargs):
        self.paths[key] = file_path
        return self

    def robot_description(self, file_path=None, mappings=None):
        self.mappings = mappings
        return self._record("robot_description", file_path)

    def robot_description_semantic(self, file_path=None, mappings=None):
        return self._record("robot_description_semantic", file_path)

    def robot_description_kinematics(self, file_path=None):
        return self._record("robot_description_kinematics", file_path)

    def joint_limits(self, file_path=None):
        return self._record("joint_limits", file_path)

    def trajectory_execution(self, file_path=None, moveit_manage_controllers=True):
        return self._record("trajectory_execution", file_path)

    def planning_pipelines(self, default_planning_pipeline=None, pipelines=None, load_all=True):
        self.pipelines = pipelines
        return self

    def to_moveit_configs(self):
        cfg = types.SimpleNamespace(**{k: {k: v} for k, v in self.paths.items()})
        cfg.planning_pipelines = {"planning_pipelines": self.pipelines}
        cfg.to_dict = lambda: {k: v for k, v in self.paths.items()}
        return cfg


@pytest.fixture
def ros2_launch_api(monkeypatch):
    """Minimal stand-ins for launch, launch_ros, ament_index_python and moveit_configs_utils."""
    shares: dict[str, str] = {}

    def module(name, **attrs):
        m = types.ModuleType(name)
        m.__dict__.update(attrs)
        monkeypatch.setitem(sys.modules, name, m)
        return m

    def get_package_share_directory(name):
        if name not in shares:
            raise LookupError(name)
        return shares[name]

    module("launch", LaunchDescription=lambda actions: list(actions))
    module("launch.actions", DeclareLaunchArgument=_Action, OpaqueFunction=_Action, TimerAction=_Action)
    module("launch.substitutions", LaunchConfiguration=_LaunchConfiguration)
    module("launch_ros")
    module("launch_ros.actions", Node=_Action)
    module("ament_index_python")
    module("ament_index_python.packages", get_package_share_directory=get_package_share_directory)
    module("moveit_configs_utils", MoveItConfigsBuilder=_Builder)
    _Builder.instances = []
    return shares


def run_launch(path: Path, **args):
    """Exec a generated launch file, evaluate its OpaqueFunction with the given launch arguments."""
    ns: dict = {"__file__": str(path), "__name__": "launch_under_test"}
    exec(compile(path.read_text(), str(path), "exec"), ns)
    description = ns["generate_launch_description"]()
    declared = {a.args[0] if a.args else a.kwargs["name"]: a.kwargs.get("default_value")
                for a in description if "default_value" in a.kwargs}
    context = {**declared, **args}
    actions = []
    for a in description:
        if "function" in a.kwargs:
            actions += a.kwargs["function"](context)
    return declared, flatten(actions)


def flatten(actions):
    out = []
    for a in actions:
        out.append(a)
        out += flatten(a.kwargs.get("actions", []))
    return out


def nodes(actions, executable):
    return [a for a in actions if a.kwargs.get("executable") == executable]


def test_launch_files_compile(examples):
    for stem, (b, files, d) in examples.items():
        for rel in files:
            if rel.endswith(".py"):
                compile(files[rel], rel, "exec")


def test_demo_launch_starts_control_moveit_and_rviz(examples, ros2_launch_api):
    pytest.importorskip("xacro")
    for stem, (b, files, d) in examples.items():
        ros2_launch_api[f"{stem}_modc"] = str(d)
        for robot in b.design.robots:
            f = ros.robot_files(robot.file_stem)
            declared, actions = run_launch(d / f["demo_launch"])
            assert declared == {"moveit": "true", "rviz": "true", "hardware_plugin": "mock_components/GenericSystem"}
            (rsp,) = nodes(actions, "robot_state_publisher")
            description = rsp.kwargs["parameters"][0]["robot_description"]
            doc = ET.fromstring(description)
            assert doc.find("ros2_control/hardware/plugin").text == "mock_components/GenericSystem"
            meshes = [m.get("filename") for m in doc.iter("mesh")]
            assert meshes and all(m.startswith(f"package://{stem}_modc/meshes/") for m in meshes)
            (control,) = nodes(actions, "ros2_control_node")
            params = control.kwargs["parameters"]
            assert params[0]["robot_description"] == description
            assert Path(params[1]) == d / f["ros2_controllers"] and Path(params[1]).is_file()
            spawned = [n.kwargs["arguments"][0] for n in nodes(actions, "spawner")]
            assert spawned == ["joint_state_broadcaster", "arm_controller"]
            # move_group reads the package's own MoveIt files (the SRDF comes from the SRDF backend)
            builder = _Builder.instances[-1]
            assert builder.package_name == f"{stem}_modc" and builder.pipelines == ["ompl"]
            assert builder.paths == {
                "robot_description": f["description"], "robot_description_semantic": f["srdf"],
                "robot_description_kinematics": f["kinematics"], "joint_limits": f["joint_limits"],
                "trajectory_execution": f["moveit_controllers"]}
            for key, rel in builder.paths.items():
                assert key == "robot_description_semantic" or (d / rel).is_file(), rel
            assert f["srdf"] == f"config/{robot.file_stem}.srdf"  # SPEC section 5
            assert len(nodes(actions, "move_group")) == 1
            (tf,) = nodes(actions, "static_transform_publisher")  # the SRDF's virtual joint world -> base_link
            assert tf.kwargs["arguments"] == ["--frame-id", "world", "--child-frame-id", "base_link"]
            scene = nodes(actions, "moveit_publish_scene_from_text")
            assert len(scene) == (1 if robot.obstacles else 0)
            if scene:
                assert scene[0].kwargs["arguments"][0] == "--scene"
                assert Path(scene[0].kwargs["arguments"][1]).is_file()
            (rviz,) = nodes(actions, "rviz2")
            assert Path(rviz.kwargs["arguments"][1]).name == "ros2_moveit.rviz"
            assert Path(rviz.kwargs["arguments"][1]).is_file()
            # without MoveIt and RViz: control only
            _, actions = run_launch(d / f["demo_launch"], moveit="false", rviz="false",
                                    hardware_plugin="kinova/KortexSystem")
            assert not nodes(actions, "move_group") and not nodes(actions, "rviz2")
            assert not nodes(actions, "static_transform_publisher")
            (rsp,) = nodes(actions, "robot_state_publisher")
            assert "<plugin>kinova/KortexSystem</plugin>" in rsp.kwargs["parameters"][0]["robot_description"]


def test_ros2_display_launch(examples, ros2_launch_api):
    pytest.importorskip("xacro")
    b, files, d = examples["farm"]
    ros2_launch_api["farm_modc"] = str(d)
    declared, actions = run_launch(d / "launch/mod3_farm_display.launch.py")
    assert declared == {"gui": "true", "rviz": "true"}
    (rsp,) = nodes(actions, "robot_state_publisher")
    doc = ET.fromstring(rsp.kwargs["parameters"][0]["robot_description"])
    assert doc.find("ros2_control") is None and doc.find("link[@name='tool0']") is not None
    (jsp,) = nodes(actions, "joint_state_publisher_gui")
    assert jsp.kwargs["parameters"] == [{"zeros": {"joint_1": 0.0, "joint_2": 0.0, "joint_3": 0.0}}]
    (rviz,) = nodes(actions, "rviz2")
    assert Path(rviz.kwargs["arguments"][1]).is_file()
    _, actions = run_launch(d / "launch/mod3_farm_display.launch.py", gui="false", rviz="false")
    assert nodes(actions, "joint_state_publisher") and not nodes(actions, "rviz2")


def test_ros1_display_launch(examples):
    for stem, (b, files, d) in examples.items():
        for robot in b.design.robots:
            f = ros.robot_files(robot.file_stem)
            doc = ET.fromstring(files[f["display_launch_ros1"]])
            assert doc.tag == "launch"
            assert {a.get("name"): a.get("default") for a in doc.findall("arg")} == {"gui": "true", "rviz": "true"}
            param = doc.find("param[@name='robot_description']").get("command")
            m = re.fullmatch(r"\$\(find xacro\)/xacro '\$\(find (\w+)\)/(\S+)' ros2_control:=false", param)
            assert m and m.group(1) == f"{stem}_modc" and (d / m.group(2)).is_file()
            pkgs = {n.get("pkg") for n in doc.findall("node")}
            assert {"robot_state_publisher", "joint_state_publisher", "joint_state_publisher_gui", "rviz"} <= pkgs
            rviz = doc.find("node[@pkg='rviz']").get("args")
            m = re.fullmatch(r"-d \$\(find (\w+)\)/(\S+)", rviz)
            assert m and (d / m.group(2)).is_file()
            for node in doc.findall("node"):
                zeros = node.find("rosparam[@param='zeros']")
                if zeros is not None:
                    assert yaml.safe_load(zeros.text) == {f"joint_{k}": q for k, q in enumerate(robot.home(), start=1)}


def test_xml_and_rviz_files_parse(examples):
    for stem, (b, files, d) in examples.items():
        for rel, text in files.items():
            if rel.endswith((".xml", ".xacro", ".launch")):
                ET.fromstring(text)
            if rel.endswith(".rviz"):
                cfg = yaml.safe_load(text)
                assert cfg["Visualization Manager"]["Global Options"]["Fixed Frame"] == "base_link"


def test_real_number_literals():
    assert ros.real(2) == "2.0" and ros.real(0) == "0.0" and ros.real(0.05) == "0.05"
    assert ros.real(-3) == "-3.0" and ros.real(1e-5) == "1.0e-05" and ros.real(1.5e20) == "1.5e+20"
    for x in [2, 0, 0.05, 1e-5, 1.5e20, -7.25, 123456789012345]:
        v = yaml.safe_load(ros.real(x))
        assert isinstance(v, float) and math.isclose(v, x, rel_tol=1e-11)


def test_awkward_file_names_give_valid_xml():
    c = checked_ok("robot r { chain H1 - L1 }\n", "my--arm & <co>-.mod")
    _, files = emit(c)
    for rel, text in files.items():
        if rel.endswith((".xml", ".xacro", ".launch")):
            ET.fromstring(text)
    pkg = catkin().parse_package_string(files["package.xml"])
    assert pkg.name == "my_arm_co_modc"
    assert "my--arm & <co>-.mod" in ET.fromstring(files["package.xml"]).find("description").text
