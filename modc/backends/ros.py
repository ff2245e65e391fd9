"""ROS backend: OUT/ becomes one buildable ROS package per input file (SPEC section 5).

What a ROS user gets for every robot (stem = mod<n>_<name>):

    config/<stem>_ros_controllers.yaml          ROS 1 ros_control: effort JointTrajectoryController + JointStateController
    config/<stem>_ros2_controllers.yaml         ROS 2 ros2_control: controller_manager, JointTrajectoryController, JointStateBroadcaster
    config/<stem>_moveit_controllers.yaml       MoveIt 2: moveit_simple_controller_manager -> arm_controller
    config/<stem>_simple_moveit_controllers.yaml  MoveIt 1: controller_list -> arm_controller
    config/<stem>_kinematics.yaml               IK solver of the planning group (TRAC-IK; KDL as the documented fallback)
    config/<stem>_joint_limits.yaml             MoveIt joint limits (position, velocity, acceleration, effort)
    config/<stem>_initial_positions.yaml        home pose, read by the ros2_control xacro
    config/<stem>.scene                         MoveIt planning scene of the file's obstacles (only if there are any)
    urdf/<stem>_ros.urdf.xacro                  the robot for ROS: package:// mesh URIs, transmissions, ros2_control
    urdf/<stem>.ros2_control.xacro              ros2_control macro (mock_components/GenericSystem by default)
    launch/<stem>_demo.launch.py                ROS 2: robot_state_publisher, ros2_control_node, spawners, move_group, RViz
    launch/<stem>_display.launch.py             ROS 2: robot_state_publisher + joint_state_publisher_gui + RViz
    launch/<stem>_display.launch                ROS 1: the same with roslaunch

and once per package: package.xml (format 3), CMakeLists.txt and RViz configurations. The
package builds with ament_cmake under ROS 2 and with catkin under ROS 1 (REP 149 conditions on
$ROS_VERSION), so one generated tree serves both.

Options, read from the Build when present (the CLI may set them), else the defaults:
    build.ros_package             package name (default: the input file's stem + "_modc", see package_name)
    build.ik_solver               "trac_ik" (default, the paper's) or "kdl"
    build.ros2_command_interface  "position" (default: mock hardware, Kinova position mode) or "effort"
An invalid option raises ValueError (validate at the CLI first: valid_package_name, IK_SOLVERS,
COMMAND_INTERFACES).

If the SRDF backend ran first, its arm group (kinematics.yaml) and virtual joint frame (the demo's
static transform) are used; otherwise its conventions, "arm" and "world".

Python prepares every value as a string (numbers through modc.backends.format); the templates in
templates/ros/ only lay them out. Output is deterministic.
"""
from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

from markupsafe import Markup

from .. import __version__
from ..kinematics import rpy_matrix
from . import Build, register
from .format import num
from .templates import comment, render, scene_token, text_line
from .urdf import urdf_text

# --- documented choices (README: "ROS package") -------------------------------------------------

PACKAGE_VERSION = "0.1.0"
PACKAGE_LICENSE = "BSD-3-Clause"  # what MoveIt Setup Assistant writes; the generated package is the user's
MAINTAINER = ("modc user", "user@example.com")  # placeholder: edit package.xml before releasing

DEFAULT_GROUP = "arm"  # planning group name when no SRDF names one (the SRDF backend's name)
DEFAULT_WORLD_FRAME = "world"  # parent of the SRDF's virtual joint when no SRDF says otherwise
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
# Acceleration limits: neither the paper nor Kinova's table gives one. We allow each actuator to
# reach its rated speed in ACCEL_RAMP_TIME, i.e. max_acceleration = max_velocity / 0.5 s.
ACCEL_RAMP_TIME = 0.5  # s
# MoveIt's own defaults (Setup Assistant): plans run at 10 % of the limits until the user scales up.
VELOCITY_SCALING = 0.1
ACCELERATION_SCALING = 0.1

IK_SOLVERS = {
    "trac_ik": ("trac_ik_kinematics_plugin/TRAC_IKKinematicsPlugin", "trac_ik_kinematics_plugin"),
    "kdl": ("kdl_kinematics_plugin/KDLKinematicsPlugin", "moveit_kinematics"),
}
DEFAULT_IK_SOLVER = "trac_ik"  # the paper's choice (section 4.4, TRAC-IK)
IK_TIMEOUT = 0.005  # s, per attempt (Setup Assistant's default)
IK_RESOLUTION = 0.005  # rad
# ros2_control command interface: "position" drives mock_components/GenericSystem (which only
# mirrors position commands) and matches the Kinova actuators, which close their own PID loop
# on position; "effort" makes the ROS 2 JointTrajectoryController close the PID with the gains.
COMMAND_INTERFACES = ("position", "effort")
DEFAULT_COMMAND_INTERFACE = "position"
MOCK_PLUGIN = "mock_components/GenericSystem"

SCENE_COLOR = "0.6 0.6 0.6 0.8"  # RGBA of obstacles in MoveIt's planning scene

PACKAGE_NAME = re.compile(r"^[a-z][a-z0-9_]*$")


# --- names ---------------------------------------------------------------------------------------

def valid_package_name(name: str) -> bool:
    """REP 144: lowercase letters, digits and single underscores, starting with a letter."""
    return bool(PACKAGE_NAME.match(name)) and "__" not in name and not name.endswith("_")


def package_name(source_name: str) -> str:
    """farm.mod -> farm_modc: the input file's stem, sanitised to a REP 144 name, plus _modc."""
    stem = re.sub(r"[^a-z0-9]+", "_", Path(source_name).stem.lower()).strip("_")
    if not stem:
        return "modc"
    return f"{stem}_modc" if stem[0].isalpha() else f"modc_{stem}"


def ik_solver(build: Build) -> str:
    name = getattr(build, "ik_solver", None) or DEFAULT_IK_SOLVER
    if name not in IK_SOLVERS:
        raise ValueError(f"unknown IK solver '{name}' (choose from {', '.join(sorted(IK_SOLVERS))})")
    return name


def command_interface(build: Build) -> str:
    name = getattr(build, "ros2_command_interface", None) or DEFAULT_COMMAND_INTERFACE
    if name not in COMMAND_INTERFACES:
        raise ValueError(f"unknown ros2_control command interface '{name}' (choose from {', '.join(COMMAND_INTERFACES)})")
    return name


def ros_package(build: Build) -> str:
    name = getattr(build, "ros_package", None) or package_name(build.source_name)
    if not valid_package_name(name):
        raise ValueError(f"'{name}' is not a valid ROS package name (lowercase letters, digits, single underscores)")
    return name


def _srdf(build: Build, robot) -> ET.Element | None:
    """The SRDF backend's output for this robot, if it ran before this backend."""
    text = build.files.get(f"config/{robot.file_stem}.srdf")
    if isinstance(text, bytes):
        text = text.decode("utf-8")
    if not text:
        return None
    try:
        return ET.fromstring(text)
    except ET.ParseError:
        return None


def planning_group(build: Build, robot) -> str:
    """The SRDF's arm group (the first group with a chain), else DEFAULT_GROUP."""
    srdf = _srdf(build, robot)
    groups = [] if srdf is None else [g for g in srdf.findall("group") if g.get("name")]
    chains = [g for g in groups if g.find("chain") is not None]
    return (chains or groups)[0].get("name") if groups else DEFAULT_GROUP


def world_frame(build: Build, robot) -> str:
    """The parent frame of the SRDF's virtual joint (MoveIt's planning frame), else "world"."""
    srdf = _srdf(build, robot)
    vj = None if srdf is None else srdf.find("virtual_joint")
    return vj.get("parent_frame") if vj is not None and vj.get("parent_frame") else DEFAULT_WORLD_FRAME


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

@dataclass(frozen=True)
class JointData:
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


def robot_context(build: Build, robot, package: str) -> dict:
    solver = ik_solver(build)
    (alternative,) = (n for n in sorted(IK_SOLVERS) if n != solver)
    iface = command_interface(build)
    js = joints(robot)
    stem = robot.file_stem
    return {
        "version": __version__, "source": comment(build.source_name),
        "source_comment": comment(build.source_name), "package": package,
        "robot": robot.name, "stem": stem, "sequence": robot.sequence, "dof": robot.dof,
        "library": comment(robot.library.name), "group": planning_group(build, robot),
        "world_frame": world_frame(build, robot),
        "controller": ARM_CONTROLLER, "joint_state_controller": JOINT_STATE_CONTROLLER,
        "joint_state_broadcaster": JOINT_STATE_BROADCASTER,
        "joints": [_joint_ctx(j, iface) for j in js],
        "home_flow": "{" + ", ".join(f"{j.name}: {real(j.home)}" for j in js) + "}",
        "home_origin": _home_origin(robot),
        "update_rate": str(UPDATE_RATE), "joint_state_rate": real(JOINT_STATE_RATE),
        "goal_time": real(GOAL_TIME), "goal_tolerance": real(GOAL_TOLERANCE),
        "path_tolerance": real(PATH_TOLERANCE), "stopped_velocity_tolerance": real(STOPPED_VELOCITY_TOLERANCE),
        "accel_ramp_time": num(ACCEL_RAMP_TIME),
        "velocity_scaling": real(VELOCITY_SCALING), "acceleration_scaling": real(ACCELERATION_SCALING),
        "ik": {
            "solver": solver, "plugin": IK_SOLVERS[solver][0],
            "alternative": alternative, "alternative_plugin": IK_SOLVERS[alternative][0],
            "timeout": real(IK_TIMEOUT), "resolution": real(IK_RESOLUTION),
            # a pose has 6 DoF: an arm with fewer joints can reach positions, not orientations
            "position_only": "true" if robot.dof < 6 else "false",
        },
        "command_interface": iface, "mock_plugin": MOCK_PLUGIN,
        "scene": _scene(robot),
        "files": robot_files(stem),
    }


def robot_files(stem: str) -> dict[str, str]:
    """Every per-robot path, relative to the package root (templates and tests use these)."""
    return {
        "ros_controllers": f"config/{stem}_ros_controllers.yaml",
        "ros2_controllers": f"config/{stem}_ros2_controllers.yaml",
        "moveit_controllers": f"config/{stem}_moveit_controllers.yaml",
        "simple_moveit_controllers": f"config/{stem}_simple_moveit_controllers.yaml",
        "kinematics": f"config/{stem}_kinematics.yaml",
        "joint_limits": f"config/{stem}_joint_limits.yaml",
        "initial_positions": f"config/{stem}_initial_positions.yaml",
        "scene": f"config/{stem}.scene",
        "srdf": f"config/{stem}.srdf",  # written by the SRDF backend
        "urdf": f"urdf/{stem}.urdf",  # written by the URDF backend
        "description": f"urdf/{stem}_ros.urdf.xacro",
        "ros2_control": f"urdf/{stem}.ros2_control.xacro",
        "demo_launch": f"launch/{stem}_demo.launch.py",
        "display_launch_ros2": f"launch/{stem}_display.launch.py",
        "display_launch_ros1": f"launch/{stem}_display.launch",
    }


PACKAGE_FILES = {
    "package": "package.xml",
    "cmake": "CMakeLists.txt",
    "rviz2_display": "config/ros2_display.rviz",
    "rviz2_moveit": "config/ros2_moveit.rviz",
    "rviz1_display": "config/ros1_display.rviz",
}


def _urdf_body(text: str) -> str:
    """The children of <robot> in a URDF document, as text (the ROS xacro wraps them)."""
    start = text.index(">", text.index("<robot ")) + 1
    end = text.rindex("</robot>")
    return text[start:end].strip("\n")


# --- package-level files -------------------------------------------------------------------------

# (package, condition) pairs; condition None = both ROS versions.
def exec_depends(solvers: set[str]) -> list[dict]:
    both = ["controller_manager", "joint_state_publisher", "joint_state_publisher_gui", "joint_trajectory_controller",
            "moveit_simple_controller_manager", "robot_state_publisher", "xacro"]
    both += [IK_SOLVERS[s][1] for s in sorted(solvers)]
    ros1 = ["effort_controllers", "joint_state_controller", "rviz"]
    ros2 = ["ament_index_python", "hardware_interface", "joint_state_broadcaster", "launch", "launch_ros",
            "moveit_configs_utils", "moveit_planners_ompl", "moveit_ros_move_group", "moveit_ros_planning",
            "moveit_ros_visualization", "rviz2", "tf2_ros"]
    out = [{"name": n, "condition": None} for n in sorted(set(both))]
    out += [{"name": n, "condition": "$ROS_VERSION == 1"} for n in sorted(set(ros1))]
    out += [{"name": n, "condition": "$ROS_VERSION == 2"} for n in sorted(set(ros2))]
    return out


def package_context(build: Build, package: str) -> dict:
    robots = build.design.robots
    summary = ", ".join(f"{r.name} = {r.sequence}" for r in robots)
    return {
        "version": __version__, "source": comment(build.source_name),
        "source_comment": comment(build.source_name), "package": package,
        "package_version": PACKAGE_VERSION, "license": PACKAGE_LICENSE,
        "maintainer": MAINTAINER[0], "maintainer_email": MAINTAINER[1],
        "description": text_line(f"URDF, ros_control / ros2_control and MoveIt configuration of {build.source_name} "
                                 f"({summary}), MOIRs Mark-2 modules, generated by modc {__version__}."),
        "depends": exec_depends({ik_solver(build)}),
        "robots": [{"name": r.name, "stem": r.file_stem, "files": robot_files(r.file_stem)} for r in robots],
        "directories": ["config", "launch", "meshes", "urdf"],
    }


# --- emit ----------------------------------------------------------------------------------------

def robot_outputs(build: Build, robot, package: str) -> dict[str, str]:
    ctx = robot_context(build, robot, package)
    f = ctx["files"]
    out = {
        f["ros_controllers"]: render("ros/ros_controllers.yaml.j2", ctx),
        f["ros2_controllers"]: render("ros/ros2_controllers.yaml.j2", ctx),
        f["moveit_controllers"]: render("ros/moveit_controllers.yaml.j2", ctx),
        f["simple_moveit_controllers"]: render("ros/simple_moveit_controllers.yaml.j2", ctx),
        f["kinematics"]: render("ros/kinematics.yaml.j2", ctx),
        f["joint_limits"]: render("ros/joint_limits.yaml.j2", ctx),
        f["initial_positions"]: render("ros/initial_positions.yaml.j2", ctx),
        f["ros2_control"]: render("ros/ros2_control.xacro.j2", ctx),
        f["description"]: render("ros/description.urdf.xacro.j2", {
            **ctx, "body": Markup(_urdf_body(urdf_text(build, robot, mesh_prefix=f"package://{package}/meshes/")))}),
        f["demo_launch"]: render("ros/demo.launch.py.j2", ctx),
        f["display_launch_ros2"]: render("ros/display.launch.py.j2", ctx),
        f["display_launch_ros1"]: render("ros/display.launch.j2", ctx),
    }
    if ctx["scene"] is not None:
        out[f["scene"]] = render("ros/environment.scene.j2", ctx)
    return out


def emit_package(build: Build) -> dict[str, str]:
    package = ros_package(build)
    out: dict[str, str] = {}
    for robot in build.design.robots:
        out.update(robot_outputs(build, robot, package))
    pctx = package_context(build, package)
    out[PACKAGE_FILES["package"]] = render("ros/package.xml.j2", pctx)
    out[PACKAGE_FILES["cmake"]] = render("ros/CMakeLists.txt.j2", pctx)
    out[PACKAGE_FILES["rviz2_display"]] = render("ros/ros2_display.rviz.j2", pctx)
    out[PACKAGE_FILES["rviz2_moveit"]] = render("ros/ros2_moveit.rviz.j2", pctx)
    out[PACKAGE_FILES["rviz1_display"]] = render("ros/ros1_display.rviz.j2", pctx)
    return dict(sorted(out.items()))


@register("ros", "ROS package: package.xml, CMakeLists.txt, controllers (ROS 1/2), MoveIt config, launch files")
def emit(build: Build):
    return emit_package(build)
