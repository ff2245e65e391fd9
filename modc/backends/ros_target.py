"""What the ROS package is generated for: the target distro, its IK plugins, and the package name.

One compile writes one package for one ROS distro, so package.xml, CMakeLists.txt and the launch
files always agree (no REP 149 conditions on $ROS_VERSION: the package never changes meaning with
the environment). The Build carries the choice (Build.ros_distro, ...); only the CLI looks at the
environment, so the library and the golden files are the same on every machine.

Distro facts (which IK plugins are released, from the rosdistro distribution files):
    noetic  ROS 1  KDL (moveit_kinematics), TRAC-IK (trac_ik_kinematics_plugin)
    humble  ROS 2  KDL, pick_ik                  TRAC-IK is not released for Humble
    jazzy   ROS 2  KDL, pick_ik, TRAC-IK
"""
from __future__ import annotations

import re

from .. import names
from ..records import Record

# name -> (MoveIt kinematics_solver plugin, the package that provides it)
IK_PLUGINS = {
    "kdl": ("kdl_kinematics_plugin/KDLKinematicsPlugin", "moveit_kinematics"),
    "trac_ik": ("trac_ik_kinematics_plugin/TRAC_IKKinematicsPlugin", "trac_ik_kinematics_plugin"),
    "pick_ik": ("pick_ik/PickIkPlugin", "pick_ik"),
}


class Distro(Record, kw_only=False):
    name: str
    ros: int  # 1 or 2
    ik_solvers: tuple[str, ...]  # released in this distro, the default first


DISTROS = {
    "noetic": Distro("noetic", 1, ("kdl", "trac_ik")),
    # KDL by default: the Setup Assistant's own default, and TRAC-IK is not released for Humble
    "humble": Distro("humble", 2, ("kdl", "pick_ik")),
    # TRAC-IK by default where it is released: the paper's solver (section 4.4)
    "jazzy": Distro("jazzy", 2, ("trac_ik", "kdl", "pick_ik")),
}
DEFAULT_DISTRO = "jazzy"  # the newest ROS 2 LTS
DEFAULT_FOR_VERSION = {1: "noetic", 2: "jazzy"}  # --ros 1|2 (or $ROS_VERSION) without a distro

COMMAND_INTERFACES = ("position", "effort")
# "position" drives mock_components/GenericSystem (which only mirrors position commands) and
# matches the Kinova actuators, which close their own PID loop on position; "effort" makes the
# ROS 2 JointTrajectoryController close the PID with the library's gains.
DEFAULT_COMMAND_INTERFACE = "position"

PACKAGE_SUFFIX = "_moveit_config"  # the Setup Assistant's own naming: <robot>_moveit_config


# The generated package is the user's: its license and maintainer are theirs to choose
# (Build.package_license, Build.maintainer; `--package-license`, `--maintainer` on the command line).
# Until they do, placeholders that say so, as `ros2 pkg create` writes them.
PLACEHOLDER_LICENSE = "TODO: License declaration"
PLACEHOLDER_MAINTAINER = ("TODO maintainer", "todo@todo.todo")
# An SPDX license expression (MIT, BSD-3-Clause, Apache-2.0 OR MIT, LicenseRef-Mine); nothing that
# could break out of the XML element or a YAML scalar.
_LICENSE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9.+\-]*( (AND|OR|WITH) [A-Za-z0-9][A-Za-z0-9.+\-]*)*$")
# "Name <email>": a name of letters (any script), digits, spaces and . , ' - ; catkin_pkg's email rule.
_MAINTAINER = re.compile(r"^(?P<name>[^\W_][\w .,'-]{0,99}) <(?P<email>[-a-zA-Z0-9_%+]+(\.[-a-zA-Z0-9_%+]+)*"
                         r"@[-a-zA-Z0-9%]+(\.[-a-zA-Z0-9%]+)*\.[a-zA-Z]{2,})>$")


class RosOptionError(ValueError):
    """An option the target cannot honour (the CLI reports it as a usage error)."""


def valid_package_name(name: str) -> bool:
    """REP 144: lowercase letters, digits and single underscores, starting with a letter."""
    return names.ros_package_problem(name) is None  # the whole string: "pkg\n" is not one


def package_name(robot_name: str) -> str:
    """The robot `Farm-Arm` -> farm_arm_moveit_config (REP 144; the file name plays no part)."""
    stem = re.sub(r"[^a-z0-9]+", "_", robot_name.lower()).strip("_")
    if not stem:
        stem = "modc"
    elif not stem[0].isalpha():
        stem = f"modc_{stem}"
    return stem + PACKAGE_SUFFIX


def package_license(text: str | None) -> str:
    """The package.xml license: an SPDX expression the user chose, else the placeholder."""
    if text is None:
        return PLACEHOLDER_LICENSE
    if len(text) > 100 or not _LICENSE.match(text):
        raise RosOptionError(f"package license {text[:100]!r} is not an SPDX license expression "
                             "(e.g. MIT, BSD-3-Clause, Apache-2.0 OR MIT)")
    return text


def maintainer(text: str | None) -> tuple[str, str]:
    """(name, email) from "Name <email>", else the placeholder."""
    if text is None:
        return PLACEHOLDER_MAINTAINER
    m = _MAINTAINER.match(text.strip())
    if not m:
        raise RosOptionError(f"maintainer {text[:100]!r} is not \"Name <email>\" (a name of letters, digits, "
                             "spaces and . , ' -, and an e-mail address)")
    return m["name"].strip(), m["email"]


def distro_for(ros_version: int | None = None, ros_distro: str | None = None,
               env: dict[str, str] | None = None) -> str:
    """The target distro. Precedence: --ros-distro, then --ros 1|2 (its LTS), then $ROS_DISTRO,
    then $ROS_VERSION, then DEFAULT_DISTRO. Raises RosOptionError for an unknown or contradictory one."""
    env = env or {}
    if ros_distro:
        name = ros_distro.strip().lower()
        if name not in DISTROS:
            raise RosOptionError(f"unknown ROS distro '{ros_distro}' (choose from {', '.join(DISTROS)})")
        if ros_version is not None and DISTROS[name].ros != ros_version:
            raise RosOptionError(f"--ros {ros_version} contradicts --ros-distro {name} (ROS {DISTROS[name].ros})")
        return name
    if ros_version is not None:
        if ros_version not in DEFAULT_FOR_VERSION:
            raise RosOptionError(f"--ros must be 1 or 2, not {ros_version}")
        return DEFAULT_FOR_VERSION[ros_version]
    if env.get("ROS_DISTRO"):
        name = env["ROS_DISTRO"].strip().lower()
        if name not in DISTROS:
            raise RosOptionError(f"$ROS_DISTRO is '{name}', which modc cannot target; "
                                 f"pass --ros-distro {'|'.join(DISTROS)}")
        return name
    if env.get("ROS_VERSION", "").strip() in ("1", "2"):
        return DEFAULT_FOR_VERSION[int(env["ROS_VERSION"])]
    return DEFAULT_DISTRO


class Target(Record, kw_only=False):
    """The resolved ROS options of one compile."""

    distro: Distro
    ik_solver: str
    command_interface: str
    package: str
    license: str = PLACEHOLDER_LICENSE
    maintainer: tuple[str, str] = PLACEHOLDER_MAINTAINER  # (name, email)

    @property
    def ros(self) -> int:
        return self.distro.ros


def resolve(build) -> Target:
    """The Build's ROS options, checked against the distro (RosOptionError when one cannot be honoured)."""
    name = build.ros_distro or DEFAULT_DISTRO
    if name not in DISTROS:
        raise RosOptionError(f"unknown ROS distro '{name}' (choose from {', '.join(DISTROS)})")
    distro = DISTROS[name]
    solver = build.ik_solver or distro.ik_solvers[0]
    if solver not in distro.ik_solvers:
        known = "" if solver in IK_PLUGINS else f" (modc knows {', '.join(IK_PLUGINS)})"
        raise RosOptionError(f"IK solver '{solver}' is not released for ROS {name}{known}; "
                             f"choose from {', '.join(distro.ik_solvers)}")
    iface = build.command_interface or DEFAULT_COMMAND_INTERFACE
    if iface not in COMMAND_INTERFACES:
        raise RosOptionError(f"unknown ros2_control command interface '{iface}' "
                             f"(choose from {', '.join(COMMAND_INTERFACES)})")
    robots = build.robots
    package = build.ros_package or package_name(robots[0].name if robots else "modc")
    if not valid_package_name(package):
        raise RosOptionError(f"'{names.shown(package, 80)}' is not a valid ROS package name "
                             "(lowercase letters, digits and single underscores, starting with a letter)")
    return Target(distro, solver, iface, package, package_license(build.package_license), maintainer(build.maintainer))
