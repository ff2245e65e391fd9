"""Command line: `modc FILE -o OUT`, `modc lint`, `modc schema`, `modc codes`.

Exit codes: 0 success, 1 diagnostics with errors, 2 usage or I/O error. Heavy libraries
(numpy, jinja2, trimesh, pinocchio…) are imported inside commands, never at start-up.
"""
from __future__ import annotations

import sys
from enum import Enum
from typing import Annotated, Optional

import typer

from . import __version__

app = typer.Typer(add_completion=False, no_args_is_help=True, rich_markup_mode=None,
                  help="modc: compile .mod files describing MOIRs Mark-2 modular arms into URDF and friends.")

EXIT_OK, EXIT_ERRORS, EXIT_USAGE = 0, 1, 2


class Verbosity:
    quiet = False
    verbose = False


def _err(text: str) -> None:
    print(text, file=sys.stderr)


def _print_diagnostics(diags, sources) -> None:
    from .diagnostics.render import render_text

    shown = [d for d in diags if not (Verbosity.quiet and not d.is_error)]
    if shown:
        _err(render_text(shown, sources))


class TorqueLevel(str, Enum):
    error = "error"
    warning = "warning"
    off = "off"


LibraryOpt = Annotated[Optional[str], typer.Option("--library", help="module library: a built-in name (mark2, mark2-strict) or a YAML file; overrides `library` in the file")]


@app.command("compile")
def compile_cmd(
    file: Annotated[str, typer.Argument(help=".mod file (or its YAML form)")],
    out: Annotated[str, typer.Option("-o", "--out", help="output directory (replaced atomically on success)")],
    library: LibraryOpt = None,
    only: Annotated[Optional[str], typer.Option(help="comma-separated backends to run (default: all); see `modc backends`")] = None,
    force: Annotated[bool, typer.Option(help="replace OUT even if modc did not create it")] = False,
    collision_samples: Annotated[int, typer.Option(min=0, help="random poses for the SRDF collision matrix (MoveIt's default)")] = 10_000,
    seed: Annotated[int, typer.Option(min=0, help="seed of those poses: same file and seed, same SRDF on any machine")] = 0,
    smoke: Annotated[bool, typer.Option("--smoke", help="also run `modc sim` (PyBullet) before writing OUT")] = False,
    torque: Annotated[Optional[TorqueLevel], typer.Option(help="how a joint that cannot hold the arm at peak torque is reported")] = None,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="print errors only")] = False,
    verbose: Annotated[bool, typer.Option("--verbose", "-v", help="list the files written")] = False,
):
    """Check FILE and write URDF, meshes and a report into OUT."""
    from .compiler import COMPILE_ANALYSES, InputError, build, check_file, write_tree

    Verbosity.quiet, Verbosity.verbose = quiet, verbose
    try:
        checked = check_file(file, library, analyses=COMPILE_ANALYSES, torque_severity=(torque or TorqueLevel.error).value)
    except InputError as e:
        _print_diagnostics([e.diagnostic], {})
        raise typer.Exit(EXIT_USAGE)
    _print_diagnostics(checked.diagnostics, checked.sources)
    if not checked.ok:
        from .diagnostics.render import summary

        _err(f"modc: {summary(checked.diagnostics)}; nothing written to {out}")
        raise typer.Exit(EXIT_ERRORS)
    selected = None
    if only:
        from .backends import load_all

        selected = [s.strip() for s in only.split(",") if s.strip()]
        unknown = [s for s in selected if s not in load_all()]
        if unknown:
            _err(f"modc: unknown backend(s) {', '.join(unknown)}; available: {', '.join(load_all())}")
            raise typer.Exit(EXIT_USAGE)
    if smoke:  # before anything is written: a failed smoke test leaves OUT as it was
        from .sim.smoke import run_sim

        ok, lines, _ = run_sim(file, library=library)
        for line in lines:
            _err(line)
        if not ok:
            _err(f"modc: smoke test failed; nothing written to {out}")
            raise typer.Exit(EXIT_ERRORS)
    files = build(checked, selected, collision_samples=collision_samples, seed=seed)
    try:
        write_tree(files, out, force=force)
    except InputError as e:
        _print_diagnostics([e.diagnostic], {})
        raise typer.Exit(EXIT_USAGE)
    except OSError as e:
        _err(f"modc: cannot write {out}: {e}")
        raise typer.Exit(EXIT_USAGE)
    if verbose:
        for rel in files:
            _err(f"  wrote {out.rstrip('/')}/{rel}")
    if not quiet:
        robots = ", ".join(f"{r.file_stem} ({r.sequence})" for r in checked.design.robots)
        _err(f"modc: {len(files)} files written to {out}: {robots}")


class LintFormat(str, Enum):
    text = "text"
    json = "json"
    github = "github"
    sarif = "sarif"


def _expand(paths: list[str]) -> list[str]:
    """Files as given; directories searched for *.mod; glob patterns (also '**') expanded here,
    so quoted patterns work in CI shells. Sorted and de-duplicated, for stable output."""
    import glob
    from pathlib import Path

    out: list[str] = []
    for p in paths:
        if Path(p).is_dir():
            out += sorted(str(f) for f in Path(p).rglob("*.mod"))
        elif glob.has_magic(p):
            out += sorted(f for f in glob.glob(p, recursive=True) if Path(f).is_file())
        else:
            out.append(p)
    return list(dict.fromkeys(out))


@app.command("lint")
def lint_cmd(
    files: Annotated[list[str], typer.Argument(help=".mod files or directories")],
    format: Annotated[LintFormat, typer.Option("--format", "-f", help="output format")] = LintFormat.text,
    library: LibraryOpt = None,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="print errors only")] = False,
):
    """Check files without writing anything."""
    from .compiler import InputError, check_file
    from .diagnostics.render import render_github, render_json, render_sarif, summary

    Verbosity.quiet = quiet
    diags, sources, io_error = [], {}, False
    paths = _expand(files)
    for path in paths:
        try:
            c = check_file(path, library)
        except InputError as e:
            diags.append(e.diagnostic)
            io_error = True
            continue
        diags += c.diagnostics
        sources.update(c.sources)
    shown = [d for d in diags if not (quiet and not d.is_error)]
    if format is LintFormat.json:
        print(render_json(shown))
    elif format is LintFormat.github:
        if shown:
            print(render_github(shown))
    elif format is LintFormat.sarif:
        print(render_sarif(shown, __version__))
    else:
        _print_diagnostics(diags, sources)
        if not quiet:
            _err(f"modc lint: {len(paths)} file{'s' * (len(paths) != 1)}, {summary(diags)}")
    if io_error:
        raise typer.Exit(EXIT_USAGE)
    raise typer.Exit(EXIT_ERRORS if any(d.is_error for d in diags) else EXIT_OK)


def _mass(text: str) -> float | None:
    import math
    import re

    m = re.fullmatch(r"\s*([+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?)\s*(kg|g)?\s*", text)
    if not m:
        return None
    value = float(m.group(1)) * (0.001 if m.group(2) == "g" else 1.0)
    return value if math.isfinite(value) and value >= 0 else None


@app.command("check")
def check_cmd(
    file: Annotated[str, typer.Argument(help=".mod file (or its YAML form)")],
    payload: Annotated[Optional[str], typer.Option(help="payload at tool0 replacing the file's, e.g. 0.5kg or 500g")] = None,
    json_out: Annotated[bool, typer.Option("--json", help="print the torque table as JSON")] = False,
    library: LibraryOpt = None,
):
    """Torque feasibility: the worst static gravity torque of every joint over its range, against
    the actuator's nominal and peak torque. Exit 1 if a joint can exceed its peak torque."""
    import json
    import math

    from .compiler import COMPILE_ANALYSES, InputError, check_file
    from .diagnostics import Span, codes

    mass = None
    if payload is not None:
        mass = _mass(payload)
        if mass is None:
            _print_diagnostics([codes.BAD_PAYLOAD.at(Span.point("<command line>"), value=payload)], {})
            raise typer.Exit(EXIT_USAGE)
    try:
        checked = check_file(file, library, analyses=COMPILE_ANALYSES, payload_override=mass)
    except InputError as e:
        _print_diagnostics([e.diagnostic], {})
        raise typer.Exit(EXIT_USAGE)
    robots = [r for r in checked.design.robots if r.torque is not None]
    if json_out:
        doc = {"robots": [{"name": r.name, "payload": mass if mass is not None else (r.payload.mass if r.payload else 0.0),
                           "joints": [j.to_json() for j in r.torque]} for r in robots]}
        print(json.dumps(doc, indent=2))
    else:
        for r in robots:
            print(f"robot {r.name} ({r.sequence}), payload {mass if mass is not None else (r.payload.mass if r.payload else 0):g} kg")
            print(f"  {'joint':<9}{'unit':<6}{'worst |tau| N·m':>16}{'nominal':>9}{'peak':>7}{'margin':>8}  worst pose (deg)")
            for j in r.torque:
                pose = ", ".join(f"{math.degrees(x):.0f}" for x in j.q)
                print(f"  {j.name:<9}{j.variant:<6}{j.tau:>16.3f}{j.tau_nom:>9g}{j.tau_max:>7g}{j.margin:>8.0%}  ({pose})  {j.level}")
    _print_diagnostics(checked.diagnostics, checked.sources)
    raise typer.Exit(EXIT_OK if checked.ok else EXIT_ERRORS)


@app.command("dh2mod")
def dh2mod_cmd(
    table: Annotated[str, typer.Argument(help="CSV with header a,alpha,d,theta (metres, radians), one row per joint")],
    json_out: Annotated[bool, typer.Option("--json", help="print requested vs realised DH as JSON instead of .mod text")] = False,
    fit_links: Annotated[bool, typer.Option("--fit-links", help="print link modules at the lengths that realise each a exactly")] = False,
    name: Annotated[Optional[str], typer.Option(help="robot name (default: from the file name)")] = None,
    library: LibraryOpt = None,
):
    """Convert a standard DH table into a module chain (paper section 4.2); .mod text on stdout."""
    from .compiler import InputError, read_source
    from .dh.convert_file import convert_table

    try:
        text = read_source(table)
    except InputError as e:
        _print_diagnostics([e.diagnostic], {})
        raise typer.Exit(EXIT_USAGE)
    out, diags, ok = convert_table(text, table, name=name, fit_links=fit_links, library=library, as_json=json_out)
    _print_diagnostics(diags, {table: text})
    if not ok:
        raise typer.Exit(EXIT_ERRORS)
    sys.stdout.write(out)


@app.command("dh")
def dh_cmd(
    file: Annotated[str, typer.Argument(help=".mod file (or its YAML form)")],
    json_out: Annotated[bool, typer.Option("--json", help="JSON instead of a table")] = False,
    library: LibraryOpt = None,
):
    """Show the realised standard DH table of every robot (and the requested one, for dh tables)."""
    import json

    from .compiler import InputError, check_file
    from .dh.report import compare, text_table

    try:
        checked = check_file(file, library)
    except InputError as e:
        _print_diagnostics([e.diagnostic], {})
        raise typer.Exit(EXIT_USAGE)
    if not checked.ok:
        _print_diagnostics(checked.diagnostics, checked.sources)
        raise typer.Exit(EXIT_ERRORS)
    robots = checked.design.robots
    if json_out:
        doc = {"robots": [{"name": r.name, "sequence": r.sequence, "joints": compare(r)} for r in robots]}
        print(json.dumps(doc, indent=2))
    else:
        print("\n\n".join(text_table(r) for r in robots))


@app.command("fmt")
def fmt_cmd(
    files: Annotated[list[str], typer.Argument(help=".mod files or directories")],
    check: Annotated[bool, typer.Option("--check", help="write nothing; list the files that would change and exit 1 if any")] = False,
):
    """Rewrite .mod files in the canonical layout (comments kept, meaning unchanged)."""
    from .compiler import YAML_SUFFIXES, InputError, read_source
    from .syntax.format import FormatterBug, format_text, rewrite_file

    diags, sources, io_error, changed = [], {}, False, []
    for path in _expand(files):
        if path.endswith(YAML_SUFFIXES):
            _err(f"modc fmt: {path}: only .mod files are formatted")
            io_error = True
            continue
        try:
            text = read_source(path)
        except InputError as e:
            diags.append(e.diagnostic)
            io_error = True
            continue
        try:
            out, errors = format_text(text, path)
        except FormatterBug as e:
            _err(f"modc fmt: internal error: {e}")
            io_error = True
            continue
        if out is None:  # does not parse: reported, never touched
            diags += errors
            sources[path] = text
            continue
        with open(path, "rb") as f:  # a BOM or CRLF line ends count as a change
            if f.read() == out.encode("utf-8"):
                continue
        changed.append(path)
        if not check:
            try:
                rewrite_file(path, out)
            except OSError as e:
                _err(f"modc fmt: {path}: {e.strerror or e}")
                io_error = True
                continue
        print(path)
    _print_diagnostics(diags, sources)
    if io_error:
        raise typer.Exit(EXIT_USAGE)
    raise typer.Exit(EXIT_ERRORS if diags or (check and changed) else EXIT_OK)


@app.command("lsp")
def lsp_cmd() -> None:
    """Language server on stdio for editors: diagnostics, hover, completion, symbols, go-to-definition, formatting."""
    from .lsp import serve

    serve()


@app.command("sim")
def sim_cmd(
    file: Annotated[str, typer.Argument(help=".mod file (or its YAML form)")],
    robot: Annotated[Optional[str], typer.Option(help="simulate only this robot of the file")] = None,
    srdf_from: Annotated[Optional[str], typer.Option("--srdf-from", help="a compile output OUT/ whose config/*.srdf disabled collision pairs are honoured")] = None,
    library: LibraryOpt = None,
):
    """PyBullet smoke test: load every robot, hold home and every named pose with the actuators'
    peak torque, check tracking, self-collision, the environment, FK and holding torques.
    Exit 1 on any failure, saying what failed."""
    from .compiler import InputError
    from .sim.scene import UsageError
    from .sim.smoke import run_sim

    try:
        ok, lines, checked = run_sim(file, library=library, robot=robot, out_dir=srdf_from)
    except InputError as e:
        _print_diagnostics([e.diagnostic], {})
        raise typer.Exit(EXIT_USAGE)
    except UsageError as e:
        _err(f"modc sim: {e}")
        raise typer.Exit(EXIT_USAGE)
    _print_diagnostics(checked.diagnostics, checked.sources)
    for line in lines:
        print(line)
    raise typer.Exit(EXIT_OK if ok else EXIT_ERRORS)


@app.command("render")
def render_cmd(
    file: Annotated[str, typer.Argument(help=".mod file (or its YAML form)")],
    out: Annotated[str, typer.Option("-o", "--out", help="PNG file to write")],
    pose: Annotated[Optional[str], typer.Option(help="named pose (default: home)")] = None,
    robot: Annotated[Optional[str], typer.Option(help="render only this robot of the file")] = None,
    size: Annotated[str, typer.Option(help="WIDTHxHEIGHT in pixels")] = "800x600",
    azimuth: Annotated[Optional[float], typer.Option(help="camera azimuth in degrees from +x towards +y (default: chosen)")] = None,
    elevation: Annotated[Optional[float], typer.Option(help="camera elevation in degrees (default 30)")] = None,
    colors: Annotated[Optional[int], typer.Option(help="quantise to a palette of this many colours (<= 256) for small files")] = None,
    library: LibraryOpt = None,
):
    """A picture of the arm, its environment and its targets (PyBullet TinyRenderer, headless)."""
    from .compiler import InputError
    from .sim.render import render
    from .sim.scene import UsageError

    try:
        width, height = (int(v) for v in size.lower().split("x"))
        assert width > 0 and height > 0
    except (ValueError, AssertionError):
        _err(f"modc render: --size {size!r}: expected WIDTHxHEIGHT, e.g. 800x600")
        raise typer.Exit(EXIT_USAGE)
    if colors is not None and not 2 <= colors <= 256:
        _err(f"modc render: --colors {colors}: expected 2 to 256")
        raise typer.Exit(EXIT_USAGE)
    try:
        ok, lines, checked = render(file, out, pose=pose, robot=robot, library=library, width=width, height=height,
                                    azimuth=azimuth, elevation=elevation, colors=colors)
    except InputError as e:
        _print_diagnostics([e.diagnostic], {})
        raise typer.Exit(EXIT_USAGE)
    except UsageError as e:
        _err(f"modc render: {e}")
        raise typer.Exit(EXIT_USAGE)
    except OSError as e:
        _err(f"modc render: cannot write {out}: {e.strerror or e}")
        raise typer.Exit(EXIT_USAGE)
    _print_diagnostics(checked.diagnostics, checked.sources)
    for line in lines:
        _err(line)
    raise typer.Exit(EXIT_OK if ok else EXIT_ERRORS)


@app.command("play")
def play_cmd(
    file: Annotated[str, typer.Argument(help=".mod file (or its YAML form)")],
    traj: Annotated[str, typer.Option("--traj", help="trajectory JSON, as `modc plan --json` prints")],
    record: Annotated[Optional[str], typer.Option(help="write a GIF of the motion (headless TinyRenderer)")] = None,
    robot: Annotated[Optional[str], typer.Option(help="the robot the trajectory is for (files with several robots)")] = None,
    headless: Annotated[bool, typer.Option("--headless", help="never open the PyBullet GUI")] = False,
    library: LibraryOpt = None,
):
    """Play a trajectory in PyBullet: in the GUI when a display works, else headless; report
    tracking and collisions; --record OUT.gif."""
    from .compiler import InputError
    from .sim.play import play
    from .sim.scene import UsageError

    try:
        ok, lines, checked = play(file, traj, record=record, robot=robot, library=library, gui=False if headless else None)
    except InputError as e:
        _print_diagnostics([e.diagnostic], {})
        raise typer.Exit(EXIT_USAGE)
    except UsageError as e:
        _err(f"modc play: {e}")
        raise typer.Exit(EXIT_USAGE)
    except OSError as e:
        _err(f"modc play: cannot write {record}: {e.strerror or e}")
        raise typer.Exit(EXIT_USAGE)
    _print_diagnostics(checked.diagnostics, checked.sources)
    if not ok:
        from .diagnostics import Span, codes

        _print_diagnostics([codes.TRAJ_INVALID.at(Span.point(traj), detail=line) for line in lines], {})
        raise typer.Exit(EXIT_ERRORS)
    for line in lines:
        print(line)
    raise typer.Exit(EXIT_OK)


@app.command("plan")
def plan_cmd(
    file: Annotated[str, typer.Argument(help=".mod file (or its YAML form)")],
    to: Annotated[str, typer.Option("--to", help="target to move tool0 to (a `target` of the robot)")],
    json_out: Annotated[bool, typer.Option("--json", help="print the trajectory as JSON on stdout (SPEC section 6)")] = False,
    robot: Annotated[Optional[str], typer.Option(help="robot of the file (default: the one that has the target)")] = None,
    seed: Annotated[int, typer.Option(min=0, help="seed of IK starts, RRT-Connect and shortcuts: same file and seed, same motion")] = 0,
    start: Annotated[Optional[str], typer.Option(help="pose to start from (default: home)")] = None,
    timeout: Annotated[float, typer.Option(min=0.1, help="seconds of path search at most")] = 20.0,
    library: LibraryOpt = None,
):
    """Plan a collision-free motion from the home pose (or --start) to a named target (exit 1 if none)."""
    from .plan import PlanError, plan

    try:
        result = plan(file, to, robot=robot, seed=seed, start=start, library=library, timeout=timeout)
    except PlanError as e:
        _print_diagnostics(e.diagnostics, e.sources)
        raise typer.Exit(e.exit_code)
    if json_out:
        sys.stdout.write(result.dumps())
    else:
        print(result.summary())


@app.command("schema")
def schema_cmd():
    """Print the JSON Schema of the YAML form of .mod files."""
    import json

    from .syntax.document import json_schema

    print(json.dumps(json_schema(), indent=2))


@app.command("codes")
def codes_cmd():
    """List every diagnostic code with its severity and meaning."""
    from .diagnostics import REGISTRY

    for code in REGISTRY.values():
        allow = " (allowable)" if code.allowable else ""
        print(f"{code.name:28} {code.severity.value:8} {code.summary}{allow}")


@app.command("backends")
def backends_cmd():
    """List the output backends."""
    from .backends import load_all

    for b in load_all().values():
        print(f"{b.name:10} {b.summary}")


def _version(value: bool):
    if value:
        print(f"modc {__version__}")
        raise typer.Exit()


@app.callback()
def _root(version: Annotated[bool, typer.Option("--version", callback=_version, is_eager=True, help="print the version")] = False):
    pass


def main(argv: list[str] | None = None) -> None:
    args = list(sys.argv[1:] if argv is None else argv)
    # `modc FILE -o OUT` is `modc compile FILE -o OUT`.
    commands = {c.name or c.callback.__name__ for c in app.registered_commands}
    if args and not args[0].startswith("-") and args[0] not in commands:
        args.insert(0, "compile")
    app(args=args, prog_name="modc")
