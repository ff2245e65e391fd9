"""ROS backend: OUT/ is a MoveIt configuration package, file for file as the MoveIt Setup
Assistant of the target distro writes it (docs/outputs.md), for ROS 2 or for ROS 1.

ROS 2 (humble, jazzy; templates/ros/ros2), the layout MoveItConfigsBuilder reads by default:

    .setup_assistant                     urdf: urdf/<stem>_ros.urdf, srdf: config/<stem>.srdf
    config/<stem>.urdf.xacro             the robot + ros2_control (what robot_description loads)
    config/<stem>.ros2_control.xacro     ros2_control macro, mock_components/GenericSystem by default
    config/kinematics.yaml joint_limits.yaml pilz_cartesian_limits.yaml initial_positions.yaml
    config/moveit_controllers.yaml       MoveIt's controller list (the builder picks "moveit_")
    config/ros2_controllers.yaml         controller_manager: arm_controller, joint_state_broadcaster
    config/moveit.rviz
    launch/{demo,move_group,moveit_rviz,rsp,spawn_controllers,static_virtual_joint_tfs,
            warehouse_db,setup_assistant}.launch.py      each one call of moveit_configs_utils.launches

ROS 1 (noetic; templates/ros/ros1), MoveIt 1's Setup Assistant layout: config/ holds
kinematics, joint_limits, cartesian_limits, fake_controllers, simple_moveit_controllers,
ros_controllers (effort JointTrajectoryController with the library's PID), ompl_planning and
sensors_3d; launch/ holds demo.launch, move_group.launch and the files they include.

Both: urdf/<stem>_ros.urdf (the URDF with package:// mesh URIs and base_link's mass on a fixed
child base_link_inertia, which KDL wants; for RViz and MoveIt),
config/<stem>.scene (the file's obstacles, when it has any), package.xml and CMakeLists.txt
for the one build system of the target. config/<stem>.srdf comes from the SRDF backend.

A MoveIt configuration describes one robot: a file with several robots gets the package-wide
MoveIt files of its first robot (robot_files and the scene for every robot).

Python prepares every value as a plain string (numbers through modc.backends.format); the
templates only lay them out. Output is deterministic and does not depend on the environment.
"""
from __future__ import annotations

import math

from .._version import __version__
from ..kinematics import rpy_matrix
from ..physical.assembly import kdl_root
from ..physical.constants import ACCEL_RAMP_TIME  # the acceleration limits
from ..records import Record
from .build import Build
from .common import BASE_LINK, GROUP, urdf_context
from .format import num
from .registry import register
from .ros_target import IK_PLUGINS, PLACEHOLDER_LICENSE, PLACEHOLDER_MAINTAINER, Target, resolve
from .templates import comment, render, scene_token

# --- documented choices (docs/ros.md) -------------------------------------------------------------

PACKAGE_VERSION = "0.1.0"

# The SRDF backend's planning group and virtual joint (world -> base_link, templates/srdf.xml.j2)
VIRTUAL_JOINT_PARENT = "world"
ARM_CONTROLLER = "arm_controller"
JOINT_STATE_CONTROLLER = "joint_state_controller"  # ROS 1
JOINT_STATE_BROADCASTER = "joint_state_broadcaster"  # ROS 2

UPDATE_RATE = 100  # Hz, ros2_control controller_manager loop (MoveIt Setup Assistant's default)
JOINT_STATE_RATE = 50  # Hz, ROS 1 joint_state_controller
# JointTrajectoryController constraints. The decentralised gains are soft (p = 2), so the arm lags
# its trajectory while moving: the path tolerance is left unchecked (0) and only the goal is held
# to GOAL_TOLERANCE, reached within GOAL_TIME after the trajectory's end.
GOAL_TIME = 0.6  # s
GOAL_TOLERANCE = 0.05  # rad (about 3 degrees)
PATH_TOLERANCE = 0.0  # rad, 0 = not checked
STOPPED_VELOCITY_TOLERANCE = 0.05  # rad/s
# MoveIt's own defaults (Setup Assistant): plans run at 10 % of the limits until the user scales up.
VELOCITY_SCALING = 0.1
ACCELERATION_SCALING = 0.1
IK_TIMEOUT = 0.005  # s, per attempt (Setup Assistant's default)
IK_RESOLUTION = 0.005  # rad
MOCK_PLUGIN = "mock_components/GenericSystem"
SCENE_COLOR = "0.6 0.6 0.6 0.8"  # RGBA of obstacles in MoveIt's planning scene

# The Setup Assistant's ROS 2 launch files, each one call of moveit_configs_utils.launches
ROS2_LAUNCHES = ("demo", "move_group", "moveit_rviz", "rsp", "spawn_controllers", "static_virtual_joint_tfs",
                 "warehouse_db", "setup_assistant")


# --- names ---------------------------------------------------------------------------------------

# --- numbers -------------------------------------------------------------------------------------

def real(x: float) -> str:
    """A float literal that stays a float in YAML and in ROS 2 parameters (2 -> 2.0, 1e-05 -> 1.0e-05).

    ROS 2 parameters are typed: an integer 2 given for a double parameter (JTC gains, MoveIt
    limits) is rejected, so every real value carries a decimal point."""
    s = num(x)
    if "." in s or "n" in s:  # has a point already, or inf/nan
        return s
    if "e" in s:
        mant, exp = s.split("e")
        return f"{mant}.0e{exp}"
    return s + ".0"


def quaternion(rpy) -> tuple[float, float, float, float]:
    """(x, y, z, w) of a URDF roll-pitch-yaw, w >= 0 (deterministic sign)."""
    R = rpy_matrix(rpy)
    w = math.sqrt(max(0.0, 1.0 + R[0, 0] + R[1, 1] + R[2, 2])) / 2.0
    x = math.sqrt(max(0.0, 1.0 + R[0, 0] - R[1, 1] - R[2, 2])) / 2.0
    y = math.sqrt(max(0.0, 1.0 - R[0, 0] + R[1, 1] - R[2, 2])) / 2.0
    z = math.sqrt(max(0.0, 1.0 - R[0, 0] - R[1, 1] + R[2, 2])) / 2.0
    x = math.copysign(x, R[2, 1] - R[1, 2])
    y = math.copysign(y, R[0, 2] - R[2, 0])
    z = math.copysign(z, R[1, 0] - R[0, 1])
    return x, y, z, w


# --- per-robot data ------------------------------------------------------------------------------

class JointData(Record, kw_only=False):
    """Everything ROS needs about one actuated joint, in SI units (rad, rad/s, rad/s², N·m)."""

    name: str
    variant: str
    actuator: str
    lower: float
    upper: float
    velocity: float
    acceleration: float
    effort: float
    home: float
    p: float
    i: float
    d: float


def joints(robot) -> list[JointData]:
    lib = robot.library
    home = robot.home()
    out = []
    for k, unit in enumerate(robot.units, start=1):
        act = lib.variants[unit.variant].actuator
        lo, hi = robot.joint_range(k)
        out.append(JointData(
            name=f"joint_{k}", variant=unit.variant, actuator=act.model, lower=lo, upper=hi,
            velocity=act.velocity, acceleration=act.velocity / ACCEL_RAMP_TIME, effort=act.torque_peak,
            home=home[k - 1], p=lib.control.p, i=lib.control.i, d=lib.control.d,
        ))
    return out


def _home_origin(robot) -> str:
    """Where the initial positions come from (Robot.home), for the YAML's comment."""
    if robot.pose("home") is not None or not any(robot.default_q()):
        return "the file's `pose home` (zeros without one)"
    return ("MoveIt's default values, as the file declares no `pose home`: 0, or the middle of a joint range "
            "that excludes 0")


def _joint_ctx(j: JointData, command: str) -> dict:
    lo, hi = (j.lower, j.upper) if command == "position" else (-j.effort, j.effort)
    return {
        "command_min": real(lo), "command_max": real(hi),
        "name": j.name, "variant": j.variant, "actuator": comment(j.actuator),
        "lower": real(j.lower), "upper": real(j.upper), "velocity": real(j.velocity),
        "acceleration": real(j.acceleration), "effort": real(j.effort), "home": real(j.home),
        "p": real(j.p), "i": real(j.i), "d": real(j.d),
        "rpm": num(j.velocity * 60.0 / (2.0 * math.pi)),
    }


def _scene(robot) -> dict | None:
    if not robot.obstacles:
        return None
    objects = []
    for ob in robot.obstacles:  # file order
        objects.append({
            "name": scene_token(ob.name), "shape": ob.shape, "size": " ".join(num(s) for s in ob.size),
            "xyz": " ".join(num(v) for v in ob.origin.xyz), "quat": " ".join(num(v) for v in quaternion(ob.origin.rpy)),
        })
    return {"name": f"{robot.file_stem}_environment", "objects": objects, "color": SCENE_COLOR}


def robot_files(stem: str) -> dict[str, str]:
    """Per-robot paths, relative to the package root (templates and tests use these)."""
    return {
        "srdf": f"config/{stem}.srdf",  # written by the SRDF backend
        "urdf": f"urdf/{stem}.urdf",  # written by the URDF backend (relative mesh paths)
        "description": f"urdf/{stem}_ros.urdf",  # the same robot with package:// mesh URIs
        "urdf_xacro": f"config/{stem}.urdf.xacro",  # ROS 2: description + ros2_control
        "ros2_control": f"config/{stem}.ros2_control.xacro",
        "scene": f"config/{stem}.scene",
    }


def context(build: Build, robot, target: Target) -> dict:
    """Every value the templates place, for the package's (first) robot."""
    js = joints(robot)
    plugin, ik_package = IK_PLUGINS[target.ik_solver]
    return {
        "version": __version__,
        "source": comment(build.source_name),
        "package": target.package,
        "distro": target.distro.name,
        "ros": target.ros,
        "robot": robot.name,
        "stem": robot.file_stem,
        "sequence": robot.sequence,
        "dof": robot.dof,
        "library": comment(robot.library.name),
        "group": GROUP,
        "virtual_parent": VIRTUAL_JOINT_PARENT,
        "virtual_child": BASE_LINK,
        "controller": ARM_CONTROLLER,
        "joint_state_controller": JOINT_STATE_CONTROLLER,
        "joint_state_broadcaster": JOINT_STATE_BROADCASTER,
        "joints": [_joint_ctx(j, target.command_interface) for j in js],
        "home_origin": _home_origin(robot),
        "update_rate": str(UPDATE_RATE),
        "joint_state_rate": real(JOINT_STATE_RATE),
        "goal_time": real(GOAL_TIME),
        "goal_tolerance": real(GOAL_TOLERANCE),
        "path_tolerance": real(PATH_TOLERANCE),
        "stopped_velocity_tolerance": real(STOPPED_VELOCITY_TOLERANCE),
        "accel_ramp_time": num(ACCEL_RAMP_TIME),
        "velocity_scaling": real(VELOCITY_SCALING),
        "acceleration_scaling": real(ACCELERATION_SCALING),
        "ik": {
            "solver": target.ik_solver,
            "plugin": plugin,
            "package": ik_package,
            "others": [s for s in target.distro.ik_solvers if s != target.ik_solver],
            "timeout": real(IK_TIMEOUT),
            "resolution": real(IK_RESOLUTION),
            # a pose has 6 DoF: an arm with fewer joints can reach positions, not orientations
            "position_only": "true" if robot.dof < 6 else "false",
        },
        "command_interface": target.command_interface,
        "mock_plugin": MOCK_PLUGIN,
        "scene": _scene(robot),
        "files": robot_files(robot.file_stem),
        "package_version": PACKAGE_VERSION,
        "license": target.license,
        "maintainer": target.maintainer[0],
        "maintainer_email": target.maintainer[1],
        "placeholder_note": _placeholder_note(target),
        "robots": ", ".join(f"{r.name} = {r.sequence}" for r in build.robots),
        "depends": exec_depends(target),
        # mjcf/ when that backend is in this build (it runs before this one)
        "directories": [
            "config",
            "launch",
            "meshes",
            *(["mjcf"] if any(f.startswith("mjcf/") for f in build.files) else []),
            "urdf",
        ],
    }


def _placeholder_note(target: Target) -> str | None:
    """package.xml's comment naming what is still a placeholder and the option that sets it (an XML
    comment cannot hold the options' leading dashes)."""
    left = [(what, option) for what, option, placeholder in (
        ("license", "package-license", target.license == PLACEHOLDER_LICENSE),
        ("maintainer", "maintainer", target.maintainer == PLACEHOLDER_MAINTAINER)) if placeholder]
    if not left:
        return None
    if len(left) == 1:
        return f"TODO: the {left[0][0]} below is a placeholder; set it with the modc option {left[0][1]}"
    return ("TODO: the license and maintainer below are placeholders; "
            "set them with the modc options package-license and maintainer")


# --- package.xml: what the package runs, per ROS version (every one released in the target distro)

ROS2_DEPENDS = ("controller_manager", "hardware_interface", "joint_state_broadcaster", "joint_state_publisher",
                "joint_state_publisher_gui", "joint_trajectory_controller", "moveit_configs_utils",
                "moveit_kinematics", "moveit_planners", "moveit_ros_move_group", "moveit_ros_visualization",
                "moveit_ros_warehouse", "moveit_setup_assistant", "moveit_simple_controller_manager",
                "robot_state_publisher", "rviz2", "rviz_common", "rviz_default_plugins", "tf2_ros", "xacro")
ROS1_DEPENDS = ("controller_manager", "effort_controllers", "joint_state_controller", "joint_state_publisher",
                "joint_state_publisher_gui", "joint_trajectory_controller", "moveit_fake_controller_manager",
                "moveit_kinematics", "moveit_planners", "moveit_ros_move_group", "moveit_ros_visualization",
                "moveit_ros_warehouse", "moveit_setup_assistant", "moveit_simple_controller_manager",
                "robot_state_publisher", "rviz", "tf2_ros", "xacro")


def exec_depends(target: Target) -> list[str]:
    base = ROS2_DEPENDS if target.ros == 2 else ROS1_DEPENDS
    return sorted({*base, IK_PLUGINS[target.ik_solver][1]})


# --- the file tables ------------------------------------------------------------------------------

def ros2_files(stem: str) -> dict[str, str]:
    """Package path -> template, ROS 2 (MoveIt 2 Setup Assistant)."""
    files = {
        ".setup_assistant": "ros/ros2/setup_assistant.yaml.j2",
        "package.xml": "ros/ros2/package.xml.j2",
        "CMakeLists.txt": "ros/ros2/CMakeLists.txt.j2",
        "config/kinematics.yaml": "ros/kinematics.yaml.j2",
        "config/joint_limits.yaml": "ros/joint_limits.yaml.j2",
        "config/pilz_cartesian_limits.yaml": "ros/cartesian_limits.yaml.j2",
        "config/initial_positions.yaml": "ros/ros2/initial_positions.yaml.j2",
        "config/moveit_controllers.yaml": "ros/ros2/moveit_controllers.yaml.j2",
        "config/ros2_controllers.yaml": "ros/ros2/ros2_controllers.yaml.j2",
        "config/moveit.rviz": "ros/ros2/moveit.rviz.j2",
    }
    files.update({f"launch/{name}.launch.py": "ros/ros2/launch.py.j2" for name in ROS2_LAUNCHES})
    return files


def ros1_files(stem: str) -> dict[str, str]:
    """Package path -> template, ROS 1 (MoveIt 1 Setup Assistant)."""
    files = {
        ".setup_assistant": "ros/ros1/setup_assistant.yaml.j2",
        "package.xml": "ros/ros1/package.xml.j2",
        "CMakeLists.txt": "ros/ros1/CMakeLists.txt.j2",
        "config/kinematics.yaml": "ros/kinematics.yaml.j2",
        "config/joint_limits.yaml": "ros/joint_limits.yaml.j2",
        "config/cartesian_limits.yaml": "ros/cartesian_limits.yaml.j2",
        "config/fake_controllers.yaml": "ros/ros1/fake_controllers.yaml.j2",
        "config/simple_moveit_controllers.yaml": "ros/ros1/simple_moveit_controllers.yaml.j2",
        "config/ros_controllers.yaml": "ros/ros1/ros_controllers.yaml.j2",
        "config/ompl_planning.yaml": "ros/ros1/ompl_planning.yaml.j2",
        "config/sensors_3d.yaml": "ros/ros1/sensors_3d.yaml.j2",
        "launch/moveit.rviz": "ros/ros1/moveit.rviz.j2",
        f"launch/{stem}_moveit_controller_manager.launch.xml": "ros/ros1/robot_moveit_controller_manager.launch.xml.j2",
        f"launch/{stem}_moveit_sensor_manager.launch.xml": "ros/ros1/robot_moveit_sensor_manager.launch.xml.j2",
    }
    for name in ("demo.launch", "move_group.launch", "planning_context.launch", "planning_pipeline.launch.xml",
                 "ompl_planning_pipeline.launch.xml", "trajectory_execution.launch.xml",
                 "fake_moveit_controller_manager.launch.xml", "simple_moveit_controller_manager.launch.xml",
                 "sensor_manager.launch.xml", "moveit_rviz.launch", "ros_controllers.launch", "setup_assistant.launch",
                 "warehouse.launch", "warehouse_settings.launch.xml", "default_warehouse_db.launch"):
            files[f"launch/{name}"] = f"ros/ros1/{name}.j2"
    return files


# --- emit ----------------------------------------------------------------------------------------

def robot_outputs(build: Build, robot, target: Target) -> dict[str, str]:
    """The files every robot of the file gets."""
    ctx = context(build, robot, target)
    f = ctx["files"]
    # the URDF backend's renderer over the same physical description, with ROS mesh URIs and an
    # inertia-free root for KDL (base_link's mass on base_link_inertia)
    desc = kdl_root(build.description(robot))
    mesh_prefix = f"package://{target.package}/meshes/"
    out = {f["description"]: render("urdf.xml.j2", urdf_context(desc, robot, build.source_name, mesh_prefix))}
    if target.ros == 2:
        out[f["urdf_xacro"]] = render("ros/ros2/robot.urdf.xacro.j2", ctx)
        out[f["ros2_control"]] = render("ros/ros2/ros2_control.xacro.j2", ctx)
    if ctx["scene"] is not None:
        out[f["scene"]] = render("ros/environment.scene.j2", ctx)
    return out


def emit_package(build: Build) -> dict[str, str]:
    robots = build.robots
    if not robots:
        return {}
    target = resolve(build)
    out: dict[str, str] = {}
    for robot in robots:
        out.update(robot_outputs(build, robot, target))
    main = robots[0]
    ctx = context(build, main, target)
    table = ros2_files(main.file_stem) if target.ros == 2 else ros1_files(main.file_stem)
    for rel, template in table.items():
        name = rel.rsplit("/", 1)[-1]
        out[rel] = render(template, {**ctx, "file": name, "launch": name.split(".", 1)[0]})
    return dict(sorted(out.items()))


@register("ros", "ROS package: the MoveIt Setup Assistant's layout for ROS 2 (or ROS 1), package.xml, launch files",
          reads=("mjcf",))
def emit(build: Build):
    return emit_package(build)
