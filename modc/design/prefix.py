"""Branch and bound over a shape's twist settings: whole families of settings - a prefix of
the chain fixed, the rest free - excluded by one sound test, before any setting is listed.

In the notation of modc.design.bounds, a setting is the sequence of fixed transforms
K_0 … K_n, and each K_j is chosen by its own twists: K_0 by unit 1's pivot, K_j (0 < j < n) by
unit j's port and unit j+1's pivot, K_n by unit n's port. The settings are numbered in that
order (unit 1's pivot outermost, then its port, unit 2's pivot, …), so the settings that share
K_0 … K_(k-1) are one contiguous range of numbers.

For the free rest, U_k bounds |v_k| = |tool - p_k| over every choice of K_k … K_n and every
joint angle: exact (modc.design.bounds._pair) over every pair K_(n-1), K_n, then the triangle
inequality with the shortest and longest |t(K_j)| on offer. bounds.possible with that tail is
then a test that holds for every setting of the family at once: a family it rules out for some
target holds no setting that could serve that target, and is excluded whole. Families are
refined a level at a time while at most CAP of them are alive; what survives is listed
setting by setting (and meets the exact per-setting bound) by modc.design.search.

Oriented targets (bounds' tilt test, per family): the tilt range of bounds._tilt is a recursion
over b_j, the polar angle of R(K_j)^T e_z, and each step's interval grows with its input
interval; over a free level it takes b_j's hull [min, max] of the options (the distance of the
interval to a hull of b is at most its distance to each b), and the start gamma its hull too: a
superset of every setting's range. The tested vector w = R(K_n)^T e_z depends on K_n alone, so
a family is out for a target when no option of K_n puts R_t w within eps of that range.
The wrist (bounds._wrist_ok) likewise: each option of K_n puts joint n's origin at one point per
posed target, and some option must bring every target's within reach of K_0 … K_(n-1) (the
free ones bounded by the tails of that shorter chain). Such families are refined DEEP times
further: deep families pay (for a 3-unit region cell 2 in 3 of them go).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import bounds
from .batch import pre_post

POSED = True  # the orientation (tilt) bounds per family (off: tests compare)
CAP = 200_000  # live families per level (memory: ~100 bytes each per fixed transform)
TOGETHER = 4 * CAP  # families refined at once for several target sets (refine_many), at most
SPREAD = 32  # targets the family bounds test at most (a region of 400 points: 12x less work)
WRISTS = 4  # posed targets the family wrist test takes (spread; each costs every K_n option)
DEEP = 8  # cap's multiple with posed targets
CHUNK = 50_000  # families per wrist test (memory)


@dataclass(frozen=True)
class Level:
    """The options of one K_j: rotations (m, 3, 3), translations (m, 3), and the twist axes
    that choose it (their lengths multiply to m, the first axis outermost)."""

    R: np.ndarray
    t: np.ndarray
    axes: tuple[int, ...]


def levels(types, links, pivot_set: np.ndarray, port_set: np.ndarray, free: list[bool],
           flange_tool: np.ndarray) -> list[Level]:
    """K_0 … K_n of a shape as option lists. Axes are numbered unit by unit: pivot, then port
    (a port that cannot matter has one value, 0, and no axis)."""
    n = len(types)
    axis = 0
    out: list[Level] = []
    pivot_axis: list[int] = []
    port_axis: list[int | None] = []
    for i in range(n):
        pivot_axis.append(axis)
        axis += 1
        port_axis.append(axis if free[i] else None)
        axis += int(free[i])

    def unit(i, piv, por):
        m = len(piv)
        return pre_post([types[i]], np.asarray(piv, float).reshape(m, 1), np.asarray(por, float).reshape(m, 1),
                        [links[i]])

    pr, pt, _, _ = unit(0, pivot_set, np.zeros(len(pivot_set)))
    out.append(Level(pr[:, 0], pt[:, 0], (pivot_axis[0],)))
    for j in range(1, n + 1):
        ports = port_set if free[j - 1] else np.zeros(1)
        pa = port_axis[j - 1]
        axes: tuple[int, ...] = () if pa is None else (pa,)
        _, _, qR, qt = unit(j - 1, np.zeros(len(ports)), ports)
        qR, qt = qR[:, 0], qt[:, 0]
        if j == n:
            R = qR @ flange_tool[:3, :3]
            t = qt + qR @ flange_tool[:3, 3]
        else:
            pR, pt_, _, _ = unit(j, pivot_set, np.zeros(len(pivot_set)))
            pR, pt_ = pR[:, 0], pt_[:, 0]
            R = (qR[:, None] @ pR[None]).reshape(-1, 3, 3)
            t = (qt[:, None] + np.einsum("aij,bj->abi", qR, pt_)).reshape(-1, 3)
            axes = axes + (pivot_axis[j],)
        out.append(Level(R, t, axes))
    return out


def tails(lv: list[Level]) -> list[tuple[float, float]]:
    """U_1 … U_n (index k-1 holds U_k): bounds of |v_k| over every choice of K_k … K_n."""
    n = len(lv) - 1
    U: dict[int, tuple[float, float]] = {}
    a = np.linalg.norm(lv[n].t, axis=-1)
    U[n] = (float(a.min()), float(a.max()))
    if n >= 2:
        last = lv[n]
        prev = lv[n - 1]
        P, M = len(prev.t), len(last.t)
        lo, hi = bounds._pair(np.repeat(prev.t, M, 0), np.repeat(prev.R, M, 0), np.tile(last.t, (P, 1)))
        U[n - 1] = (float(lo.min()), float(hi.max()))
    for j in range(n - 2, 0, -1):
        a = np.linalg.norm(lv[j].t, axis=-1)
        lo_n, hi_n = U[j + 1]
        U[j] = (max(0.0, float(a.min()) - hi_n, lo_n - float(a.max())), float(a.max()) + hi_n)
    return [U[k] for k in range(1, n + 1)]


@dataclass(frozen=True)
class Families:
    """The families of settings still alive: prefixes over the first `depth` levels (numbers in
    the row-major order of their axes), and how many settings each holds."""

    depth: int
    alive: np.ndarray  # sorted prefix numbers
    per: int  # settings per family

    def ranges(self) -> list[tuple[int, int]]:
        """The alive settings as [lo, hi) ranges, neighbours merged."""
        out: list[tuple[int, int]] = []
        for i in self.alive.tolist():
            lo, hi = i * self.per, (i + 1) * self.per
            if out and out[-1][1] == lo:
                out[-1] = (out[-1][0], hi)
            else:
                out.append((lo, hi))
        return out

    @property
    def settings(self) -> int:
        return len(self.alive) * self.per


def spread(xyz: np.ndarray, tol: np.ndarray, k: int = SPREAD) -> tuple[np.ndarray, np.ndarray]:
    """At most k of the targets, spread out (farthest-point order from the first): a family that
    cannot reach one of them cannot reach them all, so bounding by these is sound; a region's
    hundreds of neighbouring points would cost the bounds hundreds of times over for little more."""
    if len(xyz) <= k:
        return xyz, tol
    picked = _picks(xyz, k)
    return xyz[picked], tol[picked]


def _picks(xyz: np.ndarray, k: int) -> list[int]:
    """spread's targets, by index."""
    if len(xyz) <= k:
        return list(range(len(xyz)))
    picked = [0]
    gap = np.linalg.norm(xyz - xyz[0], axis=1)
    for _ in range(k - 1):
        i = int(np.argmax(gap))
        picked.append(i)
        gap = np.minimum(gap, np.linalg.norm(xyz - xyz[i], axis=1))
    return picked


def refine(lv: list[Level], xyz: np.ndarray, tol: np.ndarray, cap: int = CAP, tg=None) -> Families:
    """Families alive after refining level by level while at most cap of them are tested
    (against at most SPREAD of the targets, spread; and, with tg a reach.Targets, against the
    orientations of every target's, once per distinct one)."""
    keys = _keys(tg)
    cap = cap * DEEP if keys is not None and len(keys[4]) else cap
    xyz, tol = spread(np.asarray(xyz, float), np.asarray(tol, float))
    n = len(lv) - 1
    U = tails(lv)
    sizes = [len(level.t) for level in lv]
    total = int(np.prod(sizes, dtype=object))
    R = lv[0].R[:, None]
    t = lv[0].t[:, None]
    alive = np.arange(sizes[0])
    depth = 1
    while True:
        tail = U[depth - 1] if depth <= n else None
        # the orientation first: its few targets cost less than the position's SPREAD
        rows = np.arange(len(R)) if keys is None else np.flatnonzero(fits(lv, R, t, keys))
        ok = np.zeros(len(R), bool)
        ok[rows] = bounds.possible_all(bounds.Frames(R[rows], t[rows]), xyz, tol, tail)[:, 0]
        R, t, alive = R[ok], t[ok], alive[ok]
        if depth == n + 1 or len(alive) == 0 or len(alive) * sizes[depth] > cap:
            break
        m = sizes[depth]
        nxt = lv[depth]
        R = np.concatenate([np.repeat(R, m, 0), np.tile(nxt.R, (len(alive), 1, 1))[:, None]], 1)
        t = np.concatenate([np.repeat(t, m, 0), np.tile(nxt.t, (len(alive), 1))[:, None]], 1)
        alive = (alive[:, None] * m + np.arange(m)[None]).reshape(-1)
        depth += 1
    per = total // int(np.prod(sizes[:depth], dtype=object))
    return Families(depth, alive, int(per))


def refine_many(lv: list[Level], sets: list[tuple[np.ndarray, np.ndarray]], cap: int = CAP,
                tgs: list | None = None) -> list[Families]:
    """refine(lv, xyz, tol, cap) for each (xyz, tol) of sets (a shape at several base poses), in
    one pass: the families are tested against the targets of every set still refining at once,
    each set with its own alive mask (a family counts at a set only while its parent is alive
    there, as in refine), and each set stops where refine would (its own count against cap).
    The bounds are row by row, so every set gets refine's families; past TOGETHER families at
    once the sets left are refined one by one (memory). tgs: each set's reach.Targets (refine's tg)."""
    tgs = tgs if tgs is not None else [None] * len(sets)
    if len(sets) <= 1 or any(len(x) == 0 for x, _ in sets):
        return [refine(lv, x, t, cap, g) for (x, t), g in zip(sets, tgs, strict=True)]
    keys = [_keys(g) for g in tgs]
    caps = [cap * DEEP if kk is not None and len(kk[4]) else cap for kk in keys]
    picked = [spread(np.asarray(x, float), np.asarray(t, float)) for x, t in sets]
    n = len(lv) - 1
    U = tails(lv)
    sizes = [len(level.t) for level in lv]
    total = int(np.prod(sizes, dtype=object))
    out: dict[int, Families] = {}
    R, t = lv[0].R[:, None], lv[0].t[:, None]
    alive = np.arange(sizes[0])
    going = list(range(len(sets)))
    mask = np.ones((sizes[0], len(going)), bool)  # (families, sets going): alive at that set so far
    depth = 1
    while True:
        _test(lv, R, t, mask, [picked[s] for s in going], [keys[s] for s in going],
              U[depth - 1] if depth <= n else None)
        per = total // int(np.prod(sizes[:depth], dtype=object))
        stay = []
        for j, s in enumerate(going):
            k = int(mask[:, j].sum())
            if depth == n + 1 or k == 0 or k * sizes[depth] > caps[s]:
                out[s] = Families(depth, alive[mask[:, j]], int(per))
            else:
                stay.append(j)
        going, mask = [going[j] for j in stay], mask[:, stay]
        keep = mask.any(1)
        R, t, alive, mask = R[keep], t[keep], alive[keep], mask[keep]
        if not going:
            break
        m = sizes[depth]
        if len(alive) * m > TOGETHER:
            out.update((s, refine(lv, *sets[s], cap, tgs[s])) for s in going)
            break
        nxt = lv[depth]
        R = np.concatenate([np.repeat(R, m, 0), np.tile(nxt.R, (len(alive), 1, 1))[:, None]], 1)
        t = np.concatenate([np.repeat(t, m, 0), np.tile(nxt.t, (len(alive), 1))[:, None]], 1)
        alive = (alive[:, None] * m + np.arange(m)[None]).reshape(-1)
        mask = np.repeat(mask, m, 0)
        depth += 1
    return [out[s] for s in range(len(sets))]


def _test(lv: list[Level], R: np.ndarray, t: np.ndarray, mask: np.ndarray, picked: list, keys: list,
          tail: tuple[float, float] | None) -> None:
    """refine_many's bounds at one depth, in place: mask (families, sets going) keeps the families
    each set's spread targets (picked) and orientations (keys) leave alive."""
    mask &= bounds.possible_all(bounds.Frames(R, t), np.concatenate([x for x, _ in picked]),
                                np.concatenate([tl for _, tl in picked]), tail,
                                np.cumsum([0] + [len(x) for x, _ in picked[:-1]]), mask)
    for j, k in enumerate(keys):
        if k is not None:
            rows = np.flatnonzero(mask[:, j])
            mask[rows, j] = fits(lv, R[rows], t[rows], k)


def _keys(tg):
    """The distinct orientations of tg's targets: full ones (rotations (K, 3, 3), eps (K,)) and
    `pointing` ones (axes (P, 3), eps (P,)), and WRISTS of the full ones, spread (positions,
    rotations, tol_p, eps); None without any (or with POSED off)."""
    if tg is None or not POSED or not tg.oriented.any():
        return None
    pointed = tg.pointed if len(tg.pointed) else np.zeros(len(tg.xyz), bool)
    full, point = tg.oriented & ~pointed, tg.oriented & pointed
    a = np.unique(np.column_stack([tg.R[full].reshape(-1, 9), tg.tol_r[full]]), axis=0)
    b = np.unique(np.column_stack([tg.axis[point].reshape(-1, 3), tg.tol_r[point]]), axis=0)
    w = np.flatnonzero(full)[_picks(tg.xyz[full], WRISTS)]
    return (a[:, :9].reshape(-1, 3, 3), np.minimum(a[:, 9], np.pi), b[:, :3], np.minimum(b[:, 3], np.pi),
            tg.xyz[w], tg.R[w], tg.tol_p[w], np.minimum(tg.tol_r[w], np.pi))


def _hull(v: np.ndarray) -> tuple[float, float]:
    return float(v.min()), float(v.max())


def _range(lv: list[Level], R: np.ndarray, gamma, top: int) -> tuple[np.ndarray, np.ndarray]:
    """bounds._tilt for families (R: their fixed K_0 … K_(k-1)), gamma (lo, hi) the start's
    hull: each free level's b over its options' hull (module docstring)."""
    k = R.shape[1]
    lo, hi = gamma
    for j in range(top, 0, -1):
        b_lo: np.ndarray | float
        b_hi: np.ndarray | float
        if j < k:
            b_lo = b_hi = bounds._polar(R[:, j, 2, :])
        else:
            b_lo, b_hi = _hull(bounds._polar(lv[j].R[:, 2, :]))
        lo, hi = np.maximum(np.maximum(0.0, lo - b_hi), b_lo - hi), np.pi - np.maximum(
            np.maximum(0.0, lo - (np.pi - b_lo)), (np.pi - b_hi) - hi)
    return np.broadcast_to(lo, len(R)), np.broadcast_to(hi, len(R))


def _start(lv: list[Level], R: np.ndarray, j: int, col: int) -> tuple:
    """Hull of the polar angle of R(K_j)'s column col: per family if K_j is fixed, else over its options."""
    if j < R.shape[1]:
        g = bounds._polar(R[:, j, :, col])
        return g, g
    return _hull(bounds._polar(lv[j].R[:, :, col]))


def tilted(lv: list[Level], R: np.ndarray, keys) -> np.ndarray:
    """(C,): whether a family (fixed K_0 … K_(k-1), rotations R (C, k, 3, 3)) may meet the tilt
    of every orientation of keys (_keys) - False: no setting of it can (bounds._tilt_ok,
    bounds._pointing_ok)."""
    n, k = len(lv) - 1, R.shape[1]
    rot, eps, axis, eps_p = keys[:4]
    z1 = R[:, 0, :, 2]
    ok = np.ones(len(R), bool)
    if len(rot):
        if n > 1:
            lo, hi = _range(lv, R, _start(lv, R, n - 1, 2), n - 2)
        else:
            lo = hi = np.zeros(len(R))
        u = np.einsum("ci,kij->ckj", z1, rot)  # R_t^T z_1
        if k > n:
            c = np.einsum("ckj,cj->ck", u, R[:, n, 2, :])[..., None]
        else:
            c = np.einsum("ckj,mj->ckm", u, np.unique(lv[n].R[:, 2, :], axis=0))
        e = eps[None, :, None]
        fit = bounds._cos_within(c, lo[:, None, None] - e - bounds.SLACK, hi[:, None, None] + e + bounds.SLACK)
        ok &= fit.any(-1).all(-1)
    if len(axis):
        lo, hi = _range(lv, R, _start(lv, R, n, 0), n - 1)
        c = z1 @ axis.T
        ok &= bounds._cos_within(c, lo[:, None] - eps_p - bounds.SLACK, hi[:, None] + eps_p + bounds.SLACK).all(-1)
    return ok


def wristed(lv: list[Level], R: np.ndarray, t: np.ndarray, keys) -> np.ndarray:
    """(C,): whether some option of K_n puts joint n's origin, for every wrist target of keys
    (_keys), within reach of the family's K_0 … K_(n-1) (module docstring)."""
    n, k = len(lv) - 1, R.shape[1]
    x, Rt, tol_p, eps = keys[4:]
    if len(x) == 0:
        return np.ones(len(R), bool)
    u = np.unique(np.einsum("mji,mj->mi", lv[n].R, lv[n].t), axis=0)  # joint n's origin to tool0, tool frame
    W = (x[:, None] - np.einsum("tij,mj->tmi", Rt, u)).reshape(-1, 3)  # (T * M, 3)
    tol = (tol_p[:, None] + 2 * np.sin(eps / 2)[:, None] * np.linalg.norm(u, axis=-1)[None]).reshape(-1) + bounds.SLACK
    if n == 1:  # p_1 is fixed
        ok = np.linalg.norm(W[None] - t[:, 0][:, None], axis=-1) <= tol
    elif k >= n:
        ok = bounds.possible(bounds.Frames(R[:, :n], t[:, :n]), W, tol)
    else:
        ok = bounds.possible(bounds.Frames(R, t), W, tol, tails(lv[:n])[k - 1])
    return ok.reshape(len(R), len(x), len(u)).all(1).any(-1)


def fits(lv: list[Level], R: np.ndarray, t: np.ndarray, keys) -> np.ndarray:
    """(C,): tilted, then wristed on the families it leaves, CHUNK at a time."""
    ok = tilted(lv, R, keys)
    for i in range(0, len(R), CHUNK):
        rows = i + np.flatnonzero(ok[i:i + CHUNK])
        ok[rows] = wristed(lv, R[rows], t[rows], keys)
    return ok
