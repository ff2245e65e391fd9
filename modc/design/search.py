"""The twist search of one shape: every pivot and port setting, in blocks.

Complete within its bounds: every setting of a shape is either screened (batched IK per target
within the joint limits, then the obstacle screen) or excluded by a sound bound - whole families
of settings at once (modc.design.prefix: a prefix of the chain fixed, the rest free), then
setting by setting (modc.design.bounds: no joint vector, limits or not, brings tool0 within
tolerance of some target, or meets its orientation with its position - bounds.posed, first; for
2- and 3-joint chains modc.design.bounds_exact decides the position to within 0.5 mm, and
modc.design.bounds_tilt the position and an orientation's tilt at one joint vector). Exact reductions
(modc.design.space) remove settings that cannot change tool0. A shape whose families left alive
hold more than dominance.FIRST settings is searched level by level - fewest nonzero twists first
- and closed by a dominance bound as soon as its kept settings cannot be beaten by any setting
left (modc.design.dominance); only when the levels listed would pass COMPLETE settings are the
levels left searched on a deterministic coarse grid of its twists, and the shape reported as not
complete.

A shape's settings are numbered unit by unit (unit 1's pivot outermost, then its port, unit 2's
pivot, …); a unit of work is a range of those numbers (WORK settings), so a large shape spreads
over many workers. Everything here is a
function of (spec, shape, range, seed): the same inputs give the same answer in any process.
Within a shape the settings are ordered by how deep inside the tolerances their worst target
lies, then simplest twists first.
"""
from __future__ import annotations

import hashlib
import threading
import time
import weakref
import zlib
from collections import OrderedDict
from dataclasses import dataclass, field, replace

import numpy as np

from ..kinematics import transform
from . import bounds, bounds_exact, bounds_tilt, dominance, prefix
from .batch import geometry
from .evaluate import Spec, screen_batch
from .settings import COARSE, Axes, axes, coarse_axes, full_axes, settings_at
from .space import Shape, port_free, twist_values

COMPLETE = 2_000_000  # settings of a shape searched in full up to this many
BLOCK = 4096  # settings screened together (numpy amortisation)
WORK = 65536  # settings per unit of work
ORIENTED = True  # the orientation bounds (bounds.posed) screen settings before the IK (off: tests compare)
TILTED = True  # 2- and 3-joint chains, oriented targets: position and tilt at once (bounds_tilt; off: tests compare)
EXACT = True  # 2- and 3-joint chains: the exact reach test (bounds_exact) after bounds.possible (off: tests compare)
KEEP = 6  # feasible twist settings kept per shape (deepest inside the tolerances, then simplest)

STOP = threading.Event()  # set by Ctrl-C in this process: blocks end at the next boundary
TICK: list = []  # callbacks after each block, in this process only (the progress display's heartbeat)


@dataclass(frozen=True)
class Found:
    pivots: tuple[float, ...]
    ports: tuple[float, ...]
    solutions: tuple[tuple[tuple[float, ...], ...], ...]  # per target, joint vectors passing the screen
    worst: float = 0.0  # the worst target's error as a share of its tolerance


@dataclass(frozen=True)
class Part:
    """What one unit of work found: its settings (a few ranges of the shape's numbers) are
    numbered lo … hi-1 in their order, done up to `upto`."""

    shape: Shape
    lo: int
    hi: int
    upto: int
    found: tuple[Found, ...]
    screened: int  # settings that went through the IK screen
    excluded: int  # settings ruled out by a sound bound
    closest: tuple[float, ...]  # per target, m (inf: never tried)
    hit: tuple[bool, ...]  # per target: some IK run within tolerance (collisions aside)
    clear: tuple[bool, ...]  # per target: reached without touching the cell
    how: bool | tuple = True  # which list lo … hi index (see Work)


@dataclass
class ShapeResult:
    shape: Shape
    found: tuple[Found, ...]
    evaluated: int  # screened + excluded
    closest: tuple[float, ...]
    best_score: float
    screened: int = 0
    excluded: int = 0  # dominated included
    dominated: int = 0  # settings of levels a dominance bound closed (modc.design.dominance)
    total: int = 0  # settings of the shape (on the coarse grid when not complete)
    complete: bool = True  # every setting screened or excluded
    finished: bool = True  # the search of its settings ran to the end (no budget stop)
    hit: tuple[bool, ...] = ()
    clear: tuple[bool, ...] = ()
    parts: list[Part] = field(default_factory=list)


def shape_seed(seed: int, shape: Shape) -> int:
    return zlib.crc32(f"{seed}:{shape.label()}".encode()) & 0x7FFFFFFF


def _keys(worst, pivots: np.ndarray, ports: np.ndarray) -> list[tuple]:
    """order_key of settings (rows of pivots and ports) with these worst shares, without building
    their Found: simplest first is fewest twists set, then the smallest angles, then the values."""
    vals = np.concatenate([pivots, ports], axis=1)
    count = np.count_nonzero(np.abs(vals) > 1e-9, axis=1)
    total = np.abs(vals).sum(1)
    return [(round(float(w), 2), int(c), round(float(a), 9), tuple(round(float(v), 9) for v in row))
            for w, c, a, row in zip(worst, count, total, vals, strict=True)]


def order_key(f: Found) -> tuple:
    """Deepest inside the tolerances first (to 1 % of a tolerance: IK runs end ~1e-7 m off a
    reachable target, and such differences mean nothing), then simplest."""
    return _keys([f.worst], np.array([f.pivots]), np.array([f.ports]))[0]


@dataclass(frozen=True)
class Plan:
    """How a shape is searched: on which axes, which ranges of their settings (the rest
    excluded whole by modc.design.prefix), and whether that covers every setting."""

    axes: Axes
    ranges: tuple[tuple[tuple[int, int], ...], ...]  # units of work: ranges, at most WORK settings each
    total: int  # settings of the shape (of the coarse grid when not complete)
    excluded: int  # settings excluded whole, before any is listed
    how: bool | tuple = True  # what the ranges index (see Work): a level plan's first round
    levels: dominance.Levels | None = None  # the live settings by level, for a shape searched by level

    @property
    def complete(self) -> bool:
        return self.axes.full


_PLANS: dict[int, tuple[weakref.ref, dict[Shape, Plan], str]] = {}
# a worker gets a new Spec object with each unit of work: the last plans by content, so the units
# of one shape share its family bounds and level lists
_BY_CONTENT: OrderedDict[tuple[str, Shape], Plan] = OrderedDict()


_PROBLEM_TEXT: list[tuple[object, bytes]] = []  # the last few problems and their repr (thousands of region
# points make a repr cost milliseconds, and a diagnosis asks it per target)


def _problem_text(problem) -> bytes:
    for p, text in _PROBLEM_TEXT:
        if p is problem:
            return text
    text = repr(problem).encode()
    _PROBLEM_TEXT[:] = [(problem, text), *_PROBLEM_TEXT[:3]]
    return text


def _digest(spec: Spec) -> str:
    """What a plan depends on: the problem (its library, tool and targets) and the targets screened."""
    tg = spec.targets
    return hashlib.sha256(_problem_text(spec.problem) + tg.xyz.tobytes() + tg.tol_p.tobytes()
                          + np.asarray(tg.oriented).tobytes() + tg.R.tobytes() + tg.tol_r.tobytes()
                          + tg.axis.tobytes() + bytes([prefix.POSED])).hexdigest()


def plan(spec: Spec, shape: Shape) -> Plan:
    """The shape's plan (computed once per spec object in this process, and the last few by
    content)."""
    key = id(spec)
    entry = _PLANS.get(key)
    if entry is None or entry[0]() is not spec:

        def forget(_ref: weakref.ref, key: int = key) -> None:
            _PLANS.pop(key, None)

        entry = (weakref.ref(spec, forget), {}, _digest(spec))
        _PLANS[key] = entry
    cache = entry[1]
    if shape not in cache:
        got = _BY_CONTENT.get((entry[2], shape))
        if got is None:
            got = _BY_CONTENT[(entry[2], shape)] = _plan(spec, shape)
            while len(_BY_CONTENT) > 16:
                _BY_CONTENT.popitem(last=False)
        cache[shape] = got
    return cache[shape]


def _split(ranges: list[tuple[int, int]]) -> tuple[tuple[tuple[int, int], ...], ...]:
    """Ranges grouped into units of at most WORK settings (a long range cut, short ones joined:
    a unit's cost is its settings, not its ranges)."""
    units: list[list[tuple[int, int]]] = []
    room = 0
    for a, b in ranges:
        while a < b:
            if room == 0:
                units.append([])
                room = WORK
            take = min(room, b - a)
            units[-1].append((a, a + take))
            a, room = a + take, room - take
    return tuple(tuple(u) for u in units)


def _plan(spec: Spec, shape: Shape) -> Plan:
    full = full_axes(spec, shape)
    lib = spec.problem.cell.library
    types = [lib.units[k] for k in shape.kinds]
    links = [(x if x is not None else t.x23) for t, x in zip(types, shape.links, strict=True)]
    tool = spec.problem.cell.tool
    free = port_free(spec.problem, shape, lib)
    lv = prefix.levels(types, links, twist_values(lib.twists.pivot), twist_values(lib.twists.port), free,
                       transform(tool.xyz, tool.rpy))
    fam = prefix.refine(lv, spec.targets.xyz, spec.targets.tol_p, tg=spec.targets)
    total = full.count
    if fam.settings <= dominance.FIRST:
        ranges = _split(fam.ranges()) or ((),)
        return Plan(full, ranges, total, total - fam.settings)
    by_level = dominance.levels_of(full.values, fam.alive, fam.per)
    first = dominance.first_round(by_level, COMPLETE)
    if first is not None:
        size_ = sum(by_level.counts[first[0]:first[1] + 1])
        return Plan(full, _split([(0, size_)]), total, total - fam.settings, ("levels", *first), by_level)
    coarse = coarse_axes(spec, shape)
    return Plan(coarse, _split([(0, coarse.count)]), coarse.count, 0)


def size(spec: Spec, shape: Shape) -> int:
    return plan(spec, shape).total


def estimate(spec: Spec, shape: Shape) -> int:
    """The shape's settings before any bound (its coarse grid's when too many): cheap, for
    progress and ordering, where size() would run the family bounds of every shape."""
    full = full_axes(spec, shape)
    return full.count if full.count <= COMPLETE else min(full.count, COARSE)


def _listed(spec: Spec, shape: Shape, how) -> tuple[Axes, np.ndarray | None]:
    """The axes a unit of work enumerates and the setting numbers its ranges index (None: the
    ranges are the numbers). how: True / False - the full axes / the coarse grid; ("levels", lo,
    hi) - the live settings of levels lo … hi, level by level, ascending within one;
    ("rest", c) - the coarse grid's settings above level c."""
    if how is True or how is False:
        return axes(spec, shape, how), None
    p = plan(spec, shape)
    if how[0] == "levels":
        lv = p.levels if p.levels is not None and p.levels.alive is not None else _plan(spec, shape).levels
        assert lv is not None
        return p.axes, dominance.numbers(p, how, lambda: np.concatenate(
            [dominance.level_numbers(lv, c) for c in range(how[1], how[2] + 1)]))
    coarse = coarse_axes(spec, shape)

    def rest() -> np.ndarray:
        every = np.arange(coarse.count, dtype=np.int64)
        piv, por = settings_at(coarse, shape.n, every)
        level = (np.abs(piv) > 1e-9).sum(-1) + (np.abs(por) > 1e-9).sum(-1)
        return every[level > how[1]]

    return coarse, dominance.numbers(p, how, rest)


def search_part(spec: Spec, shape: Shape, ranges: tuple[tuple[int, int], ...], seed: int,
                deadline: float | None = None, full: bool | tuple = True) -> Part:
    """Screen the settings in ranges ([lo, hi) of the shape's numbers on its full axes or its
    coarse grid, or of a list of them: see _listed), BLOCK at a time, until done or the
    deadline (time.time())."""
    ax, listed_ = _listed(spec, shape, full)
    numbers = np.concatenate([np.arange(a, b, dtype=np.int64) for a, b in ranges] or [np.zeros(0, np.int64)])
    if listed_ is not None:
        numbers = listed_[numbers]
    lo, hi = 0, len(numbers)
    lib = spec.problem.cell.library
    types = [lib.units[k] for k in shape.kinds]
    links = [(x if x is not None else t.x23) for t, x in zip(types, shape.links, strict=True)]
    tool = spec.problem.cell.tool
    tg = spec.targets
    T = len(tg.names)
    s0 = shape_seed(seed, shape)
    found: list[Found] = []
    closest = np.full(T, np.inf)
    hit, clear = np.zeros(T, bool), np.zeros(T, bool)
    screened = excluded = 0
    upto = lo

    def interrupted() -> bool:  # between the targets of a block: the heartbeat, Ctrl-C and the budget
        for tick in TICK:
            tick()
        return STOP.is_set() or (deadline is not None and time.time() > deadline)

    for start in range(lo, hi, BLOCK):
        if STOP.is_set() or (deadline is not None and time.time() > deadline):
            break
        end = min(start + BLOCK, hi)
        piv, por = settings_at(ax, shape.n, numbers[start:end])
        g = geometry(types, piv, por, links, tool.xyz, tool.rpy)
        ok = _bounded(bounds.frames(g), tg, shape.n)
        excluded += int((~ok).sum())
        upto = end
        for tick in TICK:
            tick()
        if not ok.any():
            continue
        k = np.flatnonzero(ok)
        sub = g.take(k)
        s = screen_batch(spec, shape, piv[k], por[k], s0, g=sub, interrupted=interrupted)
        if s is None:  # stopped inside the block: it counts as not searched
            upto = start
            excluded -= int((~ok).sum())
            break
        screened += len(k)
        closest = np.minimum(closest, s.closest.min(0))
        hit |= s.hit.any(0)
        clear |= s.reached.any(0)
        found = _keep(found, s, piv[k], por[k])
    return Part(shape, lo, hi, upto, tuple(found), screened, excluded, tuple(float(x) for x in closest),
                tuple(bool(x) for x in hit), tuple(bool(x) for x in clear), full)


def _bounded(f: bounds.Frames, tg, n: int) -> np.ndarray:
    """(C,) the settings of f no sound bound rules out for the targets tg, cheapest tests first."""
    # the orientation bounds first where they apply: cheaper per setting, and most settings fail them
    ok = bounds.posed(f, tg, every=True) if ORIENTED and tg.oriented.any() else np.ones(len(f.t), bool)
    if ok.any():
        ok[ok] = bounds.possible(bounds.Frames(f.R[ok], f.t[ok]), tg.xyz, tg.tol_p).all(-1)
    if EXACT and n in (2, 3) and ok.any():  # most settings the interval bounds keep miss a target
        ok[ok] = bounds_exact.prune(bounds.Frames(f.R[ok], f.t[ok]), tg.xyz, tg.tol_p)
    if TILTED and ORIENTED and n in (2, 3) and tg.oriented.any() and ok.any():
        # position and orientation at one joint vector: a 3-joint arm points its tool down only on a band
        ok[ok] = bounds_tilt.posed(bounds.Frames(f.R[ok], f.t[ok]), tg, np.flatnonzero(tg.oriented))
    return ok


def _keep(found: list[Found], s, piv: np.ndarray, por: np.ndarray) -> list[Found]:
    """The KEEP best of found and the block's feasible settings (screened as s, twists piv, por),
    by order_key; a Found is built only for the settings kept (a block can pass thousands)."""
    cand = np.flatnonzero(s.feasible)
    if cand.size == 0:
        return found
    entries: list[tuple[tuple, int, Found | None]] = [(order_key(f), -1, f) for f in found]
    # the keys' first two parts (worst to 1 %, twists set) first: a setting with KEEP others
    # strictly ahead on them cannot be kept, and needs no full key
    vals = np.concatenate([piv[cand], por[cand]], axis=1)
    head = list(zip([round(float(w), 2) for w in s.worst], np.count_nonzero(np.abs(vals) > 1e-9, axis=1).tolist(),
                    strict=True))
    cut = sorted([e[0][:2] for e in entries] + head)[KEEP - 1] if len(entries) + len(head) >= KEEP else None
    near = [j for j, h in enumerate(head) if cut is None or h <= cut]
    keys = _keys(s.worst[near], piv[cand[near]], por[cand[near]])
    entries += [(key, j, None) for j, key in zip(near, keys, strict=True)]
    best = sorted(entries, key=lambda e: e[0])[:KEEP]  # stable: the order the old list had on ties
    out = []
    for _, j, f in best:
        if f is None:
            c = cand[j]
            sols = tuple(tuple(tuple(float(x) for x in q) for q in per) for per in s.solution(j))
            f = Found(tuple(float(x) for x in piv[c]), tuple(float(x) for x in por[c]), sols, float(s.worst[j]))
        out.append(f)
    return out


Work = tuple[Shape, tuple[tuple[int, int], ...], bool | tuple]  # a shape, ranges, what they index (see _listed)


def parts_of(spec: Spec, shape: Shape) -> list[Work]:
    """The shape's units of work (its plan's ranges; one empty range when every setting is
    excluded whole, so that the shape still reports)."""
    p = plan(spec, shape)
    return [(shape, r, p.how) for r in p.ranges]


def listed(spec: Spec, shape: Shape) -> int:
    """Settings of the shape that units of work go through one by one (for a shape searched by
    level, at most: its levels up to COMPLETE, then its coarse grid)."""
    p = plan(spec, shape)
    if p.levels is not None:
        live = p.total - p.excluded
        return live if live <= COMPLETE else COMPLETE + COARSE
    return sum(hi - lo for unit in p.ranges for lo, hi in unit)


def _length(spec: Spec, shape: Shape, how) -> int:
    p = plan(spec, shape)
    if how[0] == "levels" and p.levels is not None:
        return sum(p.levels.counts[how[1]:how[2] + 1])
    return len(_listed(spec, shape, how)[1])  # type: ignore[arg-type]


def _by_level(spec: Spec, shape: Shape, parts: list[Part]) -> tuple[list[Work], int, bool, bool]:
    """A shape searched by level, from the parts so far: (the next round's units of work,
    settings dominated, complete, finished); see dominance.decide."""
    p = plan(spec, shape)
    assert p.levels is not None and isinstance(p.how, tuple)
    done: dict[bool | tuple, int] = {}
    for q in parts:
        if q.upto < q.hi:
            return [], 0, False, False
        done[q.how] = done.get(q.how, 0) + q.hi

    def kept(rounds: list) -> list[Found]:
        return sorted((f for q in parts if q.how in rounds for f in q.found), key=order_key)[:KEEP]

    how, dominated, complete, finished = dominance.decide(p.levels, p.how, done, kept,
                                                          lambda h: _length(spec, shape, h), KEEP, COMPLETE)
    if how is None:
        return [], dominated, complete, finished
    return [(shape, r, how) for r in _split([(0, _length(spec, shape, how))]) or ((),)], 0, False, False


def follow(spec: Spec, shape: Shape, parts: list[Part]) -> list[Work]:
    """The units of work a shape needs after these parts (its whole previous round): the next
    level of a shape searched by level while its kept settings can still be beaten; else none."""
    if plan(spec, shape).levels is None:
        return []
    return _by_level(spec, shape, parts)[0]


def merge(spec: Spec, shape: Shape, parts: list[Part]) -> ShapeResult:
    """One shape's result from its parts (in any order: the merge sorts)."""
    T = len(spec.targets.names)
    p_ = plan(spec, shape)
    found = sorted((f for p in parts for f in p.found), key=order_key)[:KEEP]
    closest = np.full(T, np.inf)
    hit, clear = np.zeros(T, bool), np.zeros(T, bool)
    for p in parts:
        closest = np.minimum(closest, p.closest)
        hit |= np.array(p.hit, bool)
        clear |= np.array(p.clear, bool)
    screened = sum(p.screened for p in parts)
    dominated = 0
    if p_.levels is not None:
        more, dominated, complete, finished = _by_level(spec, shape, parts)
        finished = finished and not more
    else:
        finished = all(p.upto >= p.hi for p in parts) and len(parts) == len(p_.ranges)
        complete = p_.complete and finished
    excluded = sum(p.excluded for p in parts) + (p_.excluded if finished else 0) + dominated
    if p_.levels is not None and finished:  # its families' arrays are not needed any more here
        _PLANS[id(spec)][1][shape] = replace(p_, levels=p_.levels.light())
    return ShapeResult(shape, tuple(found), screened + excluded, tuple(float(x) for x in closest),
                       0.0 if found else 1.0, screened, excluded, dominated, p_.total, complete, finished,
                       tuple(bool(x) for x in hit), tuple(bool(x) for x in clear), list(parts))


def search_shape(spec: Spec, shape: Shape, seed: int, deadline: float | None = None) -> ShapeResult:
    parts = search_chunk(spec, parts_of(spec, shape), seed, deadline)
    while more := follow(spec, shape, parts):
        parts += search_chunk(spec, more, seed, deadline)
    return merge(spec, shape, parts)


def search_chunk(spec: Spec, work: list[Work], seed: int, deadline: float | None = None) -> list[Part]:
    """A worker's unit of work: ranges of shapes' settings, one after the other."""
    return [search_part(spec, s, r, seed, deadline, full) for s, r, full in work]
