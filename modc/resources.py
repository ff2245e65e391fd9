"""Where the data directories (grammar, templates, libraries) live, installed or in a checkout."""
from __future__ import annotations

from functools import cache
from pathlib import Path

_PKG = Path(__file__).resolve().parent


@cache
def data_dir(name: str) -> Path:
    # A wheel carries them under modc/_data; an editable install or a checkout has them at the root.
    for base in (_PKG / "_data", _PKG.parent):
        p = base / name
        if p.is_dir():
            return p
    raise FileNotFoundError(f"modc data directory '{name}' is missing from the installation")
