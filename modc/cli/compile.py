"""`modc FILE -o OUT`: check, build every backend, write OUT atomically."""
from __future__ import annotations

import click

from .app import (
    EXIT_ERRORS,
    EXIT_USAGE,
    Verbosity,
    _err,
    _print_diagnostics,
    app,
    argument,
    library_option,
    usage_errors,
)


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
@click.option("--torque", type=click.Choice(["error", "warning", "off"]),
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
    from ..compiler import COMPILE_ANALYSES, InputError, build_cached, check_compile
    from ..outputs import check_output_dir, write_tree

    Verbosity.quiet, Verbosity.verbose = quiet, verbose
    try:  # the inputs are protected before the analyses write to modc's caches (modc.outputs)
        checked, inputs = check_compile(file, library, analyses=COMPILE_ANALYSES, torque_severity=torque or "error")
    except InputError as e:
        _print_diagnostics([e.diagnostic], {})
        raise SystemExit(EXIT_USAGE) from None
    _print_diagnostics(checked.diagnostics, checked.sources)
    if not checked.ok:
        from ..diagnostics.render import summary

        _err(f"modc: {summary(checked.diagnostics)}; nothing written to {out}")
        raise SystemExit(EXIT_ERRORS)
    with usage_errors("compile", writing=out):  # before any work: a refused OUT costs nothing
        check_output_dir(out, inputs, force)
    selected = None
    if only:
        from ..backends import load_all

        selected = [s.strip() for s in only.split(",") if s.strip()]
        unknown = [s for s in selected if s not in load_all()]
        if unknown:
            _err(f"modc: unknown backend(s) {', '.join(unknown)}; available: {', '.join(load_all())}")
            raise SystemExit(EXIT_USAGE)
    if smoke:  # before anything is written: a failed smoke test leaves OUT as it was
        from ..sim.smoke import run_sim

        ok, lines, _ = run_sim(file, library=library)
        for line in lines:
            _err(line)
        if not ok:
            _err(f"modc: smoke test failed; nothing written to {out}")
            raise SystemExit(EXIT_ERRORS)
    ros_options = _ros_options(checked, selected, ros, ros_distro, ik_solver, ros_package, command_interface,
                               package_license, maintainer)
    try:
        files = build_cached(checked, selected, collision_samples=collision_samples, seed=seed, **ros_options)
    except InputError as e:  # a backend refuses a value it cannot write (mjcf: not-finite)
        _print_diagnostics([e.diagnostic], checked.sources)
        _err(f"modc: nothing written to {out}")
        raise SystemExit(EXIT_ERRORS) from None
    with usage_errors("compile", writing=out):
        write_tree(files, out, force=force, inputs=inputs)
    if verbose:
        for rel in files:
            _err(f"  wrote {out.rstrip('/')}/{rel}")
    if not quiet:
        robots = ", ".join(f"{r.file_stem} ({r.sequence})" for r in checked.design.robots)
        _err(f"modc: {len(files)} files written to {out}: {robots or 'no robot'}")
        if checked.design.problems and not checked.design.robots:  # a design problem compiles to nothing
            _err(f"modc: {file} holds design problems, no robot: `modc design {file} -o DIR` finds arms for them")


def _ros_options(checked, selected, ros, ros_distro, ik_solver, ros_package, command_interface,
                 package_license=None, maintainer=None) -> dict:
    """Build fields of the ROS backend. The environment ($ROS_DISTRO, $ROS_VERSION) is read here
    and only here, below the command-line options (docs/ros.md)."""
    import os
    from types import SimpleNamespace

    from ..backends.ros_target import RosOptionError, distro_for, resolve

    try:
        options = {"ros_distro": distro_for(ros, ros_distro, dict(os.environ)), "ik_solver": ik_solver,
                   "ros_package": ros_package, "command_interface": command_interface,
                   "package_license": package_license, "maintainer": maintainer}
        if selected is None or "ros" in selected:
            resolve(SimpleNamespace(robots=checked.design.resolved_robots(), **options))  # what a Build holds
    except RosOptionError as e:
        _err(f"modc: {e}")
        raise SystemExit(EXIT_USAGE) from None
    return options
