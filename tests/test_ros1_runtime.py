"""The ROS 1 package (--ros 1, noetic) in Debian's real ROS 1 tools.

Debian packages ROS 1 (apt: ros-core python3-roslaunch ros-robot-state-publisher catkin
catkin-lint colcon python3-colcon-ros); every test skips, saying why, where the machine lacks
them. The tools run with the system Python (/usr/bin), whatever the test's interpreter.

- roslaunch --nodes / --dump-params resolve MoveIt 1's demo.launch, move_group.launch (the
  arm's controllers or the fake ones) and the controller bring-up: every include, $(find),
  rosparam file and argument of the package;
- catkin_make install and colcon build (colcon-ros) build and install it, catkin_lint finds
  nothing to report; colcon sees the ROS 2 package as ament_cmake;
- robot_state_publisher (KDL) loads the ROS description without the root-inertia warning that
  the plain URDF, whose base_link carries the base's mass, gives.
"""
from __future__ import annotations

import os
import shutil
import socket
import subprocess
import time
from pathlib import Path

import pytest
import yaml
from conftest import EXAMPLES

from modc.compiler import build, check_file

SYSTEM_PATH = "/usr/bin:/bin"
RSP = Path("/usr/lib/robot_state_publisher/robot_state_publisher")
KDL_WARNING = "root link base_link has an inertia"


def tool(name: str) -> str:
    exe = shutil.which(name, path=SYSTEM_PATH)
    if exe is None:
        pytest.skip(f"{name} is not installed (apt: ros-core python3-roslaunch catkin catkin-lint)")
    return exe


@pytest.fixture(scope="module")
def workspace(tmp_path_factory):
    """A catkin workspace with the farm arm (obstacles) and Example B (6 joints) for noetic."""
    ws = tmp_path_factory.mktemp("ros1_ws")
    pkgs = {}
    for stem in ("farm", "example_b"):
        (ex,) = [e for e in EXAMPLES if e.stem == stem]
        c = check_file(ex)
        files = build(c, ros_distro="noetic", collision_samples=0)
        robot = c.design.robots[0]
        pkg = f"{robot.name}_moveit_config"
        d = ws / "src" / pkg
        for rel, content in files.items():
            p = d / rel
            p.parent.mkdir(parents=True, exist_ok=True)
            p.write_bytes(content) if isinstance(content, bytes) else p.write_text(content, encoding="utf-8")
        pkgs[stem] = (robot, pkg, d)
    env = {"PATH": SYSTEM_PATH, "HOME": str(ws), "ROS_HOME": str(ws / ".ros"), "ROS_PACKAGE_PATH": str(ws / "src"),
           "LANG": "C.UTF-8"}
    return ws, pkgs, env


def run(cmd: list[str], env: dict, **kwargs) -> subprocess.CompletedProcess:
    return subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=240, check=False, **kwargs)


@pytest.mark.slow
def test_roslaunch_resolves_the_moveit1_demo(workspace):
    roslaunch = tool("roslaunch")
    _, pkgs, env = workspace
    for robot, pkg, d in pkgs.values():
        r = run([roslaunch, "--nodes", pkg, "demo.launch"], env)
        assert r.returncode == 0, r.stderr
        nodes = {n.rsplit("/", 1)[-1].split("_vm_")[0] for n in r.stdout.split()}
        assert {"virtual_joint_broadcaster_0", "joint_state_publisher", "robot_state_publisher", "move_group"} <= nodes
        assert any(n.startswith("rviz") for n in nodes)
        r = run([roslaunch, "--dump-params", pkg, "demo.launch"], env)
        assert r.returncode == 0, r.stderr
        params = yaml.safe_load(r.stdout)
        assert params["/robot_description"] == (d / f"urdf/{robot.file_stem}_ros.urdf").read_text()
        assert params["/robot_description_semantic"] == (d / f"config/{robot.file_stem}.srdf").read_text()
        kdl = "kdl_kinematics_plugin/KDLKinematicsPlugin"
        assert params["/robot_description_kinematics/arm/kinematics_solver"] == kdl
        assert params["/robot_description_planning/joint_limits/joint_1/has_velocity_limits"] is True
        fake_manager = "moveit_fake_controller_manager/MoveItFakeControllerManager"
        assert params["/move_group/moveit_controller_manager"] == fake_manager
        (fake,) = params["/move_group/controller_list"]
        assert fake["type"] == "interpolate" and fake["joints"] == [f"joint_{k}" for k in range(1, robot.dof + 1)]
        assert params["/move_group/initial"] == [{"group": "arm", "pose": "home"}]
        assert params["/move_group/planning_pipelines/ompl/planning_plugin"] == "ompl_interface/OMPLPlanner"
        assert params["/move_group/planning_pipelines/ompl/arm/default_planner_config"] == "RRTConnectkConfigDefault"


@pytest.mark.slow
def test_roslaunch_move_group_with_the_arm_controllers(workspace):
    roslaunch = tool("roslaunch")
    _, pkgs, env = workspace
    _, pkg, _ = pkgs["farm"]
    r = run([roslaunch, "--dump-params", pkg, "move_group.launch"], env)
    assert r.returncode == 0, r.stderr
    params = yaml.safe_load(r.stdout)
    assert params["/move_group/moveit_controller_manager"] == \
        "moveit_simple_controller_manager/MoveItSimpleControllerManager"
    (arm,) = params["/move_group/controller_list"]
    assert arm["name"] == "arm_controller" and arm["type"] == "FollowJointTrajectory"
    # controller bring-up: the same controller in ros_control, with the library's gains
    r = run([roslaunch, "--dump-params", pkg, "ros_controllers.launch"], env)
    assert r.returncode == 0, r.stderr
    params = yaml.safe_load(r.stdout)
    assert params["/arm_controller/type"] == "effort_controllers/JointTrajectoryController"
    assert [params[f"/arm_controller/gains/joint_1/{k}"] for k in "pid"] == [2.0, 0.0, 0.05]
    assert params["/joint_state_controller/type"] == "joint_state_controller/JointStateController"
    r = run([roslaunch, "--nodes", pkg, "ros_controllers.launch"], env)
    assert r.stdout.split() == ["/controller_spawner"]
    for launch in ("setup_assistant.launch", "default_warehouse_db.launch", "moveit_rviz.launch"):
        r = run([roslaunch, "--nodes", pkg, launch], env)
        assert r.returncode == 0 and r.stdout.strip(), (launch, r.stderr)


@pytest.mark.slow
def test_catkin_lint_and_catkin_make_install(workspace):
    lint = tool("catkin_lint")
    ws, pkgs, env = workspace
    r = run([lint, "--strict", "-W2", str(ws / "src")], env)
    assert r.returncode == 0, r.stdout + r.stderr
    catkin_make = tool("catkin_make")
    r = run([catkin_make, "install"], env, cwd=ws)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    for robot, pkg, _ in pkgs.values():
        share = ws / "install" / "share" / pkg
        for rel in (".setup_assistant", "launch/demo.launch", "config/kinematics.yaml",
                    f"urdf/{robot.file_stem}_ros.urdf", f"config/{robot.file_stem}.srdf", "meshes"):
            assert (share / rel).exists(), rel


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def publishes(master_uri: str, topic: str, node: str, proc: subprocess.Popen) -> bool:
    """Whether the ROS master lists node as a publisher of topic (while proc, the node, still runs)."""
    import xmlrpc.client

    assert proc.poll() is None, "the publisher has ended"
    _, _, (pubs, _, _) = xmlrpc.client.ServerProxy(master_uri).getSystemState("/modc_test")
    return any(t == topic and node in nodes for t, nodes in pubs)


@pytest.mark.slow
def test_robot_state_publisher_has_no_root_inertia_warning(workspace, tmp_path):
    if not RSP.is_file():
        pytest.skip("robot_state_publisher is not installed (apt: ros-robot-state-publisher)")
    rosmaster, rosparam = tool("rosmaster"), tool("rosparam")
    _, pkgs, env = workspace
    port = free_port()
    master_uri = f"http://127.0.0.1:{port}"
    env = {**env, "ROS_MASTER_URI": master_uri}
    master = subprocess.Popen([rosmaster, "--core", "-p", str(port)], env=env, stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL)
    try:
        robot, _, d = pkgs["example_b"]
        stderr = {}
        for which in ("_ros.urdf", ".urdf"):
            urdf = d / f"urdf/{robot.file_stem}{which}"
            deadline = time.monotonic() + 240  # a guard against a master that never comes up
            while run([rosparam, "set", "/robot_description", "-t", str(urdf)], env).returncode != 0:
                assert time.monotonic() < deadline, "rosmaster did not come up"
                time.sleep(0.1)  # the master needs a moment
            log = tmp_path / f"rsp{which}.log"
            with open(log, "w") as f:
                node = f"rsp_{len(stderr)}"  # its own name: the master may still list the previous one
                rsp = subprocess.Popen([str(RSP), f"__name:={node}"], stdout=f, stderr=subprocess.STDOUT, env=env)
            try:
                # it runs until stopped: wait for the event that it has built the KDL tree (it advertises
                # /tf_static only after the tree is built and the warning printed), not for a time
                while not publishes(master_uri, "/tf_static", f"/{node}", rsp):
                    assert time.monotonic() < deadline, "robot_state_publisher never advertised /tf_static"
                    time.sleep(0.1)
            finally:
                rsp.terminate()
                rsp.wait(timeout=60)
            stderr[which] = log.read_text()
        assert KDL_WARNING not in stderr["_ros.urdf"], stderr["_ros.urdf"]
        assert KDL_WARNING in stderr[".urdf"], "the check would not see the warning"
    finally:
        master.terminate()
        master.wait(timeout=60)


@pytest.mark.skipif(os.name != "posix", reason="POSIX only")
def test_no_ros2_file_in_a_ros1_package(workspace):
    for _, _, d in workspace[1].values():
        assert not list(d.rglob("*.launch.py")) and not (d / "config/ros2_controllers.yaml").exists()


@pytest.mark.slow
def test_colcon_builds_the_ros1_package_and_sees_the_ros2_one_as_ament_cmake(workspace, tmp_path):
    """colcon (Debian, with colcon-ros) builds the catkin package; for ROS 2 it identifies the
    package's build type (building it needs ament_cmake, which is not installable here)."""
    colcon = tool("colcon")
    _, pkgs, env = workspace
    _, pkg, d = pkgs["farm"]
    src = tmp_path / "ws" / "src"
    shutil.copytree(d, src / pkg)
    r = run([colcon, "list"], env, cwd=src.parent)
    if "ros.catkin" not in r.stdout:
        pytest.skip(f"colcon has no ROS package support (apt: python3-colcon-ros): {r.stdout} {r.stderr}")
    assert r.stdout.split() == [pkg, f"src/{pkg}", "(ros.catkin)"]
    r = run([colcon, "build", "--merge-install"], env, cwd=src.parent)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    assert (src.parent / "install/share" / pkg / "launch/demo.launch").is_file()
    ros2 = tmp_path / "ws2" / "src" / pkg
    files = build(check_file(EXAMPLES[0]), collision_samples=0)  # jazzy
    for rel, content in files.items():
        p = ros2 / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_bytes(content) if isinstance(content, bytes) else p.write_text(content, encoding="utf-8")
    r = run([colcon, "list"], env, cwd=ros2.parent.parent)
    assert r.stdout.split()[-1] == "(ros.ament_cmake)"
