"""Command line: `modc FILE -o OUT`, `modc lint`, `check`, `dh2mod`, `dh`, `sim`, `render`, `play`,
`plan`, `view`, `design`, `fmt`, `lsp`, `schema`, `codes`, `backends`.

Exit codes: 0 success, 1 diagnostics with errors (or a failed check), 2 usage or I/O error. Heavy
libraries (numpy, jinja2, trimesh, pinocchio, pybullet…) are imported inside commands, never at start-up.
"""
from __future__ import annotations

import sys
from typing import TYPE_CHECKING

from . import app as _app_module

if TYPE_CHECKING:
    from .app import app

__all__ = ["app", "main"]
# `modc.cli.app` is the click group (with every command registered), as it always was, not the
# module that the import above bound here: see __getattr__.
del app  # noqa: F821


def __getattr__(name: str):
    if name == "app":
        _app_module.load_commands()
        globals()["app"] = _app_module.app
        return _app_module.app
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def main(argv: list[str] | None = None) -> None:
    """The `modc` command: each command's module is imported only when it runs (app.COMMANDS)."""
    _app_module.run(list(sys.argv[1:] if argv is None else argv))
