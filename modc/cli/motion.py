"""PyBullet and planning: `sim`, `render`, `play`, `plan`."""
from __future__ import annotations

import sys
from typing import Any

import click

from .app import (
    EXIT_ERRORS,
    EXIT_OK,
    EXIT_USAGE,
    _err,
    _print_diagnostics,
    app,
    argument,
    library_option,
    usage_errors,
)


@app.command("sim")
@argument("file", help=".mod file (or its YAML form)")
@click.option("--robot", help="simulate only this robot of the file")
@click.option("--srdf-from", help="a compile output OUT/ whose config/*.srdf disabled collision pairs are honoured")
@library_option
@click.option("--engine", default="pybullet", help="physics engine: pybullet (the URDF) or mujoco (the MJCF)")
def sim_cmd(file: str, robot: str | None, srdf_from: str | None, library: str | None, engine: str) -> None:
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
    raise SystemExit(EXIT_OK if ok else EXIT_ERRORS)


MAX_PIXELS = 4096  # per side: a 4096x4096 RGBA frame is 64 MB; 100000x100000 aborted in TinyRenderer


def _angle(limit: float):
    """A click callback: a finite angle in degrees within ±limit (FloatRange lets nan through)."""
    def check(_ctx: click.Context, param: click.Parameter, value: float | None) -> float | None:
        if value is not None and not -limit <= value <= limit:
            raise click.BadParameter(f"expected degrees from {-limit:g} to {limit:g}")
        return value
    return check


@app.command("render")
@argument("file", help=".mod file (or its YAML form)")
@click.option("-o", "--out", required=True, help="PNG file to write")
@click.option("--pose", help="named pose (default: home)")
@click.option("--robot", help="render only this robot of the file")
@click.option("--size", default="1280x960", help="WIDTHxHEIGHT in pixels")
@click.option("--azimuth", type=float, callback=_angle(360.0),
              help="camera azimuth in degrees from +x towards +y (default: chosen)")
@click.option("--elevation", type=float, callback=_angle(90.0), help="camera elevation in degrees (default 30)")
@click.option("--colors", type=int, help="quantise to a palette of this many colours (<= 256) for small files")
@library_option
def render_cmd(
    file: str,
    out: str,
    pose: str | None,
    robot: str | None,
    size: str,
    azimuth: float | None,
    elevation: float | None,
    colors: int | None,
    library: str | None,
) -> None:
    """A picture of the arm, its environment and its targets (PyBullet TinyRenderer, headless)."""
    from ..sim.render import render
    from ..sim.scene import UsageError

    try:
        width, height = (int(v) for v in size.lower().split("x"))
        assert 0 < width <= MAX_PIXELS and 0 < height <= MAX_PIXELS
    except (ValueError, AssertionError):
        _err(f"modc render: --size {size[:40]!r}: expected WIDTHxHEIGHT, each 1 to {MAX_PIXELS}, e.g. 1280x960")
        raise SystemExit(EXIT_USAGE) from None
    if colors is not None and not 2 <= colors <= 256:
        _err(f"modc render: --colors {colors}: expected 2 to 256")
        raise SystemExit(EXIT_USAGE)
    with usage_errors("render", (UsageError,), writing=out):
        from ..compiler import inputs_of
        from ..outputs import check_output_file

        check_output_file(out, inputs_of(file, library), "-o", "arm.png")
        ok, lines, checked = render(file, out, pose=pose, robot=robot, library=library, width=width, height=height,
                                    azimuth=azimuth, elevation=elevation, colors=colors)
    _print_diagnostics(checked.diagnostics, checked.sources)
    for line in lines:
        _err(line)
    raise SystemExit(EXIT_OK if ok else EXIT_ERRORS)


@app.command("play")
@argument("file", help=".mod file (or its YAML form)")
@click.option("--traj", required=True, help="trajectory JSON, as `modc plan --json` prints")
@click.option("--record", help="write a GIF of the motion (headless: TinyRenderer, or MuJoCo's offscreen renderer)")
@click.option("--robot", help="the robot the trajectory is for (files with several robots)")
@click.option("--headless", is_flag=True, help="never open the PyBullet GUI")
@click.option("--engine", default="pybullet",
              help="pybullet (the URDF) or mujoco (the MJCF scene, servos with inverse-dynamics feed-forward)")
@library_option
def play_cmd(file: str, traj: str, record: str | None, robot: str | None, headless: bool, engine: str,
             library: str | None) -> None:
    """Play a trajectory in PyBullet (in the GUI when a display works, else headless) or MuJoCo
    (--engine mujoco); report tracking error (max per joint) and collisions; --record OUT.gif."""
    from ..sim.play import play
    from ..sim.scene import UsageError

    with usage_errors("play", (UsageError,), writing=record):
        if record is not None:
            from ..compiler import inputs_of
            from ..outputs import check_output_file

            check_output_file(record, inputs_of(file, library, more=[traj]), "--record", "motion.gif")
        ok, lines, checked = play(
            file, traj, record=record, robot=robot, library=library, gui=False if headless else None, engine=engine
        )
    _print_diagnostics(checked.diagnostics, checked.sources)
    if not ok:
        from ..diagnostics import Span, codes

        _print_diagnostics([codes.TRAJ_INVALID.at(Span.point(traj), detail=line) for line in lines], {})
        raise SystemExit(EXIT_ERRORS)
    for line in lines:
        print(line)
    raise SystemExit(EXIT_OK)


def _seconds(_ctx: click.Context, _param: click.Parameter, value: float) -> float:
    """A click callback: finite seconds, at least 0.1 (FloatRange lets nan and inf through)."""
    import math

    if not (math.isfinite(value) and value >= 0.1):
        raise click.BadParameter(f"{value!r} is not a number of seconds from 0.1 on")
    return value


EXIT_INTERRUPTED = 130  # Ctrl-C, as a shell reports a process SIGINT ended


@app.command("plan")
@argument("file", help=".mod file (or its YAML form)")
@click.option("--to", help="target to move tool0 to (a `target` of the robot)")
@click.option("--task", help="plan and time this task or path of the robot (`task`, `path`), as one trajectory")
@click.option("--json", "json_out", is_flag=True, help="print the trajectory as JSON on stdout (docs/conventions.md)")
@click.option("--robot", help="robot of the file (default: the one that has the target)")
@click.option("--seed", type=click.IntRange(min=0), default=0,
              help="seed of IK starts, RRT-Connect and shortcuts: same file and seed, same motion")
@click.option("--start", help="pose to start from (default: home)")
@click.option("--timeout", type=float, default=20.0, callback=_seconds,
              help="seconds of path search at most (per segment with --task)")
@click.option("-q", "--quiet", is_flag=True, help="no progress display (--task)")
@library_option
def plan_cmd(
    file: str,
    to: str | None,
    task: str | None,
    json_out: bool,
    robot: str | None,
    seed: int,
    start: str | None,
    timeout: float,
    quiet: bool,
    library: str | None,
) -> None:
    """Plan a collision-free motion from the home pose (or --start) to a named target (exit 1 if none);
    with --task, plan and time a whole task from the home pose (progress on stderr, -q: none)."""
    from ..plan import PlanError, plan

    if (to is None) == (task is None):
        _err("modc plan: give one of --to TARGET or --task NAME")
        raise SystemExit(EXIT_USAGE)
    try:
        if task is not None:
            from ..plan.task import plan_task
            from .plan_progress import progress

            if start is not None:
                _err("modc plan: --start does not apply to --task (a task starts from the home pose)")
                raise SystemExit(EXIT_USAGE)
            mode = "off" if quiet else "live" if sys.stderr.isatty() else "plain"
            with progress(mode, task) as hook:
                result: Any = plan_task(file, task, robot=robot, seed=seed, library=library, timeout=timeout,
                                        progress=hook)
        else:
            assert to is not None
            result = plan(file, to, robot=robot, seed=seed, start=start, library=library, timeout=timeout)
    except PlanError as e:
        _print_diagnostics(e.diagnostics, e.sources)
        raise SystemExit(e.exit_code) from None
    except KeyboardInterrupt:
        _err("modc plan: interrupted; nothing planned")
        raise SystemExit(EXIT_INTERRUPTED) from None
    if json_out:
        sys.stdout.write(result.dumps())
    else:
        print(result.summary())
