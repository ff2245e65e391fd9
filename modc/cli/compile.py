"""`modc FILE -o OUT`: check, build every backend, write OUT atomically (the work is
modc.cli.compile_run's, which also reads a plain command line without click)."""
from __future__ import annotations

import click

from .app import app, argument, library_option
from .compile_run import TORQUE, run


@app.command("compile")
@argument("file", help=".mod file (or its YAML form)")
@click.option("-o", "--out", required=True, help="output directory (replaced atomically on success)")
@library_option
@click.option("--only", help="comma-separated backends to run (default: all; `modc backends`)")
@click.option("--force/--no-force", default=False,
              help="replace OUT whatever it holds (deletes files modc did not write; never an input or a "
                   "folder holding one)")
@click.option("--collision-samples", type=click.IntRange(min=0, max=1_000_000), default=10_000,
              help="random poses for the SRDF collision matrix (MoveIt's default; at most 1,000,000)")
@click.option("--seed", type=click.IntRange(min=0), default=0,
              help="seed of those poses: same file and seed, same SRDF on any machine")
@click.option("--smoke", is_flag=True, help="also run `modc sim` (PyBullet) before writing OUT")
@click.option("--torque", type=click.Choice(TORQUE),
              help="how a joint that cannot hold the arm at peak torque is reported")
# ROS package options (docs/ros.md; precedence in modc.backends.ros_target.distro_for)
@click.option("--ros", type=int,
              help="ROS package for ROS 1 (noetic) or ROS 2 (jazzy); default: $ROS_DISTRO, $ROS_VERSION, else 2")
@click.option("--ros-distro", help="target distro: noetic, humble or jazzy (overrides --ros)")
@click.option("--ik-solver", help="MoveIt IK plugin: kdl, trac_ik or pick_ik (default: the distro's)")
@click.option("--ros-package", help="ROS package name (default: <robot>_moveit_config)")
@click.option("--command-interface", help="ros2_control command interface: position (default) or effort")
@click.option("--package-license", metavar="SPDX",
              help="package.xml license, e.g. MIT (default: a TODO placeholder)")
@click.option("--maintainer", metavar="'NAME <EMAIL>'", help="package.xml maintainer (default: a TODO placeholder)")
@click.option("-q", "--quiet", is_flag=True, help="print errors only")
@click.option("-v", "--verbose", is_flag=True, help="list the files written")
def compile_cmd(
    file: str,
    out: str,
    library: str | None,
    only: str | None,
    force: bool,
    collision_samples: int,
    seed: int,
    smoke: bool,
    torque: str | None,
    ros: int | None,
    ros_distro: str | None,
    ik_solver: str | None,
    ros_package: str | None,
    command_interface: str | None,
    package_license: str | None,
    maintainer: str | None,
    quiet: bool,
    verbose: bool,
) -> None:
    """Check FILE and write URDF, meshes and a report into OUT."""
    run(file, out, library, only, force, collision_samples, seed, smoke, torque, ros, ros_distro, ik_solver,
        ros_package, command_interface, package_license, maintainer, quiet, verbose)
