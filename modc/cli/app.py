"""The Typer app and what every command shares: output, exit codes, common options."""

from __future__ import annotations

import difflib
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from enum import Enum
from pathlib import Path
from typing import Annotated, Any

import typer

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    rich_markup_mode=None,
    context_settings={"show_default": True},
    help="modc: compile .mod files describing MOIRs Mark-2 modular arms into URDF and friends.\n\n"
    "\b\n`modc FILE -o OUT` is `modc compile FILE -o OUT`: check FILE (.mod or its YAML form)\n"
    "and write URDF, meshes, xacro, SRDF and a ROS package into OUT.",
)


EXIT_OK, EXIT_ERRORS, EXIT_USAGE = 0, 1, 2


class Verbosity:
    quiet = False
    verbose = False


def _err(text: str) -> None:
    print(text, file=sys.stderr)


def _print_diagnostics(diags, sources) -> None:
    from ..diagnostics.render import render_text

    shown = [d for d in diags if not (Verbosity.quiet and not d.is_error)]
    if shown:
        _err(render_text(shown, sources))


class TorqueLevel(str, Enum):
    error = "error"
    warning = "warning"
    off = "off"


LibraryOpt = Annotated[
    str | None,
    typer.Option(
        "--library",
        metavar="NAME|FILE",
        help="module library: a built-in name (mark2, mark2-strict) or a YAML file; overrides `library` in the file",
    ),
]


def _expand(paths: list[str], prog: str = "modc") -> list[str]:
    """Files as given; directories searched for *.mod; glob patterns (also '**') expanded here,
    so quoted patterns work in CI shells. Sorted and de-duplicated, for stable output. A directory
    without .mod files or a pattern matching no file ends the command (exit 2): a mistyped CI
    glob must not pass as "0 files, no errors"."""
    import glob
    from pathlib import Path

    out: list[str] = []
    for p in paths:
        if Path(p).is_dir():
            found = sorted(str(f) for f in Path(p).rglob("*.mod"))
            what = "directory holds no .mod file"
        elif glob.has_magic(p):
            found = sorted(f for f in glob.glob(p, recursive=True) if Path(f).is_file())
            what = "pattern matches no file"
        else:
            found, what = [p], ""
        if not found:
            _err(f"{prog}: {p}: the {what}")
            raise typer.Exit(EXIT_USAGE)
        out += found
    return list(dict.fromkeys(out))


@contextmanager
def usage_errors(prog: str, usage: tuple[type[Exception], ...] = (), writing: str | None = None):
    """Unreadable input, an unknown robot, a bad name on the command line (`usage`) or a failed
    write (`writing`) end the command with exit 2 and a diagnostic or one plain line — never a
    traceback."""
    from ..compiler import InputError
    from ..model.select import RobotChoiceError

    try:
        yield
    except (InputError, RobotChoiceError) as e:
        _print_diagnostics([e.diagnostic], {})
        raise typer.Exit(EXIT_USAGE) from None
    except usage as e:
        _err(f"modc {prog}: {e}")
        raise typer.Exit(EXIT_USAGE) from None
    except OSError as e:
        if writing is None:
            raise
        _err(f"modc {prog}: cannot write {writing}: {e.strerror or e}")
        raise typer.Exit(EXIT_USAGE) from None


# --- the command line as a whole: routing, help, missing extras -------------------------------------

# Modules of the `full` extra, by the pip package that provides them.
HEAVY = {
    "pinocchio": "pin",
    "coal": "pin",
    "pybullet": "pybullet",
    "pybullet_data": "pybullet",
    "ompl": "ompl",
    "PIL": "pillow",
    "mujoco": "mujoco",
    "viser": "viser",
    "cma": "cma",
    "dask": "dask",
    "distributed": "distributed",
}
SOURCE_SUFFIXES = (".mod", ".yaml", ".yml")


def missing_extra(e: ModuleNotFoundError, command: str) -> str | None:
    """One line for a command that needs a module of the `full` extra; None for any other module
    (a real bug, which keeps its traceback)."""
    root = (e.name or "").split(".")[0]
    if root not in HEAVY:
        return None
    package = f"{root} (pip package {HEAVY[root]})" if HEAVY[root] != root.lower() else root
    return f"modc {command}: needs {package}, which the light install leaves out: pip install 'modc[full]'"


def route(args: list[str], commands: list[str]) -> list[str] | str:
    """The arguments for the Typer app, or an error line. A first word that is no command is a
    file to compile (`modc FILE -o OUT`) when it looks like one (it exists, or has a source suffix
    or a path separator); any other word is a mistyped command."""
    if not args or args[0].startswith("-") or args[0] in commands:
        return args
    word = args[0]
    looks_like_path = Path(word).exists() or word.lower().endswith(SOURCE_SUFFIXES) or any(c in word for c in "/\\.*?")
    if looks_like_path:
        return ["compile", *args]
    close = difflib.get_close_matches(word, commands, n=1, cutoff=0.6)
    suggestion = f"did you mean '{close[0]}'?" if close else "see modc --help"
    return f"modc: no command or file '{word}': {suggestion}"


def _metavar(param: Any) -> str:
    """A plain metavar: the choices, N for a number, else the parameter's name (FILE, OUT)."""
    desc = param.type_descriptor  # Typer describes parameter types itself (it vendors click)
    if desc.choices:
        return "|".join(str(getattr(c, "value", c)) for c in desc.choices)
    if desc.annotation in (int, float):
        return "N"
    return (param.name or "value").upper()


def _plain_help(command: Any) -> None:
    """Help without Typer's `<str>` types and `{file}` braces: every parameter gets a metavar."""
    for param in command.params:
        if getattr(param, "is_flag", False) or param.name == "help":
            continue
        if param.metavar is None:
            param.metavar = _metavar(param)
        if param.param_type_name == "argument":
            name = param.metavar + ("..." if param.nargs != 1 else "")
            usage = name if param.required else f"[{name}]"
            param.display_type_rich = lambda ctx: None
            param._usage_display_name = lambda usage=usage: usage
    for sub in getattr(command, "commands", {}).values():
        _plain_help(sub)


def _commands() -> Iterator[str]:
    for c in app.registered_commands:
        name = c.name or (c.callback.__name__ if c.callback else None)
        if name:
            yield name


def run(argv: list[str]) -> None:
    """The `modc` entry point: route, then run the Typer app as a click command."""
    routed = route(argv, list(_commands()))
    if isinstance(routed, str):
        _err(routed)
        raise SystemExit(EXIT_USAGE)
    command = typer.main.get_command(app)
    _plain_help(command)
    try:
        command.main(args=routed, prog_name="modc")
    except ModuleNotFoundError as e:
        line = missing_extra(e, routed[0] if routed else "")
        if line is None:
            raise
        _err(line)
        raise SystemExit(EXIT_USAGE) from None
