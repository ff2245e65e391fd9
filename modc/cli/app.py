"""The click group and what every command shares: output, exit codes, common options."""

from __future__ import annotations

import difflib
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import click

from .. import __version__
from .common import (  # noqa: F401 - the commands' modules import them from here
    EXIT_ERRORS,
    EXIT_OK,
    EXIT_USAGE,
    Verbosity,
    _err,
    _expand,
    _print_diagnostics,
    usage_errors,
)


def _metavar(option: click.Option) -> str:
    """A plain metavar: the choices, N for a number, else the option's name (OUT, ROBOT)."""
    if isinstance(option.type, click.Choice):
        return "|".join(map(str, option.type.choices))
    if option.type in (click.INT, click.FLOAT) or isinstance(option.type, click.IntRange | click.FloatRange):
        return "N"
    return (option.name or "value").upper()


class Argument(click.Argument):
    """A positional argument with a help line, listed under "Arguments" (click before 8.5 has none)."""

    def __init__(self, param_decls: Sequence[str], help: str = "", **attrs: Any) -> None:
        super().__init__(param_decls, **attrs)
        self.help = help


class Command(click.Command):
    """Plain help: an "Arguments" section, and a metavar for every option instead of click's
    TEXT/INTEGER/[a|b] type names."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        for param in self.params:
            if isinstance(param, click.Option) and not param.is_flag and param.metavar is None:
                param.metavar = _metavar(param)

    def format_help(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        self.format_usage(ctx, formatter)
        self.format_help_text(ctx, formatter)
        arguments = [p for p in self.params if isinstance(p, Argument)]
        rows = [(a.human_readable_name, (a.help or "") + ("  [required]" if a.required else "")) for a in arguments]
        if rows:
            with formatter.section("Arguments"):
                formatter.write_dl(rows)
        self.format_options(ctx, formatter)
        self.format_epilog(ctx, formatter)


# Each command and the module of modc.cli that registers it, in the order `modc --help` lists them
# (not alphabetically). A command's module is imported when the command runs: `modc lint` builds
# no other command's options (benchmarks/bench_startup.py).
COMMANDS = {
    "check": "analysis", "dh2mod": "analysis", "dh": "analysis", "compile": "compile", "design": "design_cmd",
    "lsp": "info", "schema": "info", "codes": "info", "backends": "info", "lint": "lint", "fmt": "lint",
    "sim": "motion", "render": "motion", "play": "motion", "plan": "motion", "view": "view",
}


def load_commands() -> None:
    """Every command registered, in COMMANDS' order."""
    import importlib

    for module in dict.fromkeys(COMMANDS.values()):
        importlib.import_module(f"{__package__}.{module}")
    ordered = {name: app.commands[name] for name in COMMANDS if name in app.commands}
    ordered.update(app.commands)
    app.commands.clear()
    app.commands.update(ordered)


class Group(click.Group):
    """`modc`: every module of modc.cli registers its commands here; `modc --help` lists them in
    COMMANDS' order."""

    command_class = Command

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        if cmd_name not in self.commands and cmd_name in COMMANDS:
            import importlib

            importlib.import_module(f"{__package__}.{COMMANDS[cmd_name]}")
        return super().get_command(ctx, cmd_name)

    def list_commands(self, ctx: click.Context) -> list[str]:
        load_commands()
        return list(self.commands)


def _version(ctx: click.Context, _param: click.Parameter, value: bool) -> None:
    if value and not ctx.resilient_parsing:
        print(f"modc {__version__}")
        ctx.exit()


app = Group(
    "modc",
    no_args_is_help=True,
    context_settings={"show_default": True},
    params=[
        click.Option(["--version"], is_flag=True, expose_value=False, is_eager=True, callback=_version,
                     help="print the version")
    ],
    help="modc: compile .mod files describing MOIRs Mark-2 modular arms into URDF and friends.\n\n"
    "\b\n`modc FILE -o OUT` is `modc compile FILE -o OUT`: check FILE (.mod or its YAML form)\n"
    "and write URDF, meshes, xacro, SRDF and a ROS package into OUT.",
)


def argument(name: str, help: str, **attrs: Any):
    """A positional argument of a command, with its help line."""
    return click.argument(name, cls=Argument, help=help, **attrs)


library_option = click.option(
    "--library",
    metavar="NAME|FILE",
    help="module library: a built-in name (mark2, mark2-strict) or a YAML file; overrides `library` in the file",
)


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
    "toppra": "toppra",
}
SOURCE_SUFFIXES = (".mod", ".yaml", ".yml")


def missing_extra(e: ModuleNotFoundError, command: str) -> str | None:
    """One line for a command that needs a module of the `full` extra; None for any other module
    (a real bug, which keeps its traceback)."""
    root = (e.name or "").split(".")[0]
    if root not in HEAVY:
        return None
    package = f"{root} (pip package {HEAVY[root]})" if HEAVY[root] != root.lower() else root
    # modc is not on PyPI: the extra is installed from the checkout (or the wheel) modc came from
    return (f"modc {command}: needs {package}, which the light install leaves out: "
            "pip install 'CHECKOUT[full]' (or the wheel, 'modc-VERSION-py3-none-any.whl[full]')")


def route(args: list[str], commands: list[str]) -> list[str] | str:
    """The arguments for the click group, or an error line. A first word that is no command is a
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


def run(argv: list[str]) -> None:
    """The `modc` entry point: route, then run the click group."""
    routed = route(argv, list(dict.fromkeys([*COMMANDS, *app.commands])))
    if isinstance(routed, str):
        _err(routed)
        raise SystemExit(EXIT_USAGE)
    try:
        app.main(args=routed, prog_name="modc")
    except ModuleNotFoundError as e:
        line = missing_extra(e, routed[0] if routed else "")
        if line is None:
            raise
        _err(line)
        raise SystemExit(EXIT_USAGE) from None
