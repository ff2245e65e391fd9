"""Rigid-body inertials of URDF links, combined from parts by the parallel-axis theorem."""
from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from .parts import Part


@dataclass(frozen=True)
class Inertial:
    mass: float
    com: np.ndarray  # (3,), link frame
    inertia: np.ndarray  # (3, 3) about com, link frame axes


@lru_cache(maxsize=512)
def _local(part: Part) -> Inertial:
    """The part's inertial in its own frame: constant, so computed once per part."""
    vols = np.array([p.volume for p in part.primitives])
    masses = part.mass * vols / vols.sum()
    return combine([Inertial(m, np.array(prim.center), prim.inertia(m)) for prim, m in zip(part.primitives, masses)])


def part_inertial(part: Part, T_link_part: np.ndarray) -> Inertial:
    """A part's inertial in the link frame; its mass is spread over its primitives by volume."""
    local = _local(part)
    R, p = T_link_part[:3, :3], T_link_part[:3, 3]
    return Inertial(local.mass, R @ local.com + p, R @ local.inertia @ R.T)


def combine(items: list[Inertial]) -> Inertial:
    M = sum(i.mass for i in items)
    com = sum(i.mass * i.com for i in items) / M
    I = np.zeros((3, 3))
    for i in items:
        d = i.com - com
        I += i.inertia + i.mass * (d @ d * np.eye(3) - np.outer(d, d))
    return Inertial(M, com, 0.5 * (I + I.T))


def sphere(mass: float, radius: float, center) -> Inertial:
    return Inertial(mass, np.asarray(center, dtype=float), np.eye(3) * 0.4 * mass * radius * radius)
