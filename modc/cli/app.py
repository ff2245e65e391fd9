"""The click group and what every command shares: output, exit codes, common options."""

from __future__ import annotations

import difflib
from collections.abc import Sequence
from typing import Any

import click

from .. import __version__
from .common import (  # noqa: F401 - the commands' modules import them from here
    COMMANDS,
    EXIT_ERRORS,
    EXIT_OK,
    EXIT_USAGE,
    Verbosity,
    _err,
    _expand,
    _print_diagnostics,
    looks_like_path,
    missing_extra,
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

def route(args: list[str], commands: list[str]) -> list[str] | str:
    """The arguments for the click group, or an error line. A first word that is no command is a
    file to compile (`modc FILE -o OUT`) when it looks like one (it exists, or has a source suffix
    or a path separator); any other word is a mistyped command."""
    if not args or args[0].startswith("-") or args[0] in commands:
        return args
    word = args[0]
    if looks_like_path(word):
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
