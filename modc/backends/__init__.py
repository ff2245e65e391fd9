"""Backends: registered by name; each turns a checked design into {relative path: content}.

A new backend is one module here (plus its templates) that calls ``registry.register``; what it
shares with other backends lives in common.py, never in another backend.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any

from .registry import BACKENDS, Backend, Files, check_order, register

if TYPE_CHECKING:
    from .build import Build


def __getattr__(name: str) -> Any:
    # Build (and with it the physical description and numpy) is imported when first used, so that
    # a compile served from modc's cache (modc.compiler.build_cached) and the ROS option check
    # (ros_target) load neither
    if name == "Build":
        from .build import Build

        return Build
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


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
