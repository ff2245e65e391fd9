"""A shape's twist settings: the values of each twist axis (every realisable one, or a coarse
grid of them), and the numbering of the settings - unit by unit, unit 1's pivot outermost, then
its port, unit 2's pivot, … - that the search's ranges of work and the dominance levels index."""
from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from .evaluate import Spec
from .space import Shape, port_free, twist_values

COARSE = 2048  # settings on the coarse grid of a shape too large to enumerate


def coarse_index(count: int, i0: int, stride: int) -> list[int]:
    """Every stride-th index counted from i0 (the value nearest 0 stays in)."""
    return [i for i in range(count) if (i - i0) % stride == 0]


@dataclass(frozen=True)
class Axes:
    """The twist values per axis, unit by unit (its pivot, then its port when that matters),
    which twist each axis sets, and whether they are every realisable value (not a coarse grid)."""

    values: tuple[np.ndarray, ...]
    roles: tuple[tuple[str, int], ...]  # ("pivot" | "port", position)
    full: bool

    @property
    def count(self) -> int:
        return math.prod(len(a) for a in self.values)


def full_axes(spec: Spec, shape: Shape) -> Axes:
    lib = spec.problem.cell.library
    pivot_set, port_set = twist_values(lib.twists.pivot), twist_values(lib.twists.port)
    free = port_free(spec.problem, shape, lib)
    values: list[np.ndarray] = []
    roles: list[tuple[str, int]] = []
    for i in range(shape.n):
        values.append(pivot_set)
        roles.append(("pivot", i))
        if free[i]:
            values.append(port_set)
            roles.append(("port", i))
    return Axes(tuple(values), tuple(roles), True)


def coarse_axes(spec: Spec, shape: Shape) -> Axes:
    ax = full_axes(spec, shape)
    zero = [int(np.argmin(np.abs(a))) for a in ax.values]
    steps = _strides(tuple(len(a) for a in ax.values), tuple(zero))
    return Axes(tuple(a[coarse_index(len(a), z, s)] for a, z, s in zip(ax.values, zero, steps, strict=True)),
                ax.roles, False)


def axes(spec: Spec, shape: Shape, full: bool = True) -> Axes:
    """The axes a unit of work enumerates (cheap: no bound is computed)."""
    return full_axes(spec, shape) if full else coarse_axes(spec, shape)


@functools.lru_cache(maxsize=256)
def _strides(lengths: tuple[int, ...], zero: tuple[int, ...]) -> tuple[int, ...]:
    """Strides that thin the axes evenly (the longest first) until at most COARSE settings remain."""
    strides = [1] * len(lengths)

    def count(j: int) -> int:
        return (lengths[j] - 1 - zero[j] % strides[j]) // strides[j] + 1

    while math.prod(count(j) for j in range(len(lengths))) > COARSE:
        k = max(range(len(lengths)), key=lambda j: (count(j), -j))
        strides[k] += 1
    return tuple(strides)


def range_settings(ax: Axes, n: int, lo: int, hi: int) -> tuple[np.ndarray, np.ndarray]:
    return settings_at(ax, n, np.arange(lo, hi))


def settings_at(ax: Axes, n: int, numbers: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    idx = np.unravel_index(numbers, [len(a) for a in ax.values])
    pivots = np.zeros((len(numbers), n))
    ports = np.zeros((len(numbers), n))
    for a, i, (role, pos) in zip(ax.values, idx, ax.roles, strict=True):
        (pivots if role == "pivot" else ports)[:, pos] = a[i]
    return pivots, ports
