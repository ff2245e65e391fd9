"""`modc FILE -o OUT`: check, build every backend, write OUT atomically."""
from __future__ import annotations

from typing import Annotated

import typer

from .app import (
    EXIT_ERRORS,
    EXIT_USAGE,
    LibraryOpt,
    TorqueLevel,
    Verbosity,
    _err,
    _print_diagnostics,
    app,
    usage_errors,
)

OnlyOpt = Annotated[str | None, typer.Option(help="comma-separated backends to run (default: all; `modc backends`)")]
SamplesOpt = Annotated[int, typer.Option(min=0, help="random poses for the SRDF collision matrix (MoveIt's default)")]
SeedOpt = Annotated[int, typer.Option(min=0, help="seed of those poses: same file and seed, same SRDF on any machine")]
TorqueOpt = Annotated[TorqueLevel | None,
                      typer.Option(help="how a joint that cannot hold the arm at peak torque is reported")]
# ROS package options (README "Use in ROS 2 / ROS 1"; precedence in modc.backends.ros_target.distro_for)
RosOpt = Annotated[int | None, typer.Option(
    "--ros", help="ROS package for ROS 1 (noetic) or ROS 2 (jazzy); default: $ROS_DISTRO, $ROS_VERSION, else 2")]
DistroOpt = Annotated[str | None, typer.Option(help="target distro: noetic, humble or jazzy (overrides --ros)")]
IkOpt = Annotated[str | None, typer.Option(help="MoveIt IK plugin: kdl, trac_ik or pick_ik (default: the distro's)")]
PackageOpt = Annotated[str | None, typer.Option(help="ROS package name (default: <robot>_moveit_config)")]
InterfaceOpt = Annotated[str | None, typer.Option(help="ros2_control command interface: position (default) or effort")]


@app.command("compile")
def compile_cmd(
    file: Annotated[str, typer.Argument(help=".mod file (or its YAML form)")],
    out: Annotated[str, typer.Option("-o", "--out", help="output directory (replaced atomically on success)")],
    library: LibraryOpt = None,
    only: OnlyOpt = None,
    force: Annotated[
        bool, typer.Option(help="replace OUT whatever it holds (deletes files modc did not write)")
    ] = False,
    collision_samples: SamplesOpt = 10_000,
    seed: SeedOpt = 0,
    smoke: Annotated[bool, typer.Option("--smoke", help="also run `modc sim` (PyBullet) before writing OUT")] = False,
    torque: TorqueOpt = None,
    ros: RosOpt = None,
    ros_distro: DistroOpt = None,
    ik_solver: IkOpt = None,
    ros_package: PackageOpt = None,
    command_interface: InterfaceOpt = None,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="print errors only")] = False,
    verbose: Annotated[bool, typer.Option("--verbose", "-v", help="list the files written")] = False,
):
    """Check FILE and write URDF, meshes and a report into OUT."""
    from ..compiler import COMPILE_ANALYSES, InputError, build, check_file, write_tree

    Verbosity.quiet, Verbosity.verbose = quiet, verbose
    try:
        severity = (torque or TorqueLevel.error).value
        checked = check_file(file, library, analyses=COMPILE_ANALYSES, torque_severity=severity)
    except InputError as e:
        _print_diagnostics([e.diagnostic], {})
        raise typer.Exit(EXIT_USAGE) from None
    _print_diagnostics(checked.diagnostics, checked.sources)
    if not checked.ok:
        from ..diagnostics.render import summary

        _err(f"modc: {summary(checked.diagnostics)}; nothing written to {out}")
        raise typer.Exit(EXIT_ERRORS)
    selected = None
    if only:
        from ..backends import load_all

        selected = [s.strip() for s in only.split(",") if s.strip()]
        unknown = [s for s in selected if s not in load_all()]
        if unknown:
            _err(f"modc: unknown backend(s) {', '.join(unknown)}; available: {', '.join(load_all())}")
            raise typer.Exit(EXIT_USAGE)
    if smoke:  # before anything is written: a failed smoke test leaves OUT as it was
        from ..sim.smoke import run_sim

        ok, lines, _ = run_sim(file, library=library)
        for line in lines:
            _err(line)
        if not ok:
            _err(f"modc: smoke test failed; nothing written to {out}")
            raise typer.Exit(EXIT_ERRORS)
    ros_options = _ros_options(checked, selected, ros, ros_distro, ik_solver, ros_package, command_interface)
    files = build(checked, selected, collision_samples=collision_samples, seed=seed, **ros_options)
    with usage_errors("compile", writing=out):
        write_tree(files, out, force=force, inputs=[file])
    if verbose:
        for rel in files:
            _err(f"  wrote {out.rstrip('/')}/{rel}")
    if not quiet:
        robots = ", ".join(f"{r.file_stem} ({r.sequence})" for r in checked.design.robots)
        _err(f"modc: {len(files)} files written to {out}: {robots or 'no robot'}")
        if checked.design.problems and not checked.design.robots:  # a design problem compiles to nothing
            _err(f"modc: {file} holds design problems, no robot: `modc design {file} -o DIR` finds arms for them")


def _ros_options(checked, selected, ros, ros_distro, ik_solver, ros_package, command_interface) -> dict:
    """Build fields of the ROS backend. The environment ($ROS_DISTRO, $ROS_VERSION) is read here
    and only here, below the command-line options (README "Use in ROS 2 / ROS 1")."""
    import os

    from ..backends import Build
    from ..backends.ros_target import RosOptionError, distro_for, resolve

    try:
        options = {"ros_distro": distro_for(ros, ros_distro, dict(os.environ)), "ik_solver": ik_solver,
                   "ros_package": ros_package, "command_interface": command_interface}
        if selected is None or "ros" in selected:
            resolve(Build(checked.design, **options))
    except RosOptionError as e:
        _err(f"modc: {e}")
        raise typer.Exit(EXIT_USAGE) from None
    return options
