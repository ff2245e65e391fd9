"""Backends: registered by name; each turns a checked design into {relative path: content}.

A new backend is one module here (plus its templates) that calls ``register``.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

from .build import Build

Files = dict[str, "str | bytes"]


@dataclass(frozen=True)
class Backend:
    name: str
    summary: str
    emit: Callable[[Build], Files]
    heavy: bool = False  # needs more than the core (meshes: trimesh on a cache miss)


BACKENDS: dict[str, Backend] = {}


def register(name: str, summary: str, heavy: bool = False):
    def deco(fn: Callable[[Build], Files]):
        BACKENDS[name] = Backend(name, summary, fn, heavy)
        return fn

    return deco


def load_all() -> dict[str, Backend]:
    # Registration happens on import, in run order: later backends may read earlier outputs
    # (ros installs mjcf/ when the mjcf backend ran); report runs last so that it lists every output.
    # The order of these imports is the run order: not sorted on purpose.
    from . import meshes, urdf  # noqa: F401, I001
    from . import srdf  # noqa: F401
    from . import mjcf  # noqa: F401
    from . import ros  # noqa: F401
    from . import xacro  # noqa: F401
    from . import report  # noqa: F401

    return BACKENDS


__all__ = ["BACKENDS", "Backend", "Build", "Files", "register", "load_all"]
