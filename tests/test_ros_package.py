"""The ROS backend (modc/backends/ros.py): OUT/ is the MoveIt configuration package the MoveIt
Setup Assistant would write, for ROS 2 (jazzy, humble) or ROS 1 (noetic).

What a ROS user relies on is asserted with the real consumers installable here: catkin_pkg
parses package.xml, the PyPI xacro expands config/<robot>.urdf.xacro, urdf_parser_py reads the
ROS description; every YAML carries the library's numbers under the names MoveIt and
ros_control expect. MoveIt's own tools are in tests/test_ros_moveit.py (the builder's lookups)
and tests/test_ros1_runtime.py (roslaunch, catkin, catkin_lint).
"""
from __future__ import annotations

import math
import re
import shutil
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
import yaml
from conftest import ARM_EXAMPLES, checked_ok

from modc.backends import Build, load_all
from modc.backends import ros_target as rt
from modc.compiler import build, check_file

# catkin_pkg's condition parser uses pyparsing's pre-3.0 names
pytestmark = pytest.mark.filterwarnings("ignore:.*deprecated.*:DeprecationWarning")

load_all()

ROS2_LAYOUT = {
    ".setup_assistant", "package.xml", "CMakeLists.txt", "config/kinematics.yaml", "config/joint_limits.yaml",
    "config/pilz_cartesian_limits.yaml", "config/initial_positions.yaml", "config/moveit_controllers.yaml",
    "config/ros2_controllers.yaml", "config/moveit.rviz",
    *(f"launch/{n}.launch.py" for n in ("demo", "move_group", "moveit_rviz", "rsp", "spawn_controllers",
                                         "static_virtual_joint_tfs", "warehouse_db", "setup_assistant")),
}
ROS1_LAYOUT = {
    ".setup_assistant", "package.xml", "CMakeLists.txt", "config/kinematics.yaml", "config/joint_limits.yaml",
    "config/cartesian_limits.yaml", "config/fake_controllers.yaml", "config/simple_moveit_controllers.yaml",
    "config/ros_controllers.yaml", "config/ompl_planning.yaml", "config/sensors_3d.yaml", "launch/moveit.rviz",
    "launch/demo.launch", "launch/move_group.launch", "launch/planning_context.launch",
    "launch/planning_pipeline.launch.xml", "launch/ompl_planning_pipeline.launch.xml",
    "launch/trajectory_execution.launch.xml", "launch/fake_moveit_controller_manager.launch.xml",
    "launch/simple_moveit_controller_manager.launch.xml", "launch/sensor_manager.launch.xml",
    "launch/moveit_rviz.launch", "launch/ros_controllers.launch", "launch/setup_assistant.launch",
    "launch/warehouse.launch", "launch/warehouse_settings.launch.xml", "launch/default_warehouse_db.launch",
}


def compile_files(source: Path | str, **options) -> tuple[Build, dict]:
    c = check_file(source) if isinstance(source, Path) else checked_ok(source)
    assert c.ok
    return c, build(c, **options)


def write(files: dict, out: Path) -> Path:
    for rel, content in files.items():
        p = out / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_bytes(content) if isinstance(content, bytes) else p.write_text(content, encoding="utf-8")
    return out


@pytest.fixture(scope="module")
def packages(tmp_path_factory):
    """(example stem, distro) -> (checked, files, package directory), for every example and distro."""
    out = {}
    for ex in ARM_EXAMPLES:
        for distro in ("jazzy", "noetic"):
            c, files = compile_files(ex, ros_distro=distro)
            out[ex.stem, distro] = (c, files, write(files, tmp_path_factory.mktemp(f"{ex.stem}_{distro}")))
    return out


def ros_files(files: dict) -> set[str]:
    per_robot = (".srdf", ".scene", ".urdf.xacro", ".ros2_control.xacro", ".srdf.xacro")
    return {
        rel
        for rel in files
        if not rel.startswith(("urdf/", "meshes/", "mjcf/", "report")) and not rel.endswith(per_robot)
    }


# ------------------------------------------------------------------------------------------------
# layout and names


def test_layout_is_the_setup_assistants(packages):
    for (stem, distro), (c, files, _) in packages.items():
        robot = c.design.robots[0]
        s = robot.file_stem
        if distro == "jazzy":
            assert ros_files(files) == ROS2_LAYOUT, stem
            assert {f"config/{s}.urdf.xacro", f"config/{s}.ros2_control.xacro"} <= set(files)
        else:
            assert ros_files(files) == ROS1_LAYOUT | {f"launch/{s}_moveit_controller_manager.launch.xml",
                                                      f"launch/{s}_moveit_sensor_manager.launch.xml"}, stem
        # the documented paths (docs/outputs.md) stay where they were
        assert {f"urdf/{s}.urdf", f"config/{s}.srdf", f"urdf/{s}_ros.urdf", f"urdf/{s}.urdf.xacro"} <= set(files)
        assert (f"config/{s}.scene" in files) == bool(robot.obstacles)
        # exactly one file for MoveIt's trajectory execution among *_controllers.yaml (ROS 2)
        controllers = sorted(rel for rel in files if re.fullmatch(r"config/.*_controllers\.yaml", rel))
        assert controllers == (["config/moveit_controllers.yaml", "config/ros2_controllers.yaml"] if distro == "jazzy"
                               else ["config/fake_controllers.yaml", "config/ros_controllers.yaml",
                                     "config/simple_moveit_controllers.yaml"])


def test_package_is_named_after_the_robot_not_the_file(tmp_path):
    src = tmp_path / "cell_v2.mod"
    src.write_text("robot Farm_Arm { chain H1 - L4(port=45deg) - L1 }\n")
    c, files = compile_files(src)
    assert "<name>farm_arm_moveit_config</name>" in files["package.xml"]
    assert rt.package_name("Farm_Arm") == "farm_arm_moveit_config"
    assert rt.package_name("9lives") == "modc_9lives_moveit_config"
    assert rt.valid_package_name(rt.package_name("a__b-"))
    c, files = compile_files(src, ros_package="my_cell")  # noqa: RUF059
    assert "<name>my_cell</name>" in files["package.xml"]
    for bad in ("My-Cell", "cell__x", "1cell", "cell_"):
        with pytest.raises(rt.RosOptionError):
            build(c, ros_package=bad)


def test_output_is_deterministic():
    a = compile_files(ARM_EXAMPLES[0])[1]
    b = compile_files(ARM_EXAMPLES[0])[1]
    assert a == b


# ------------------------------------------------------------------------------------------------
# target distro, IK plugin, options


def test_distro_precedence():
    assert rt.distro_for() == "jazzy"
    assert rt.distro_for(env={"ROS_DISTRO": "humble", "ROS_VERSION": "2"}) == "humble"
    assert rt.distro_for(env={"ROS_VERSION": "1"}) == "noetic"
    assert rt.distro_for(2, env={"ROS_DISTRO": "noetic"}) == "jazzy"  # --ros beats the environment
    assert rt.distro_for(1) == "noetic"
    assert rt.distro_for(None, "Humble", env={"ROS_DISTRO": "noetic"}) == "humble"  # --ros-distro beats all
    for args in [(1, "jazzy"), (3, None), (None, "iron")]:
        with pytest.raises(rt.RosOptionError):
            rt.distro_for(*args)
    with pytest.raises(rt.RosOptionError, match="--ros-distro"):
        rt.distro_for(env={"ROS_DISTRO": "galactic"})


@pytest.mark.parametrize("distro, solver, package", [
    ("jazzy", "trac_ik", "trac_ik_kinematics_plugin"), ("humble", "kdl", "moveit_kinematics"),
    ("noetic", "kdl", "moveit_kinematics")])
def test_ik_plugin_is_released_in_the_distro(distro, solver, package):
    c, files = compile_files(ARM_EXAMPLES[0], ros_distro=distro)
    kin = yaml.safe_load(files["config/kinematics.yaml"])
    (group,) = kin.values()
    assert group["kinematics_solver"] == rt.IK_PLUGINS[solver][0]
    assert f"<exec_depend>{package}</exec_depend>" in files["package.xml"]
    # moveit_kinematics is always there (the Setup Assistant's dependency, KDL's package)
    others = {rt.IK_PLUGINS[s][1] for s in rt.IK_PLUGINS if s != solver} - {package, "moveit_kinematics"}
    assert not any(f">{p}<" in files["package.xml"] for p in others)


def test_ik_solver_option():
    c, files = compile_files(ARM_EXAMPLES[0], ros_distro="humble", ik_solver="pick_ik")
    assert yaml.safe_load(files["config/kinematics.yaml"])["arm"]["kinematics_solver"] == "pick_ik/PickIkPlugin"
    with pytest.raises(rt.RosOptionError, match="not released for ROS humble"):
        build(c, ros_distro="humble", ik_solver="trac_ik")
    with pytest.raises(rt.RosOptionError):
        build(c, ik_solver="ikfast")
    with pytest.raises(rt.RosOptionError):
        build(c, command_interface="velocity")


def test_cli_reads_the_environment_below_its_options(tmp_path, monkeypatch):
    from click.testing import CliRunner

    from modc.cli.app import app

    src = str(ARM_EXAMPLES[0])
    runner = CliRunner()
    monkeypatch.setenv("ROS_DISTRO", "noetic")
    r = runner.invoke(app, ["compile", src, "-o", str(tmp_path / "a"), "-q", "--collision-samples", "0"])
    assert r.exit_code == 0, r.output
    assert "<buildtool_depend>catkin</buildtool_depend>" in (tmp_path / "a/package.xml").read_text()
    r = runner.invoke(app, ["compile", src, "-o", str(tmp_path / "b"), "-q", "--collision-samples", "0", "--ros", "2"])
    assert r.exit_code == 0, r.output
    assert "ament_cmake" in (tmp_path / "b/package.xml").read_text()
    r = runner.invoke(app, ["compile", src, "-o", str(tmp_path / "c"), "-q", "--ros-distro", "humble",
                            "--ik-solver", "trac_ik"])
    assert r.exit_code == 2 and "not released" in r.output and not (tmp_path / "c").exists()


# ------------------------------------------------------------------------------------------------
# package.xml and CMakeLists.txt agree, for the one ROS version of the target


def test_package_xml_parses_with_catkin_pkg(packages):
    catkin = pytest.importorskip("catkin_pkg.package", reason="catkin_pkg parses package.xml")
    for (_, distro), (_, files, d) in packages.items():
        p = catkin.parse_package(str(d / "package.xml"))
        p.validate()
        build_type = "ament_cmake" if distro == "jazzy" else "catkin"
        assert [dep.name for dep in p.buildtool_depends] == [build_type]
        assert p.get_build_type() == build_type
        assert not any(dep.condition for dep in p.exec_depends), "no $ROS_VERSION conditions: one target"
        names = {dep.name for dep in p.exec_depends}
        assert {"moveit_ros_move_group", "robot_state_publisher", "xacro"} <= names
        assert ("rviz2" in names) == (distro == "jazzy") and ("rviz" in names) == (distro == "noetic")
        cmake = files["CMakeLists.txt"]
        assert f"project({p.name})" in cmake and f"find_package({build_type} REQUIRED)" in cmake
        assert "ROS_VERSION" not in cmake and ("ament" in cmake) == (distro == "jazzy")


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("cmake") is None, reason="needs cmake")
def test_cmakelists_installs_the_package_with_ament_or_catkin(packages, tmp_path):
    """Configure and install with a stand-in for ament_cmake / catkin's find_package (the real
    catkin build is in test_ros1_runtime.py; ament_cmake is not installable here)."""
    for distro in ("jazzy", "noetic"):
        c, files, d = packages["farm", distro]
        stub = tmp_path / distro / "stub"
        stub.mkdir(parents=True)
        (stub / "ament_cmakeConfig.cmake").write_text("macro(ament_package)\nendmacro()\n")
        (stub / "catkinConfig.cmake").write_text(
            "set(CATKIN_PACKAGE_SHARE_DESTINATION share/${PROJECT_NAME})\nmacro(catkin_package)\nendmacro()\n")
        build_dir, prefix = tmp_path / distro / "build", tmp_path / distro / "install"
        env = {"PATH": "/usr/bin:/bin"}
        subprocess.run(["cmake", "-S", str(d), "-B", str(build_dir), f"-DCMAKE_PREFIX_PATH={stub}",
                        f"-DCMAKE_INSTALL_PREFIX={prefix}"], check=True, capture_output=True, env=env)
        subprocess.run(["cmake", "--install", str(build_dir)], check=True, capture_output=True, env=env)
        share = prefix / "share" / rt.package_name(c.design.robots[0].name)
        for rel in files:
            if rel not in ("package.xml", "CMakeLists.txt", "report.json"):
                assert (share / rel).is_file(), f"{distro}: {rel} not installed"


# ------------------------------------------------------------------------------------------------
# the robot description for ROS


def test_ros_description_is_the_urdf_with_package_meshes_and_no_root_inertia(packages):
    urdf_parser = pytest.importorskip("urdf_parser_py.urdf", reason="urdf_parser_py reads the ROS description")
    for c, files, d in packages.values():
        for robot in c.design.robots:
            pkg = rt.package_name(c.design.robots[0].name)
            ros_urdf = urdf_parser.URDF.from_xml_string(files[f"urdf/{robot.file_stem}_ros.urdf"].encode())
            plain = urdf_parser.URDF.from_xml_string(files[f"urdf/{robot.file_stem}.urdf"].encode())
            assert ros_urdf.get_root() == "base_link" and ros_urdf.link_map["base_link"].inertial is None
            inertia = ros_urdf.link_map["base_link_inertia"].inertial
            assert inertia.mass == pytest.approx(plain.link_map["base_link"].inertial.mass, rel=1e-12)
            assert {j.name for j in ros_urdf.joints} == {j.name for j in plain.joints} | {"base_link_inertia_joint"}
            meshes = [g.geometry.filename for link in ros_urdf.links for g in link.visuals + link.collisions]
            assert meshes and all(m.startswith(f"package://{pkg}/meshes/") for m in meshes)
            for m in meshes:
                assert (d / m.removeprefix(f"package://{pkg}/")).is_file()


@pytest.mark.slow
def test_urdf_xacro_expands_to_the_robot_with_ros2_control(packages):
    xacro = pytest.importorskip("xacro")
    for (_, distro), (c, files, d) in packages.items():
        if distro != "jazzy":
            continue
        robot = c.design.robots[0]
        doc = xacro.process_file(str(d / f"config/{robot.file_stem}.urdf.xacro"))
        root = ET.fromstring(doc.toxml())
        ros_urdf = ET.fromstring(files[f"urdf/{robot.file_stem}_ros.urdf"])
        assert {e.get("name") for e in root.findall("link")} == {e.get("name") for e in ros_urdf.findall("link")}
        (control,) = root.findall("ros2_control")
        assert control.find("hardware/plugin").text == "mock_components/GenericSystem"
        home = yaml.safe_load(files["config/initial_positions.yaml"])["initial_positions"]
        assert home == {f"joint_{k}": q for k, q in enumerate(robot.home(), start=1)}
        for j in control.findall("joint"):
            assert j.find("command_interface").get("name") == "position"
            (initial,) = [p for p in j.iter("param") if p.get("name") == "initial_value"]
            assert float(initial.text) == pytest.approx(home[j.get("name")])
        # a real driver instead of the mock hardware
        doc = xacro.process_file(str(d / f"config/{robot.file_stem}.urdf.xacro"),
                                 mappings={"ros2_control_plugin": "kinova/KortexSystem"})
        assert "<plugin>kinova/KortexSystem</plugin>" in doc.toxml()


# ------------------------------------------------------------------------------------------------
# the numbers in the YAML files


def close(value, expected: float, what: str) -> None:
    assert isinstance(value, float), f"{what}: {value!r} is not a float (ROS 2 parameters are typed)"
    assert math.isclose(value, expected, rel_tol=1e-10, abs_tol=1e-12), f"{what}: {value} != {expected}"


def test_controllers_carry_the_library_gains(packages):
    for (stem, distro), (c, files, _) in packages.items():
        robot = c.design.robots[0]
        ctl = robot.library.control
        names = [f"joint_{k}" for k in range(1, robot.dof + 1)]
        if distro == "jazzy":
            cfg = yaml.safe_load(files["config/ros2_controllers.yaml"])
            cm = cfg["controller_manager"]["ros__parameters"]
            assert cm["arm_controller"]["type"] == "joint_trajectory_controller/JointTrajectoryController"
            assert cm["joint_state_broadcaster"]["type"] == "joint_state_broadcaster/JointStateBroadcaster"
            arm = cfg["arm_controller"]["ros__parameters"]
            moveit = yaml.safe_load(files["config/moveit_controllers.yaml"])
            assert moveit["moveit_simple_controller_manager"]["controller_names"] == ["arm_controller"]
            assert moveit["moveit_simple_controller_manager"]["arm_controller"]["joints"] == names
        else:
            arm = yaml.safe_load(files["config/ros_controllers.yaml"])["arm_controller"]
            assert arm["type"] == "effort_controllers/JointTrajectoryController"
            (simple,) = yaml.safe_load(files["config/simple_moveit_controllers.yaml"])["controller_list"]
            assert simple["name"] == "arm_controller" and simple["joints"] == names
            (fake,) = yaml.safe_load(files["config/fake_controllers.yaml"])["controller_list"]
            assert fake["joints"] == names
        assert arm["joints"] == names
        for n in names:
            for k in ("p", "i", "d"):
                close(arm["gains"][n][k], getattr(ctl, k), f"{stem} {n} {k}")


def test_joint_limits_match_the_library(packages):
    for c, files, _ in packages.values():
        robot = c.design.robots[0]
        lim = yaml.safe_load(files["config/joint_limits.yaml"])["joint_limits"]
        for k, unit in enumerate(robot.units, start=1):
            act = robot.library.variants[unit.variant].actuator
            lo, hi = robot.joint_range(k)
            j = lim[f"joint_{k}"]
            close(j["min_position"], lo, "min")
            close(j["max_position"], hi, "max")
            close(j["max_velocity"], act.velocity, "velocity")
            close(j["max_effort"], act.torque_peak, "effort")
            close(j["max_acceleration"], act.velocity / 0.5, "acceleration")


def test_kinematics_group_is_the_srdf_group(packages):
    for c, files, _ in packages.values():
        robot = c.design.robots[0]
        srdf = ET.fromstring(files[f"config/{robot.file_stem}.srdf"])
        chain_groups = [g.get("name") for g in srdf.findall("group") if g.find("chain") is not None]
        kin = yaml.safe_load(files["config/kinematics.yaml"])
        assert list(kin) == chain_groups[:1]
        assert kin[chain_groups[0]]["position_only_ik"] is (robot.dof < 6)


def parse_every_file(files: dict) -> None:
    """Every text output parses as what its name says: XML, YAML or Python."""
    for rel, text in files.items():
        if isinstance(text, bytes):
            continue
        if rel.endswith((".xml", ".xacro", ".launch", ".urdf", ".srdf")):
            ET.fromstring(text)
        if rel.endswith((".yaml", ".rviz")) or rel == ".setup_assistant":
            yaml.safe_load(text)
        if rel.endswith(".py"):
            compile(text, rel, "exec")


@pytest.mark.slow
def test_xml_and_yaml_files_parse(packages):
    for _, files, _ in packages.values():
        parse_every_file(files)


def test_a_file_with_two_robots_is_one_package():
    c, files = compile_files("""
robot left_arm { chain H1 - L4(port=45deg) - L1 }
robot Wrist2 { chain L1 - L4(pivot=-90deg, port=90deg) - L1
    allow first-variant
    sphere ball radius 0.05 m at (0.3, 0, 0.2) m }
""")
    assert "<name>left_arm_moveit_config</name>" in files["package.xml"]
    for stem in (r.file_stem for r in c.design.robots):
        assert {f"urdf/{stem}_ros.urdf", f"config/{stem}.urdf.xacro", f"config/{stem}.ros2_control.xacro"} <= set(files)
    assert '"mod3_left_arm"' in files["launch/demo.launch.py"]  # MoveIt's configuration: the first robot
    assert f"config/{c.design.robots[1].file_stem}.scene" in files


def test_awkward_file_names_stay_inert(tmp_path):
    """The file name reaches comments and package.xml's description only: valid XML, and nothing
    roslaunch substitutes (fake_controllers.yaml is loaded with subst_value)."""
    src = tmp_path / "a&b <c> $(env HOME) ${x} -->.mod"
    src.write_text("robot r { chain H1 - L4(port=45deg) - L1 }\n")
    for distro in ("jazzy", "noetic"):
        _, files = compile_files(src, ros_distro=distro, collision_samples=0)
        parse_every_file(files)
        if distro == "noetic":
            assert "$(env" not in files["config/fake_controllers.yaml"]
        assert ET.fromstring(files["package.xml"]).find("description").text.count("a&b <c>") == 1


def test_library_output_ignores_the_environment(monkeypatch):
    """Only the CLI reads $ROS_DISTRO / $ROS_VERSION: build() (and so the golden files) does not."""
    before = compile_files(ARM_EXAMPLES[0], collision_samples=0)[1]
    monkeypatch.setenv("ROS_DISTRO", "noetic")
    monkeypatch.setenv("ROS_VERSION", "1")
    after = compile_files(ARM_EXAMPLES[0], collision_samples=0)[1]
    assert after == before and "<buildtool_depend>ament_cmake</buildtool_depend>" in after["package.xml"]


def test_effort_command_interface():
    c, files = compile_files(ARM_EXAMPLES[0], command_interface="effort", collision_samples=0)
    robot = c.design.robots[0]
    arm = yaml.safe_load(files["config/ros2_controllers.yaml"])["arm_controller"]["ros__parameters"]
    assert arm["command_interfaces"] == ["effort"]
    control = ET.fromstring(files[f"config/{robot.file_stem}.ros2_control.xacro"])
    for k, unit in enumerate(robot.units, start=1):
        (joint,) = [j for j in control.iter("joint") if j.get("name") == f"joint_{k}"]
        ci = joint.find("command_interface")
        peak = robot.library.variants[unit.variant].actuator.torque_peak
        assert ci.get("name") == "effort"
        assert [float(p.text) for p in ci.findall("param")] == pytest.approx([-peak, peak])
    setup = yaml.safe_load(files[".setup_assistant"])["moveit_setup_assistant_config"]
    assert setup["control_xacro"]["command"] == ["effort"]
