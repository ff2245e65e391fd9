"""The backend registry: each backend module registers its emit function here, by name.

Backends import this module (and build, common, format, templates), never the package or each
other: `modc.backends.load_all` imports every backend, so a backend importing the package would
depend on all the others (the independence contract in pyproject.toml). A backend that reads
another's outputs from the build (ros installs mjcf/ when the mjcf backend ran) says so in
``reads``; load_all checks that it runs after them.
"""
from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from ..records import Record

if TYPE_CHECKING:  # the physical description (numpy) loads with the first backend, not the registry
    from .build import Build

Files = dict[str, "str | bytes"]


class Backend(Record, kw_only=False):
    name: str
    summary: str
    emit: Callable[[Build], Files]
    heavy: bool = False  # needs more than the core (meshes: trimesh on a cache miss)
    reads: tuple[str, ...] = ()  # backends whose outputs this one reads from build.files, when they ran


BACKENDS: dict[str, Backend] = {}


def register(name: str, summary: str, heavy: bool = False, reads: tuple[str, ...] = ()):
    def deco(fn: Callable[[Build], Files]):
        BACKENDS[name] = Backend(name, summary, fn, heavy, reads)
        return fn

    return deco


def check_order(backends: dict[str, Backend]) -> None:
    """Every backend runs after the ones it reads (the dict's order is the run order)."""
    seen: set[str] = set()
    for b in backends.values():
        late = [r for r in b.reads if r in backends and r not in seen]
        if late:
            raise RuntimeError(f"backend {b.name} reads {', '.join(late)} but runs before it")
        seen.add(b.name)
