"""Command line: `modc FILE -o OUT`, `modc lint`, `check`, `dh2mod`, `dh`, `sim`, `render`, `play`,
`plan`, `design`, `fmt`, `lsp`, `schema`, `codes`, `backends`.

Exit codes: 0 success, 1 diagnostics with errors (or a failed check), 2 usage or I/O error. Heavy
libraries (numpy, jinja2, trimesh, pinocchio, pybullet…) are imported inside commands, never at start-up.
"""
from __future__ import annotations

import sys
from typing import Annotated

import typer

from .. import __version__
# each module registers its commands; import order is the order `modc --help` lists them in
from . import compile, lint, analysis, motion, info, design_cmd  # noqa: F401, I001
from .app import app

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
