"""Rigid-body inertials of URDF links, combined from parts by the parallel-axis theorem."""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..records import Record
from .parts import Part


class Inertial(Record, kw_only=False):
    mass: float
    com: np.ndarray  # (3,), link frame
    inertia: np.ndarray  # (3, 3) about com, link frame axes


@lru_cache(maxsize=512)
def local_inertial(part: Part) -> Inertial:
    """The part's inertial in its own frame (its mass spread over its primitives by volume):
    constant, so computed once per part."""
    vols = np.array([p.volume for p in part.primitives])
    masses = part.mass * vols / vols.sum()
    return combine([Inertial(m, np.array(prim.center), prim.inertia(m))
                    for prim, m in zip(part.primitives, masses, strict=True)])


def moved(local: Inertial, T_link_part: np.ndarray) -> Inertial:
    """An inertial given in a part's frame, in the link frame."""
    R, p = T_link_part[:3, :3], T_link_part[:3, 3]
    return Inertial(local.mass, R @ local.com + p, R @ local.inertia @ R.T)


def part_inertial(part: Part, T_link_part: np.ndarray) -> Inertial:
    """A part's inertial in the link frame."""
    return moved(local_inertial(part), T_link_part)


_EYE3 = np.eye(3)


def combine(items: list[Inertial]) -> Inertial:
    """One rigid body of several: total mass, mass centre, inertia about it (parallel axes)."""
    return combine_groups(np.array([i.mass for i in items]), np.array([i.com for i in items]),
                          np.array([i.inertia for i in items]), [0])[0]


def combine_groups(m: np.ndarray, C: np.ndarray, inertia: np.ndarray, starts: list[int]) -> list[Inertial]:
    """combine() of consecutive groups of items at once (group g: items starts[g] to the next
    start): masses (k,), mass centres (k, 3), inertias about them (k, 3, 3). Vectorised over the
    groups; the sums run over the items in order, from 0, as a loop over one group's items would
    (so results do not depend on how the items are batched; describe() is on the design search's
    hot path)."""
    G, k = len(starts), len(m)
    sizes = np.diff([*starts, k])
    group = np.repeat(np.arange(G), sizes)
    pos = np.arange(k) - np.repeat(starts, sizes)
    # items laid out per group, padded with zeros (adding 0.0 changes no sum)
    pad_m = np.zeros((G, int(sizes.max())))
    pad_m[group, pos] = m
    pad_mC = np.zeros((*pad_m.shape, 3))
    pad_mC[group, pos] = m[:, None] * C
    M, mC = np.zeros(G), np.zeros((G, 3))
    for j in range(pad_m.shape[1]):
        M += pad_m[:, j]
        mC += pad_mC[:, j]
    com = mC / M[:, None]
    d = C - com[group]
    dd = (d[:, None, :] @ d[:, :, None])[:, 0, 0]  # row by row d @ d, rounded as a loop of d @ d is
    pad_I = np.zeros((*pad_m.shape, 3, 3))
    pad_I[group, pos] = inertia + m[:, None, None] * (dd[:, None, None] * _EYE3 - d[:, :, None] * d[:, None, :])
    S = np.zeros((G, 3, 3))
    for j in range(pad_m.shape[1]):
        S += pad_I[:, j]
    S = 0.5 * (S + S.transpose(0, 2, 1))
    return [Inertial(float(M[g]), com[g], S[g]) for g in range(len(starts))]


def sphere(mass: float, radius: float, center) -> Inertial:
    return Inertial(mass, np.asarray(center, dtype=float), np.eye(3) * 0.4 * mass * radius * radius)
