"""Sound bounds: which twist settings (and which targets) no joint vector can serve, decided
without IK, for thousands of settings at once.

Written as docs/conventions.md's chain between joint frames: J_0 = base_link, and for joint i the
frame after its rotation, J_i. From J_i to the next joint's frame before its rotation the
transform K_i = POST_i . PRE_(i+1) is fixed by the twists (K_0 = PRE_1, K_n = POST_n . tool);
p_i = the origin of J_i lies on joint i's axis. With v_j the tool relative to p_j in J_j,

    v_n = t(K_n),    v_j = t(K_j) + R(K_j) . Rz(theta_(j+1)) . v_(j+1).

Every joint turning freely is a superset of the joint limits, so each interval below contains
every value the limited arm can take: a target outside them is out of reach for that setting,
whatever the IK would say. Per joint j the test is that some p_j the prefix can reach and some
tool position the suffix can reach are the target's distance apart:

- |tool - p_j| lies in W_j: exact for the last two joints (|a + R Rz(t) b|^2 ranges over
  |a|^2 + |b|^2 + 2 (a'_z b_z +- |a'_xy| |b_xy|) with a' = R^T a), the triangle inequality
  before;
- |x - p_j| lies in D_j: p_1 is fixed, p_2 runs on a circle about joint 1's axis (exact
  distance range), p_j (j > 2) within the interval of |p_j - p_2| of the circle;
- the tool's height along joint 1's axis, z_1 . (tool - p_1) = e_z . v_1, does not depend on
  theta_1: exact range for two joints, a triangle bound after.

A target's orientation (posed): the tool's rotation is R = R(K_0) Rz(theta_1) R(K_1) … Rz(theta_n)
R(K_n), and a rotation within eps of the target's R_t turns no vector more than eps (and moves
a point at distance r by at most the chord 2 sin(eps / 2) r). Two exact consequences:

- tilt: the angle between joint 1's axis z_1 and a vector w fixed in the tool (w = R(K_n)^T e_z,
  joint n's axis, for a full orientation; tool0's x axis for `pointing`) does not depend on
  theta_1, and its range over the other joints is exact (angles of a vector turned about e_z
  keep their tilt, see _tilt): the angle between z_1 and R_t w must lie within eps of it;
- wrist: joint n's origin p_n = x - R R(K_n)^T t(K_n) follows from the tool's pose, so with a full
  orientation it lies within tol + chord |R(K_n)^T t(K_n)| of x_t - R_t R(K_n)^T t(K_n), and the
  chain of the first n - 1 joints (K_0 … K_(n-1)) must bring its end there (possible, per
  setting). A 3-joint arm meets a 6-D pose only on a 3-D set: this rules out most settings.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Frames:
    """K_0 … K_n for C settings: rotations (C, n+1, 3, 3), translations (C, n+1, 3)."""

    R: np.ndarray
    t: np.ndarray


def frames(g) -> Frames:
    """K_0 … K_n of a batch.Geometry's C settings."""
    pre_R, pre_t, post_R, post_t = g.pre[..., :3, :3], g.pre[..., :3, 3], g.post[..., :3, :3], g.post[..., :3, 3]
    tool = g.flange_tool
    C, n = pre_R.shape[:2]
    R = np.empty((C, n + 1, 3, 3))
    t = np.empty((C, n + 1, 3))
    R[:, 0], t[:, 0] = pre_R[:, 0], pre_t[:, 0]
    R[:, 1:n] = post_R[:, :-1] @ pre_R[:, 1:]
    t[:, 1:n] = post_t[:, :-1] + np.einsum("cnij,cnj->cni", post_R[:, :-1], pre_t[:, 1:])
    R[:, n] = post_R[:, -1] @ tool[:3, :3]
    t[:, n] = post_t[:, -1] + post_R[:, -1] @ tool[:3, 3]
    return Frames(R, t)


def _norm2(v: np.ndarray) -> np.ndarray:
    """|v|^2 over the last axis (3): (v * v).sum(-1)'s bits (the same sum, left to right),
    without a reduction over an axis of 3, which costs several times the arithmetic."""
    x, y, z = v[..., 0], v[..., 1], v[..., 2]
    return x * x + y * y + z * z


def _norm(v: np.ndarray) -> np.ndarray:
    """|v| over the last axis (3): np.linalg.norm's bits."""
    return np.sqrt(_norm2(v))


def _floor(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """max(0, a, b) elementwise (np.maximum.reduce of the three, without stacking them)."""
    return np.maximum(np.maximum(a, 0.0), b)


def _pair(a: np.ndarray, R: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Exact range of |a + R Rz(t) b| over every t: a, b (C, 3), R (C, 3, 3)."""
    ap = np.einsum("cji,cj->ci", R, a)  # R^T a
    mid = (a * a).sum(-1) + (b * b).sum(-1) + 2 * ap[:, 2] * b[:, 2]
    amp = 2 * np.hypot(ap[:, 0], ap[:, 1]) * np.hypot(b[:, 0], b[:, 1])
    return np.sqrt(np.maximum(mid - amp, 0.0)), np.sqrt(np.maximum(mid + amp, 0.0))


def _interval(f: Frames, first: int, last: int, end: np.ndarray | None = None):
    """Range (lo, hi) of |t(K_first) + R(K_first) Rz . (… t(K_last))| (the point reached from
    p_first through K_first … K_last, every joint in between free), end replacing t(K_last)."""
    tail = f.t[:, last] if end is None else end
    if first == last:
        d = _norm(tail)
        return d, d
    lo, hi = _pair(f.t[:, last - 1], f.R[:, last - 1], tail)
    for j in range(last - 2, first - 1, -1):
        a = _norm(f.t[:, j])
        lo, hi = _floor(a - hi, lo - a), a + hi
    return lo, hi


def _reach(f: Frames, first: int, tail: tuple[float, float] | None):
    """Range (lo, hi) of |v_first| = |tool - p_first|. Without a tail every K_j is fixed (exact
    for the last two joints); with one, f holds K_0 … K_(k-1) and tail bounds |v_k| over every
    choice of the free K_k … K_n, so the triangle inequality carries it back to joint first."""
    if tail is None:
        return _interval(f, first, f.t.shape[1] - 1)
    k = f.t.shape[1]
    lo, hi = np.full(len(f.t), tail[0]), np.full(len(f.t), tail[1])
    for j in range(k - 1, first - 1, -1):
        a = _norm(f.t[:, j])
        lo, hi = _floor(a - hi, lo - a), a + hi
    return lo, hi


def possible(f: Frames, xyz: np.ndarray, tol: np.ndarray, tail: tuple[float, float] | None = None) -> np.ndarray:
    """(C, T): False where no joint vector (limits or not) brings tool0 within tol of target xyz
    (T, 3) for that setting - or, with a tail, for any setting that starts with f's K_0 …
    K_(k-1) and whose free rest keeps |v_k| within tail (modc.design.prefix)."""
    C, k = f.t.shape[:2]
    n = k - 1 if tail is None else k  # joints whose origin p_j is fixed by f
    p1 = f.t[:, 0]  # (C, 3)
    z1 = f.R[:, 0, :, 2]
    x = xyz if xyz.ndim == 3 else xyz[None]  # (C or 1, T, 3): a target per setting, or shared
    tl = (tol if tol.ndim == 2 else tol[None]) + 1e-9  # rounding: a target exactly at an interval's end stays possible
    ok = np.ones((C, x.shape[1]), bool)
    # D_1: p_1 fixed
    dx = x - p1[:, None]
    d1 = _norm(dx)
    lo, hi = _reach(f, 1, tail)
    ok &= (d1 <= hi[:, None] + tl) & (d1 >= lo[:, None] - tl)
    if k < 2:
        return ok
    # height along joint 1's axis
    h_x = np.einsum("cti,ci->ct", dx, z1)
    a1 = f.t[:, 1]
    if tail is None and n == 1:
        h_lo = h_hi = a1[:, 2]
    elif k == 2:  # v_2 free: its component along any axis is at most |v_2|
        h_lo, h_hi = a1[:, 2] - tail[1], a1[:, 2] + tail[1]  # type: ignore[index]
    else:
        c = f.R[:, 1, 2, :]  # R(K_1)^T e_z, as a row of R(K_1)
        b = f.t[:, 2]
        mid = a1[:, 2] + c[:, 2] * b[:, 2]
        amp = np.hypot(c[:, 0], c[:, 1]) * np.hypot(b[:, 0], b[:, 1])
        rest = _reach(f, 3, tail)[1] if (tail is not None or n >= 3) else 0.0
        h_lo, h_hi = mid - amp - rest, mid + amp + rest
    ok &= (h_x <= h_hi[:, None] + tl) & (h_x >= h_lo[:, None] - tl)
    if n < 2:
        return ok
    # D_2: p_2 on a circle about joint 1's axis
    a1w = np.einsum("cij,cj->ci", f.R[:, 0], a1)  # R(K_0) a_1, at theta_1 = 0
    along = (a1w * z1).sum(-1)
    r = _norm(a1w - along[:, None] * z1)
    centre = p1 + along[:, None] * z1
    rel = x - centre[:, None]
    h = np.einsum("cti,ci->ct", rel, z1)
    s = np.sqrt(np.maximum(_norm2(rel) - h * h, 0.0))
    dlo2, dhi2 = np.hypot(h, s - r[:, None]), np.hypot(h, s + r[:, None])
    for j in range(2, n + 1):
        if j == 2:
            dlo, dhi = dlo2, dhi2
        else:
            ulo, uhi = _interval(f, 2, j - 1)
            dlo = _floor(dlo2 - uhi[:, None], ulo[:, None] - dhi2)
            dhi = dhi2 + uhi[:, None]
        wlo, whi = _reach(f, j, tail)
        ok &= (dlo <= whi[:, None] + tl) & (dhi >= wlo[:, None] - tl)
    return ok


def possible_all(f: Frames, xyz: np.ndarray, tol: np.ndarray, tail: tuple[float, float] | None = None,
                 starts: np.ndarray | None = None, mask: np.ndarray | None = None) -> np.ndarray:
    """(C, G): possible(f, xyz, tol, tail)[:, group].all(-1) for each group of targets (the groups
    start at `starts`, in order; None: one group, every target), and False where mask (C, G), if
    given, is. Group by group, on the rows the mask leaves for it (a base grid's family is alive
    at a few of its poses: the others' targets are not tested): D_1 first (most rows fail it for
    some target: 9 in 10 of a refine's families), then every test on the rows still alive. Each
    test is row by row and target by target, so a row gets the same bits - and
    rows go ELEMENTS // targets at a time (a refine's 1.6 M families against a base grid's 300
    targets would take gigabytes per temporary array)."""
    step = max(1, ELEMENTS // max(len(xyz), 1))
    if len(f.t) > step:
        return np.concatenate([possible_all(Frames(f.R[a:a + step], f.t[a:a + step]), xyz, tol, tail, starts,
                                            None if mask is None else mask[a:a + step])
                               for a in range(0, len(f.t), step)])
    starts = np.zeros(1, np.int64) if starts is None else np.asarray(starts, np.int64)
    lo, hi = _reach(f, 1, tail)
    out = np.zeros((len(f.t), len(starts)), bool)
    ends = np.r_[starts[1:], len(xyz)]
    for g, (a, b) in enumerate(zip(starts, ends, strict=True)):
        rows = np.arange(len(f.t)) if mask is None else np.flatnonzero(mask[:, g])
        if not rows.size:
            continue
        d1 = _norm(xyz[a:b][None] - f.t[rows, 0][:, None])
        tl = tol[a:b][None] + 1e-9
        rows = rows[((d1 <= hi[rows, None] + tl) & (d1 >= lo[rows, None] - tl)).all(1)]
        if rows.size and f.t.shape[1] < 2:
            out[rows, g] = True
        elif rows.size:
            out[rows, g] = possible(Frames(f.R[rows], f.t[rows]), xyz[a:b], tol[a:b], tail).all(-1)
    return out


def _tilt(f: Frames, gamma: np.ndarray, top: int) -> tuple[np.ndarray, np.ndarray]:
    """Range (lo, hi) of the angle between e_z and R(K_1) Rz R(K_2) … R(K_top) Rz v over every
    joint angle, for v at angle gamma (C,) from e_z. Turning v about e_z keeps its tilt gamma and
    frees its azimuth, so against c = R(K_j)^T e_z (tilt b) the angle takes every value in
    [|b - gamma|, pi - |pi - b - gamma|]: over a range of gamma, its distance to b, and pi less
    the distance of pi - b to it (exact; the joint limits only shrink the set)."""
    lo = hi = gamma
    for j in range(top, 0, -1):
        b = _polar(f.R[:, j, 2, :])
        lo, hi = np.maximum.reduce([np.zeros_like(b), lo - b, b - hi]), np.pi - np.maximum.reduce(
            [np.zeros_like(b), lo - (np.pi - b), (np.pi - b) - hi])
    return lo, hi


def _polar(v: np.ndarray) -> np.ndarray:
    """Angles between unit vectors v (..., 3) and e_z (atan2: arccos loses 1e-8 rad near 0 and pi)."""
    return np.arctan2(np.hypot(v[..., 0], v[..., 1]), v[..., 2])


ELEMENTS = 1 << 21  # (setting, target) pairs possible_all tests at once (memory: ~50 MB per array)
SLACK = 1e-7  # rad and m: rounding never excludes a pose at the edge of its tolerances
SPIN = 128  # joint 2's angles a 3-joint chain's wrist scan samples (Lipschitz margins cover the gaps)


def _turned(R: np.ndarray, v: np.ndarray) -> np.ndarray:
    """R[t] v[c] (C, T, 3) for rotations R (T, 3, 3) and vectors v (C, 3): one matrix product."""
    return (v @ R.reshape(-1, 3).T).reshape(len(v), len(R), 3)


def _cos_within(c: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Whether the angles whose cosines are c lie in [lo, hi] (rad, any range: clipped to [0, pi]),
    compared as cosines (no arccos) with 1e-12 for rounding."""
    return (c >= np.cos(np.clip(hi, 0.0, np.pi)) - 1e-12) & (c <= np.cos(np.clip(lo, 0.0, np.pi)) + 1e-12)


def _tilt_ok(f: Frames, tg, full: np.ndarray) -> np.ndarray:
    """(C, T'): the tilt of joint n's axis to joint 1's fits the targets full's rotations."""
    C, n = len(f.t), f.t.shape[1] - 1
    # the test depends on the rotation and its tolerance only: once per distinct pair (a region's
    # points share theirs)
    keys, back = np.unique(np.column_stack([tg.R[full].reshape(-1, 9), tg.tol_r[full]]), axis=0, return_inverse=True)
    eps = np.minimum(keys[:, 9], np.pi)
    lo, hi = _tilt(f, _polar(f.R[:, n - 1, :, 2]), n - 2) if n > 1 else (np.zeros(C), np.zeros(C))
    c = (_turned(keys[:, :9].reshape(-1, 3, 3), f.R[:, n, 2, :]) * f.R[:, 0, :, 2][:, None]).sum(-1)
    return _cos_within(c, lo[:, None] - eps - SLACK, hi[:, None] + eps + SLACK)[:, back.reshape(-1)]


def _pointing_ok(f: Frames, tg, point: np.ndarray) -> np.ndarray:
    """(C, T'): the tilt of tool0's x axis (R(K_n) e_x) to joint 1's axis fits the targets' axes."""
    n = f.t.shape[1] - 1
    eps = np.minimum(tg.tol_r[point], np.pi)
    lo, hi = _tilt(f, _polar(f.R[:, n, :, 0]), n - 1)
    c = f.R[:, 0, :, 2] @ tg.axis[point].T
    return _cos_within(c, lo[:, None] - eps - SLACK, hi[:, None] + eps + SLACK)


def _wrist(f: Frames, tg, full: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Where the targets full's poses put joint n's origin (C, T', 3), within tol (C, T'); eps (T')."""
    n = f.t.shape[1] - 1
    eps = np.minimum(tg.tol_r[full], np.pi)
    u = np.einsum("cji,cj->ci", f.R[:, n], f.t[:, n])  # joint n's origin to tool0, in the tool frame
    wrist = tg.xyz[full][None] - _turned(tg.R[full], u)
    tol = tg.tol_p[full][None] + 2 * np.sin(eps / 2)[None] * np.linalg.norm(u, axis=-1)[:, None] + SLACK
    return wrist, tol, eps


def _wrist_ok(f: Frames, tg, full: np.ndarray) -> np.ndarray:
    """(C, T'): joint n's origin, where the targets full's poses put it, within reach of the
    first n - 1 joints."""
    n = f.t.shape[1] - 1
    wrist, tol, _ = _wrist(f, tg, full)
    if n == 1:  # p_1 is fixed
        return np.linalg.norm(wrist - f.t[:, 0][:, None], axis=-1) <= tol
    return possible(Frames(f.R[:, :n], f.t[:, :n]), wrist, tol)


def _spin(f: Frames, tg, full: np.ndarray) -> np.ndarray:
    """(C, T'), 3 joints: some theta_2 puts p_3 at the wrist's height along z_1 and distance from
    p_1 (within tol) and joint 3's axis at its tilt to z_1 (within eps) - the three at once. In
    joint 1's frame a = t(K_1) + R(K_1) Rz(theta_2) t(K_2) is p_3 - p_1 and b = R(K_1) Rz(theta_2)
    R(K_2) e_z is z_3; a_z, |a|^2 and b_z are each m + A cos(theta_2 - phi), so between the SPIN
    samples each moves by at most A pi / SPIN from the nearest one: a sample within the bands so
    widened stands for every angle near it. Other chains: True."""
    if f.t.shape[1] != 4:
        return np.ones((len(f.t), len(full)), bool)
    wrist, tol, eps = _wrist(f, tg, full)
    R0, p1 = f.R[:, 0], f.t[:, 0]
    W = (wrist - p1[:, None]) @ R0  # the wrist in joint 1's frame
    Z = _turned(tg.R[full], f.R[:, 3, 2, :]) @ R0
    gamma = _polar(Z)
    t1, t2, c1 = f.t[:, 1], f.t[:, 2], f.R[:, 1, 2, :]  # c1 = R(K_1)^T e_z
    th = np.arange(SPIN) * (2 * np.pi / SPIN)
    cs, sn = np.cos(th), np.sin(th)

    def wave(p: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """p . Rz(theta) v at the samples (C, SPIN), and its amplitude's reach between them (C,)."""
        a = p[:, 0] * v[:, 0] + p[:, 1] * v[:, 1]
        b = p[:, 1] * v[:, 0] - p[:, 0] * v[:, 1]
        return (p[:, 2] * v[:, 2])[:, None] + a[:, None] * cs + b[:, None] * sn, np.hypot(a, b) * np.pi / SPIN

    h, dh = wave(c1, t2)
    d, dd = wave(np.einsum("cji,cj->ci", f.R[:, 1], t1), t2)
    z, dz = wave(c1, f.R[:, 2, :, 2])
    h = h + t1[:, 2:3]
    d = (t1 * t1).sum(-1)[:, None] + (t2 * t2).sum(-1)[:, None] + 2 * d
    rho = np.linalg.norm(W, axis=-1)

    def within(x: np.ndarray, dx: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
        return (x[:, None] >= lo[..., None] - dx[:, None, None] - SLACK) & (
            x[:, None] <= hi[..., None] + dx[:, None, None] + SLACK)

    ok = within(h, dh, W[..., 2] - tol, W[..., 2] + tol)
    ok &= within(d, 2 * dd, np.maximum(rho - tol, 0.0) ** 2, (rho + tol) ** 2)
    ok &= within(z, dz, np.cos(np.minimum(gamma + eps, np.pi)), np.cos(np.maximum(gamma - eps, 0.0)))
    return np.asarray(ok.any(-1))


def posed(f: Frames, tg, every: bool = False) -> np.ndarray:
    """(C, T): False where no joint vector (limits or not) meets target t's orientation within its
    tolerance and its position with it (tilt and wrist in the module docstring); True for the
    targets without an orientation. tg: a reach.Targets. every: (C,) whether every target may be
    met, each test on the settings the cheaper ones left."""
    C, T = len(f.t), len(tg.xyz)
    pointed = tg.pointed if len(tg.pointed) else np.zeros(T, bool)
    full = np.flatnonzero(tg.oriented & ~pointed)
    point = np.flatnonzero(tg.oriented & pointed)
    tests = [(idx, test) for idx, test in ((full, _tilt_ok), (point, _pointing_ok), (full, _wrist_ok),
                                                    (full, _spin)) if idx.size]
    if not every:
        ok = np.ones((C, T), bool)
        for idx, test in tests:
            ok[:, idx] &= test(f, tg, idx)
        return ok
    alive = np.arange(C)
    for idx, test in tests:
        if alive.size:
            alive = alive[test(Frames(f.R[alive], f.t[alive]), tg, idx).all(-1)]
    out = np.zeros(C, bool)
    out[alive] = True
    return out


def blocked(obstacles, xyz: np.ndarray, tol: np.ndarray, tool_reach: float, radius: float, reach: float,
            starts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Targets no arm in the bounds can serve because of an obstacle, and which obstacle ((T,)
    bool, (T,) index or -1). Two sound reasons:

    - inside: tool0 there puts the arm's last frame (within tool_reach + tol of the target) so
      deep in an obstacle that its thinnest segment (radius) collides - a signed distance
      changes no faster than the distance;
    - walled off: a box lies between the arm's start and the target along one of its axes - the
      start is base_link's origin and every unit type's twist1 origin `starts` (K, 3) (the screen
      tests the chain from there), the target side is clear by tool_reach + tol - and the box
      spans the whole ball of radius `reach` (the longest chain in the bounds) around the base
      across that axis: every chain from the base to the target crosses the slab inside the box."""
    T = len(xyz)
    which = np.full(T, -1)
    if len(obstacles.shape) == 0 or T == 0:
        return np.zeros(T, bool), which
    x = np.asarray(xyz, float)
    sd = obstacles.distance(x)  # (T, K)
    inside = sd + tool_reach + tol[:, None] - radius < -1e-3
    for k in range(len(obstacles.shape)):
        if obstacles.shape[k] != 0:
            continue
        s = obstacles.size[k]
        b = -obstacles.centre[k] @ obstacles.R[k]  # base origin in the box frame
        st = (np.vstack([np.zeros(3), starts]) - obstacles.centre[k]) @ obstacles.R[k]
        xs = (x - obstacles.centre[k]) @ obstacles.R[k]
        for a in range(3):
            others = [j for j in range(3) if j != a]
            if any(abs(b[j]) + reach > s[j] for j in others):
                continue
            side = float(np.sign(b[a]))
            if side == 0.0 or not np.all(side * st[:, a] > s[a]):
                continue
            far = side * xs[:, a] < -(s[a] + tool_reach + tol)
            inside[:, k] |= far
    hit = inside.any(-1)
    which[hit] = np.argmax(inside[hit], axis=-1)
    return hit, which
