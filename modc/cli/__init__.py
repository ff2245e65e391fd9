"""Command line: `modc FILE -o OUT`, `modc lint`, `check`, `dh2mod`, `dh`, `sim`, `render`, `play`,
`plan`, `view`, `design`, `fmt`, `lsp`, `schema`, `codes`, `backends`.

Exit codes: 0 success, 1 diagnostics with errors (or a failed check), 2 usage or I/O error. Heavy
libraries (numpy, jinja2, trimesh, pinocchio, pybullet…) are imported inside commands, never at start-up.
"""
from __future__ import annotations

import sys

# each module registers its commands; import order is the order `modc --help` lists them in
from . import analysis, compile, design_cmd, info, lint, motion, view  # noqa: F401, I001
from .app import app

__all__ = ["app", "main"]


def main(argv: list[str] | None = None) -> None:
    from .app import run

    run(list(sys.argv[1:] if argv is None else argv))
