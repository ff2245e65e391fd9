"""PyBullet and planning: `sim`, `render`, `play`, `plan`."""
from __future__ import annotations

import sys
from typing import Annotated

import typer

from .app import (
    EXIT_ERRORS,
    EXIT_OK,
    EXIT_USAGE,
    LibraryOpt,
    _err,
    _print_diagnostics,
    app,
    usage_errors,
)


@app.command("sim")
def sim_cmd(
    file: Annotated[str, typer.Argument(help=".mod file (or its YAML form)")],
    robot: Annotated[str | None, typer.Option(help="simulate only this robot of the file")] = None,
    srdf_from: Annotated[
        str | None,
        typer.Option(
            "--srdf-from", help="a compile output OUT/ whose config/*.srdf disabled collision pairs are honoured"
        ),
    ] = None,
    library: LibraryOpt = None,
    engine: Annotated[str, typer.Option(help="physics engine: pybullet (the URDF) or mujoco (the MJCF)")] = "pybullet",
):
    """Smoke test (PyBullet, or MuJoCo with --engine mujoco): load every robot, hold home and
    every named pose with the actuators' peak torque, check tracking, self-collision, the
    environment, FK and holding torques. Exit 1 on any failure, saying what failed."""
    from ..sim.scene import UsageError
    from ..sim.smoke import run_sim

    with usage_errors("sim", (UsageError,)):
        ok, lines, checked = run_sim(file, library=library, robot=robot, out_dir=srdf_from, engine=engine)
    _print_diagnostics(checked.diagnostics, checked.sources)
    for line in lines:
        print(line)
    raise typer.Exit(EXIT_OK if ok else EXIT_ERRORS)


@app.command("render")
def render_cmd(
    file: Annotated[str, typer.Argument(help=".mod file (or its YAML form)")],
    out: Annotated[str, typer.Option("-o", "--out", help="PNG file to write")],
    pose: Annotated[str | None, typer.Option(help="named pose (default: home)")] = None,
    robot: Annotated[str | None, typer.Option(help="render only this robot of the file")] = None,
    size: Annotated[str, typer.Option(help="WIDTHxHEIGHT in pixels")] = "800x600",
    azimuth: Annotated[
        float | None, typer.Option(help="camera azimuth in degrees from +x towards +y (default: chosen)")
    ] = None,
    elevation: Annotated[float | None, typer.Option(help="camera elevation in degrees (default 30)")] = None,
    colors: Annotated[
        int | None, typer.Option(help="quantise to a palette of this many colours (<= 256) for small files")
    ] = None,
    library: LibraryOpt = None,
):
    """A picture of the arm, its environment and its targets (PyBullet TinyRenderer, headless)."""
    from ..sim.render import render
    from ..sim.scene import UsageError

    try:
        width, height = (int(v) for v in size.lower().split("x"))
        assert width > 0 and height > 0
    except (ValueError, AssertionError):
        _err(f"modc render: --size {size!r}: expected WIDTHxHEIGHT, e.g. 800x600")
        raise typer.Exit(EXIT_USAGE) from None
    if colors is not None and not 2 <= colors <= 256:
        _err(f"modc render: --colors {colors}: expected 2 to 256")
        raise typer.Exit(EXIT_USAGE)
    with usage_errors("render", (UsageError,), writing=out):
        ok, lines, checked = render(file, out, pose=pose, robot=robot, library=library, width=width, height=height,
                                    azimuth=azimuth, elevation=elevation, colors=colors)
    _print_diagnostics(checked.diagnostics, checked.sources)
    for line in lines:
        _err(line)
    raise typer.Exit(EXIT_OK if ok else EXIT_ERRORS)


@app.command("play")
def play_cmd(
    file: Annotated[str, typer.Argument(help=".mod file (or its YAML form)")],
    traj: Annotated[str, typer.Option("--traj", help="trajectory JSON, as `modc plan --json` prints")],
    record: Annotated[str | None, typer.Option(help="write a GIF of the motion (headless TinyRenderer)")] = None,
    robot: Annotated[
        str | None, typer.Option(help="the robot the trajectory is for (files with several robots)")
    ] = None,
    headless: Annotated[bool, typer.Option("--headless", help="never open the PyBullet GUI")] = False,
    library: LibraryOpt = None,
):
    """Play a trajectory in PyBullet: in the GUI when a display works, else headless; report
    tracking and collisions; --record OUT.gif."""
    from ..sim.play import play
    from ..sim.scene import UsageError

    with usage_errors("play", (UsageError,), writing=record):
        ok, lines, checked = play(
            file, traj, record=record, robot=robot, library=library, gui=False if headless else None
        )
    _print_diagnostics(checked.diagnostics, checked.sources)
    if not ok:
        from ..diagnostics import Span, codes

        _print_diagnostics([codes.TRAJ_INVALID.at(Span.point(traj), detail=line) for line in lines], {})
        raise typer.Exit(EXIT_ERRORS)
    for line in lines:
        print(line)
    raise typer.Exit(EXIT_OK)


@app.command("plan")
def plan_cmd(
    file: Annotated[str, typer.Argument(help=".mod file (or its YAML form)")],
    to: Annotated[str, typer.Option("--to", help="target to move tool0 to (a `target` of the robot)")],
    json_out: Annotated[
        bool, typer.Option("--json", help="print the trajectory as JSON on stdout (SPEC section 6)")
    ] = False,
    robot: Annotated[str | None, typer.Option(help="robot of the file (default: the one that has the target)")] = None,
    seed: Annotated[
        int, typer.Option(min=0, help="seed of IK starts, RRT-Connect and shortcuts: same file and seed, same motion")
    ] = 0,
    start: Annotated[str | None, typer.Option(help="pose to start from (default: home)")] = None,
    timeout: Annotated[float, typer.Option(min=0.1, help="seconds of path search at most")] = 20.0,
    library: LibraryOpt = None,
):
    """Plan a collision-free motion from the home pose (or --start) to a named target (exit 1 if none)."""
    from ..plan import PlanError, plan

    try:
        result = plan(file, to, robot=robot, seed=seed, start=start, library=library, timeout=timeout)
    except PlanError as e:
        _print_diagnostics(e.diagnostics, e.sources)
        raise typer.Exit(e.exit_code) from None
    if json_out:
        sys.stdout.write(result.dumps())
    else:
        print(result.summary())
