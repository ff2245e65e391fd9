"""modc.design.bounds_exact's branch and bound compiled with numba (imported once modc.design.reach
has loaded numba, or by the tests): depth first per (setting, target), the nearest box first,
stopping at the first reachable box; a setting's other targets are skipped once one fails, and
the failing target moves to the front of the order for the next settings. The tree and every
decision are bounds_exact's (the same operations in the same order, the same tables): the
answer is the numpy walk's."""
from __future__ import annotations

import numpy as np

from .bounds_exact import GRID, LEVELS, MARGIN, SLACK
from .reach_jit import _inline, _jit, numba

STACK = GRID * GRID + 2 * (2 * LEVELS + 2)  # depth first: a level leaves at most one sibling behind


@_inline
def _eval(P, c, rt, ht, c2, s2, c3, s3):
    wx = P[c, 12] + P[c, 15] * c3 + P[c, 18] * s3
    wy = P[c, 13] + P[c, 16] * c3 + P[c, 19] * s3
    wz = P[c, 14] + P[c, 17] * c3 + P[c, 20] * s3
    ux = c2 * wx - s2 * wy
    uy = s2 * wx + c2 * wy
    vx = P[c, 0] + P[c, 3] * ux + P[c, 4] * uy + P[c, 5] * wz
    vy = P[c, 1] + P[c, 6] * ux + P[c, 7] * uy + P[c, 8] * wz
    vz = P[c, 2] + P[c, 9] * ux + P[c, 10] * uy + P[c, 11] * wz
    dr = np.sqrt(vx * vx + vy * vy) - rt
    dh = vz - ht
    return np.sqrt(dr * dr + dh * dh), np.sqrt(wx * wx + wy * wy)


@_inline
def _push(box, top, c2, s2, c3, s3, k2, k3, d, r2):
    box[top, 0], box[top, 1], box[top, 2], box[top, 3] = c2, s2, c3, s3
    box[top, 4], box[top, 5], box[top, 6], box[top, 7] = k2, k3, d, r2
    return top + 1


@_jit
def _pair(P, c, rt, ht, tol, n, tab, box):
    """Whether the tree of (setting c, target) holds a reachable or undecided box."""
    tolx = tol + SLACK
    r3 = P[c, 21]
    g3 = GRID if n == 3 else 1
    top = 0
    for i2 in range(GRID):
        for i3 in range(g3):
            c3 = tab[3, i3] if n == 3 else 1.0
            s3 = tab[4, i3] if n == 3 else 0.0
            d, r2 = _eval(P, c, rt, ht, tab[3, i2], tab[4, i2], c3, s3)
            if d <= tol:
                return True
            top = _push(box, top, tab[3, i2], tab[4, i2], c3, s3, 0.0, 0.0, d, r2)
    for i in range(1, top):  # nearest last (popped first): insertion sort, farthest first
        j = i
        while j > 0 and box[j - 1, 6] < box[j, 6]:
            for a in range(8):
                box[j - 1, a], box[j, a] = box[j, a], box[j - 1, a]
            j -= 1
    while top > 0:
        top -= 1
        c2, s2, c3, s3 = box[top, 0], box[top, 1], box[top, 2], box[top, 3]
        k2, k3, d, r2 = int(box[top, 4]), int(box[top, 5]), box[top, 6], box[top, 7]
        e2, e3 = r2 * tab[0, k2], r3 * tab[0, k3]
        bound = e2 + e3
        if d - bound > tolx:
            continue
        if bound < MARGIN or k2 == LEVELS or k3 == LEVELS:
            return True
        along3 = e3 > e2
        lv = (k3 if along3 else k2) + 1
        cd = tab[1, lv]
        sd = tab[2, lv]
        nd = tab[2, lv] * -1.0
        if along3:
            a0, b0, a1, b1 = c3 * cd - s3 * sd, s3 * cd + c3 * sd, c3 * cd - s3 * nd, s3 * cd + c3 * nd
            d0, q0 = _eval(P, c, rt, ht, c2, s2, a0, b0)
            d1, q1 = _eval(P, c, rt, ht, c2, s2, a1, b1)
        else:
            a0, b0, a1, b1 = c2 * cd - s2 * sd, s2 * cd + c2 * sd, c2 * cd - s2 * nd, s2 * cd + c2 * nd
            d0, q0 = _eval(P, c, rt, ht, a0, b0, c3, s3)
            d1, q1 = _eval(P, c, rt, ht, a1, b1, c3, s3)
        if d0 <= tol or d1 <= tol:
            return True
        if d0 < d1:  # the farther pushed first: the nearer is walked first
            a0, b0, d0, q0, a1, b1, d1, q1 = a1, b1, d1, q1, a0, b0, d0, q0
        if along3:
            top = _push(box, top, c2, s2, a0, b0, k2, lv, d0, q0)
            top = _push(box, top, c2, s2, a1, b1, k2, lv, d1, q1)
        else:
            top = _push(box, top, a0, b0, c3, s3, lv, k3, d0, q0)
            top = _push(box, top, a1, b1, c3, s3, lv, k3, d1, q1)
    return False


@_jit
def _reachable(P, rt, ht, tol, n, order, tab):
    C, T = rt.shape
    out = np.zeros(C, np.bool_)
    box = np.empty((STACK, 8))
    order = order.copy()
    for c in range(C):
        ok = True
        for i in range(T):
            j = order[i]
            if not _pair(P, c, rt[c, j], ht[c, j], tol[j], n, tab, box):
                ok = False
                for m in range(i, 0, -1):  # the failing target first for the next settings
                    order[m] = order[m - 1]
                order[0] = j
                break
        out[c] = ok
    return out


def reachable(P, rt, ht, tol, n, order, tab) -> np.ndarray:
    return _reachable(np.ascontiguousarray(P, float), np.ascontiguousarray(rt, float),
                      np.ascontiguousarray(ht, float), np.ascontiguousarray(tol, float), int(n),
                      np.ascontiguousarray(order, np.int64), np.ascontiguousarray(tab, float))


__all__ = ["numba", "reachable"]
