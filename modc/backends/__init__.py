"""Backends: registered by name; each turns a checked design into {relative path: content}.

A new backend is one module here (plus its templates) that calls ``registry.register``; what it
shares with other backends lives in common.py, never in another backend.
"""
from __future__ import annotations

from .build import Build
from .registry import BACKENDS, Backend, Files, check_order, register


def load_all() -> dict[str, Backend]:
    # Registration happens on import, in run order: a backend that reads another's outputs declares
    # it (`reads`) and check_order enforces it; report runs last so that it lists every output.
    # The order of these imports is the run order: not sorted on purpose.
    from . import meshes, urdf  # noqa: F401, I001
    from . import srdf  # noqa: F401
    from . import mjcf  # noqa: F401
    from . import ros  # noqa: F401
    from . import xacro  # noqa: F401
    from . import report  # noqa: F401

    check_order(BACKENDS)
    return BACKENDS


__all__ = ["BACKENDS", "Backend", "Build", "Files", "register", "load_all"]
