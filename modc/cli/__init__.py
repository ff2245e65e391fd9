"""Command line: `modc FILE -o OUT`, `modc lint`, `check`, `dh2mod`, `dh`, `sim`, `render`, `play`,
`plan`, `view`, `design`, `fmt`, `lsp`, `schema`, `codes`, `backends`.

Exit codes: 0 success, 1 diagnostics with errors (or a failed check), 2 usage or I/O error. Heavy
libraries (numpy, jinja2, trimesh, pinocchio, pybullet…) are imported inside commands, never at start-up;
a plain `modc lint` or `modc FILE -o OUT` command line does not even import click
(modc.cli.lint_run, modc.cli.compile_run).
"""
from __future__ import annotations

import sys
import types
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .app import app

__all__ = ["app", "command", "main"]


class _Package(types.ModuleType):
    """`modc.cli.app` is the click group (with every command registered), as it always was, not
    the module modc/cli/app.py, whichever is imported first: the import system's binding of the
    submodule here is set aside."""

    @property
    def app(self):
        from .app import app as group
        from .app import load_commands

        load_commands()
        return group

    @app.setter
    def app(self, _module) -> None:
        pass


sys.modules[__name__].__class__ = _Package


def main(argv: list[str] | None = None) -> None:
    """The `modc` command: each command's module is imported only when it runs (app.COMMANDS)."""
    args = list(sys.argv[1:] if argv is None else argv)
    if args == ["--version"]:  # what the group's --version prints, without loading click
        from .. import __version__

        print(f"modc {__version__}")
        raise SystemExit(0)
    if args[:1] == ["lint"]:
        from .lint_run import plain_args, run_plain

        options = plain_args(args[1:])
        if options is not None:
            run_plain(options)
    elif args:
        _compile_plain(args)
    from .app import run

    run(args)


def command() -> None:
    """The installed `modc` command and `python -m modc`: main(), then, once every exit handler
    has run and the output is flushed, the process ends without Python's finalization, which
    tore down numpy, jinja2 and modc's modules object by object: ~45 ms of CPU after a compile's
    work was done (benchmarks/bench_startup.py). A command that leaves a thread running, a
    non-numeric exit, or output that cannot be flushed ends the usual way."""
    try:
        main()
    except SystemExit as e:
        _end(e.code)
        raise


def _end(code: object) -> None:
    import threading

    if not (code is None or isinstance(code, int)) or threading.active_count() > 1:
        return
    if sys.getprofile() is not None or sys.gettrace() is not None:  # cProfile, coverage: they write at exit
        return
    import atexit
    import os

    atexit._run_exitfuncs()  # the caches written at exit (the records' compiled __init__s), as at a normal exit
    try:
        sys.stdout.flush()
        sys.stderr.flush()
    except (OSError, ValueError):  # a closed pipe: Python reports it as it always did
        return
    os._exit(code or 0)


def _compile_plain(args: list[str]) -> None:
    """`modc [compile] FILE -o OUT ...` without click when its command line is plain
    (modc.cli.compile_run); returns when it is not (click reads it)."""
    from .common import COMMANDS, looks_like_path

    if args[0] == "compile":
        args = args[1:]
    elif args[0] in COMMANDS or args[0].startswith("-") or not looks_like_path(args[0]):
        return
    from .compile_run import plain_args, run

    options = plain_args(args)
    if options is not None:
        from .common import run_like_click

        run_like_click(run, options, "compile")
        raise SystemExit(0)  # as click ends a command that returned
