"""modc.design.bounds_tilt's branch and bound compiled with numba: depth first per (setting,
target), the nearer child first, stopping at the first box met or undecided; a setting's other
targets are skipped once one fails, and the failing target moves to the front for the next
settings. The tree and every decision are bounds_tilt's (bounds_exact.box for the position,
the same tilt and the same rules): the answer is the numpy walk's up to the order boxes are
visited in, which does not change it (a pair is possible iff its tree holds a box met or
undecided)."""
from __future__ import annotations

import numpy as np

from . import bounds_exact
from .bounds_exact import GRID, LEVELS, MARGIN, SLACK
from .reach_jit import _CACHED, numba

# sha256 of bounds_exact.py, whose box (and constants) this kernel compiles in: numba keys a
# kernel's cache on its own file alone (tests/test_design_bounds_tilt.py checks it)
SHARED = "94e0b1d924c251a89202696da50b87b355d0b3ea3c266d0751ec901844b37903"
TILT_MARGIN = 1e-2  # bounds_tilt's (tests check they agree)
TILT_SLACK = 1e-9
STACK = GRID * GRID + 4 * (LEVELS + 1) + 4


def _jit(f):
    return numba.njit(cache=_CACHED, nogil=True, error_model="numpy")(f) if numba is not None else f


def _inline(f):
    return numba.njit(cache=_CACHED, nogil=True, error_model="numpy", inline="always")(f) if numba is not None else f


_box = _jit(bounds_exact.box)


@_inline
def _tilt(Q, c2, s2, c3, s3):
    yx = Q[3] + Q[6] * c3 + Q[9] * s3
    yy = Q[4] + Q[7] * c3 + Q[10] * s3
    yz = Q[5] + Q[8] * c3 + Q[11] * s3
    uz = Q[0] * (c2 * yx - s2 * yy) + Q[1] * (s2 * yx + c2 * yy) + Q[2] * yz
    return np.arccos(min(max(uz, -1.0), 1.0))


@_jit
def _judge(p, Qa, Qb, nv, rt, ht, ta, tb, tol, eps, n, tab, c2, s2, c3, s3, k2, k3):
    """One box: 1 met or undecided (the pair is possible), -1 excluded, else its distance at the
    centre (>= 0, the box to split) and its bound terms."""
    h2 = tab[5, k2]
    h3 = tab[5, k3] if n == 3 else 0.0
    # the tilt first: cheaper than the position's bounds, and a box it excludes needs no more
    # (the same decision: a box is excluded when either excludes it)
    dev = abs(_tilt(Qa, c2, s2, c3, s3) - ta)
    dev2 = abs(_tilt(Qb, c2, s2, c3, s3) - tb) if nv == 2 else 0.0
    if dev - (h2 + h3) > eps + TILT_SLACK or dev2 - (h2 + h3) > eps + TILT_SLACK:
        return -1, 0.0, 0.0, 0.0, h2, h3
    d, e2, e3, low = _box(p, rt, ht, c2, s2, c3, s3, tab[0, k2], tab[0, k3], h2, h3)
    if k2 == 0 and k3 == 0:  # the grid's boxes: the first-order bound alone
        low = d - (e2 + e3)
    met = d <= tol and dev <= eps and dev2 <= eps
    out = low > tol + SLACK
    fine = (e2 + e3 < MARGIN and h2 + h3 < TILT_MARGIN) or k2 == LEVELS or k3 == LEVELS
    if met or (not out and fine):
        return 1, d, e2, e3, h2, h3
    if out:
        return -1, d, e2, e3, h2, h3
    return 0, d, e2, e3, h2, h3


@_jit
def _pair(p, Qa, Qb, nv, rt, ht, ta, tb, tol, eps, n, tab, stack):
    g3 = GRID if n == 3 else 1
    top = 0
    for i2 in range(GRID):
        for i3 in range(g3):
            c3 = tab[3, i3] if n == 3 else 1.0
            s3 = tab[4, i3] if n == 3 else 0.0
            v, d, e2, e3, h2, h3 = _judge(p, Qa, Qb, nv, rt, ht, ta, tb, tol, eps, n, tab, tab[3, i2], tab[4, i2],
                                          c3, s3, 0, 0)
            if v == 1:
                return True
            if v == 0:
                stack[top, 0], stack[top, 1], stack[top, 2], stack[top, 3] = tab[3, i2], tab[4, i2], c3, s3
                stack[top, 4], stack[top, 5], stack[top, 6] = 0.0, 0.0, d
                stack[top, 7], stack[top, 8], stack[top, 9], stack[top, 10] = e2, e3, h2, h3
                top += 1
    while top > 0:
        top -= 1
        c2, s2, c3, s3 = stack[top, 0], stack[top, 1], stack[top, 2], stack[top, 3]
        k2, k3 = int(stack[top, 4]), int(stack[top, 5])
        e2, e3, h2, h3 = stack[top, 7], stack[top, 8], stack[top, 9], stack[top, 10]
        along3 = n == 3 and e3 / MARGIN + h3 / TILT_MARGIN > e2 / MARGIN + h2 / TILT_MARGIN
        lv = (k3 if along3 else k2) + 1
        cd, sd = tab[1, lv], tab[2, lv]
        kids = np.empty((2, 11))
        m = 0
        for sign in (1.0, -1.0):
            if along3:
                a2, b2, a3, b3, j2, j3 = c2, s2, c3 * cd - s3 * sd * sign, s3 * cd + c3 * sd * sign, k2, lv
            else:
                a2, b2, a3, b3, j2, j3 = c2 * cd - s2 * sd * sign, s2 * cd + c2 * sd * sign, c3, s3, lv, k3
            v, d, f2, f3, g2, g3_ = _judge(p, Qa, Qb, nv, rt, ht, ta, tb, tol, eps, n, tab, a2, b2, a3, b3, j2, j3)
            if v == 1:
                return True
            if v == 0:
                kids[m, 0], kids[m, 1], kids[m, 2], kids[m, 3] = a2, b2, a3, b3
                kids[m, 4], kids[m, 5], kids[m, 6] = j2, j3, d
                kids[m, 7], kids[m, 8], kids[m, 9], kids[m, 10] = f2, f3, g2, g3_
                m += 1
        if m == 2 and kids[0, 6] < kids[1, 6]:  # the farther pushed first: the nearer is walked first
            for a in range(11):
                kids[0, a], kids[1, a] = kids[1, a], kids[0, a]
        for i in range(m):
            for a in range(11):
                stack[top, a] = kids[i, a]
            top += 1
    return False


@_jit
def _posed(P, Qa, Qb, nv, rt, ht, ta, tb, tol, eps, n, order, tab):
    """(C,) every target (its columns, in `order`) possible for setting c."""
    C, T = rt.shape
    out = np.zeros(C, np.bool_)
    stack = np.empty((STACK, 11))
    order = order.copy()
    for c in range(C):
        ok = True
        for i in range(T):
            j = order[i]
            if not _pair(P[c], Qa[j, c], Qb[j, c], nv[j], rt[c, j], ht[c, j], ta[c, j], tb[c, j], tol[j], eps[j], n,
                         tab, stack):
                ok = False
                for m in range(i, 0, -1):  # the failing target first for the next settings
                    order[m] = order[m - 1]
                order[0] = j
                break
        out[c] = ok
    return out


def posed(P, Qa, Qb, nv, rt, ht, ta, tb, tol, eps, n, order, tab) -> np.ndarray:
    f = np.ascontiguousarray
    return _posed(f(P, float), f(Qa, float), f(Qb, float), f(nv, np.int64), f(rt, float), f(ht, float), f(ta, float),
                  f(tb, float), f(tol, float), f(eps, float), int(n), f(order, np.int64), f(tab, float))


__all__ = ["numba", "posed"]
