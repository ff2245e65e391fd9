"""A large shape searched by complexity level, closed by a dominance bound.

Within a shape the settings kept (search.KEEP of them) are the smallest by search.order_key,

    key(s) = (round(worst(s), 2), c(s), sum |angles|, values),

c(s) the number of nonzero twists. A shape whose live families (modc.design.prefix) hold more
than FIRST settings is enumerated *level by level*: level c is every live setting with
exactly c nonzero twists (each choice of c axes set to their nonzero values, the others 0),
levels 0, 1, 2, … in turn, each through the per-setting bounds and the IK screen as usual.

Dominance (sound, exact for the ranking): suppose every level <= c is done and the kept list
holds KEEP feasible settings whose first key is 0.0 (round(worst, 2) == 0.0, the least possible
value: worst >= 0). Let k* be the KEEP-th of them; k* = (0.0, c', …) with c' <= c. Any setting s
of a level >= c + 1 has key(s) = (r, c(s), …) with r >= 0.0 and c(s) >= c + 1 > c':
if r > 0.0 then key(s) > k* on the first entry, else they tie on it and key(s) > k* on the
second. So key(s) > k* strictly (no tie to break: the keys' last entry, the values, tells any
two settings apart), and s could never be among the KEEP smallest - the list sorted over every
setting of the shape equals the list sorted over levels <= c. The rest of the shape (every live
setting of the higher levels) is excluded by that bound, counted as `dominated`, and the shape
is complete. Nothing else a shape reports changes: with KEEP feasible settings every target is
reached clear (hit, clear) and its closest distance is 0.

Without KEEP such settings after level c the next level is searched while the settings listed
so far stay within search.COMPLETE; past that the settings above the last level done are
searched on the shape's coarse grid and the shape is reported not complete (as before levels).

Scheduling: the decision needs a whole level done, so levels go out in rounds: the first round
holds the lowest levels up to FIRST settings (usually levels 0-2), each later round one level
(its units of work at most search.WORK settings each). Every unit is a slice of a level list
sorted by setting number: a pure function of (spec, shape, levels, slice), as before.
"""
from __future__ import annotations

import itertools
import math
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

FIRST = 65_536  # settings of the lowest levels searched in a shape's first round


@dataclass(frozen=True)
class Levels:
    """Live settings of a shape by level: the twist axes (values per axis, index of the value 0,
    -1 if none), the live families (prefix.Families over the first `head` axes), and the count
    of live settings per level."""

    lengths: tuple[int, ...]
    zero: tuple[int, ...]
    head: int  # axes fixed by a family's number
    alive: np.ndarray | None  # live family numbers, sorted (None: dropped, the counts kept)
    per: int  # settings per family
    nz_alive: np.ndarray | None  # nonzero twists among each live family's head axes
    counts: tuple[int, ...]  # live settings per level 0 … len(lengths)

    def light(self) -> Levels:
        return Levels(self.lengths, self.zero, self.head, None, self.per, None, self.counts)


def _poly(lengths, zero) -> list[int]:
    """Coefficient m: settings of these axes with exactly m nonzero twists."""
    out = [1]
    for n, z in zip(lengths, zero, strict=True):
        nonzero, zeros = n - (z >= 0), int(z >= 0)
        out = [(out[m] if m < len(out) else 0) * zeros + (out[m - 1] if m >= 1 else 0) * nonzero
               for m in range(len(out) + 1)]
    return out


def levels_of(values: tuple[np.ndarray, ...], alive: np.ndarray, per: int) -> Levels:
    lengths = tuple(len(a) for a in values)
    zero = tuple(int(np.flatnonzero(np.abs(a) <= 1e-9)[0]) if np.any(np.abs(a) <= 1e-9) else -1 for a in values)
    head = next(h for h in range(len(lengths) + 1) if math.prod(lengths[h:]) == per)
    alive = np.asarray(alive, np.int64)
    nz = np.zeros(len(alive), np.int8)  # a few bytes a family: plans of hundreds of shapes are in memory at once
    if head:
        digits = np.unravel_index(alive, lengths[:head])
        for d, z in zip(digits, zero[:head], strict=True):
            nz += d != z
    tail = _poly(lengths[head:], zero[head:])
    per_p = np.bincount(nz, minlength=head + 1) if len(nz) else np.zeros(head + 1, np.int64)
    counts = [sum(int(per_p[p]) * tail[c - p] for p in range(head + 1) if 0 <= c - p < len(tail))
              for c in range(len(lengths) + 1)]
    return Levels(lengths, zero, head, alive, per, nz, tuple(counts))


def _tail_numbers(lv: Levels, m: int) -> np.ndarray:
    """Numbers (over the tail axes) of the tail settings with exactly m nonzero twists, sorted."""
    lengths, zero = lv.lengths[lv.head:], lv.zero[lv.head:]
    must = [a for a, z in enumerate(zero) if z < 0]
    optional = [a for a, z in enumerate(zero) if z >= 0]
    if m < len(must) or m - len(must) > len(optional):
        return np.zeros(0, np.int64)
    out = []
    for chosen in itertools.combinations(optional, m - len(must)):
        on = set(chosen) | set(must)
        grids = [np.array([i for i in range(n) if i != z], np.int64) if a in on else np.array([z], np.int64)
                 for a, (n, z) in enumerate(zip(lengths, zero, strict=True))]
        mesh = np.meshgrid(*grids, indexing="ij") if grids else []
        out.append(np.ravel_multi_index(tuple(g.ravel() for g in mesh), lengths) if grids else np.zeros(1, np.int64))
    return np.sort(np.concatenate(out)).astype(np.int64) if out else np.zeros(0, np.int64)


def level_numbers(lv: Levels, c: int) -> np.ndarray:
    """The live settings of level c as the shape's setting numbers, ascending."""
    assert lv.alive is not None and lv.nz_alive is not None
    out = []
    for p in np.unique(lv.nz_alive).tolist():
        m = c - p
        if m < 0:
            continue
        tail = _tail_numbers(lv, m)
        if len(tail):
            fams = lv.alive[lv.nz_alive == p]
            out.append((fams[:, None] * lv.per + tail[None]).ravel())
    if not out:
        return np.zeros(0, np.int64)
    return np.sort(np.concatenate(out))


_CACHE: OrderedDict = OrderedDict()  # (id(owner), how) -> (owner, numbers): a worker slices one list many times


def numbers(owner, how, make) -> np.ndarray:
    """make() once per (owner, how) in this process (the last few kept)."""
    key = (id(owner), how)
    entry = _CACHE.get(key)
    if entry is None or entry[0] is not owner:
        entry = _CACHE[key] = (owner, make())
        while len(_CACHE) > 4:
            _CACHE.popitem(last=False)
    _CACHE.move_to_end(key)
    return entry[1]


def dominates(found, keep: int) -> bool:
    """The kept list closes the shape (see the module's docstring): keep settings whose rounded
    worst share, the first entry of their key, is 0.0."""
    return len(found) >= keep and all(round(f.worst, 2) == 0.0 for f in found[:keep])


def first_round(lv: Levels, budget: int) -> tuple[int, int] | None:
    """The levels (lo, hi) of the first round: from the lowest level holding live settings up to
    FIRST settings (at least that level, if the budget allows it); None when even that level is
    over the budget (the coarse grid then)."""
    live = [c for c, n in enumerate(lv.counts) if n]
    if not live:
        return None
    lo = hi = live[0]
    if lv.counts[lo] > budget:
        return None
    total = lv.counts[lo]
    while hi + 1 < len(lv.counts) and total + lv.counts[hi + 1] <= FIRST:
        hi += 1
        total += lv.counts[hi]
    return lo, hi


def next_level(lv: Levels, done: int, budget: int) -> int | None:
    """The next level with live settings above `done` if it fits in the budget with the levels
    done; None when no level is left; -1 when the next one would pass the budget."""
    listed = sum(lv.counts[:done + 1])
    for c in range(done + 1, len(lv.counts)):
        if lv.counts[c]:
            return c if listed + lv.counts[c] <= budget else -1
    return None


def decide(lv: Levels, first: tuple, done: dict, kept: Callable[[list], list], length: Callable[[tuple], int],
           keep: int, budget: int) -> tuple[tuple | None, int, bool, bool]:
    """What a shape searched by level needs next, from the rounds done (how -> settings done in
    whole units; kept(rounds): the kept list over those rounds; length(how): a round's settings):
    (the next round or None, settings dominated, complete, finished). The rounds run in a fixed
    chain - the first, then one level at a time, maybe the coarse rest - and a decision is taken
    only on whole rounds, so it is the same however the units were spread over workers."""
    if any(n != length(h) for h, n in done.items()):
        return None, 0, False, False
    chain: list[tuple] = [first]
    while chain[-1] in done and chain[-1][0] == "levels":
        top = chain[-1][2]
        whole = set(done) == set(chain)
        if dominates(kept(chain), keep):
            return None, (sum(lv.counts[top + 1:]) if whole else 0), whole, whole
        c = next_level(lv, top, budget)
        if c is None:
            return None, 0, whole, whole
        chain.append(("levels", c, c) if c >= 0 else ("rest", top))
    if chain[-1] in done:  # the coarse grid above the last level ran: finished, not complete
        return None, 0, False, set(done) == set(chain)
    if set(done) != set(chain[:-1]):
        return None, 0, False, False
    return chain[-1], 0, False, False
