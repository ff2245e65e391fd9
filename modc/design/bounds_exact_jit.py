"""modc.design.bounds_exact's branch and bound compiled with numba (imported once modc.design.reach
has loaded numba, or by the tests): depth first per (setting, target), the nearest box first,
stopping at the first reachable box; a setting's other targets are skipped once one fails, and
the failing target moves to the front of the order for the next settings. The tree and every
decision are bounds_exact's (the same operations in the same order, the same tables): the
answer is the numpy walk's."""
from __future__ import annotations

import numpy as np

from . import bounds_exact
from .bounds_exact import GRID, LEVELS, MARGIN, SLACK, STEPS
from .reach_jit import _CACHED, numba

# sha256 of bounds_exact.py, whose box and newton (and constants) these kernels compile in: numba
# keys a kernel's cache on its own file alone, so a change there must change this file too
# (tests/test_design_bounds_exact.py checks it)
SHARED = "94e0b1d924c251a89202696da50b87b355d0b3ea3c266d0751ec901844b37903"


def _jit(f):
    # error_model="numpy": a float division by zero gives numpy's inf or nan (the numpy walk's
    # answer), never an exception, and costs no check
    return numba.njit(cache=_CACHED, nogil=True, error_model="numpy")(f) if numba is not None else f


def _inline(f):
    return numba.njit(cache=_CACHED, nogil=True, error_model="numpy", inline="always")(f) if numba is not None else f

STACK = GRID * GRID + 2 * (2 * LEVELS + 2)  # depth first: a level leaves at most one sibling behind

_box = _inline(bounds_exact.box)
_newton = _jit(bounds_exact.newton)


@_inline
def _first(p, rt, ht, c2, s2, c3, s3, S2, S3):
    """box's d and B terms alone (the same operations): a box they exclude needs no more."""
    wx = p[12] + p[15] * c3 + p[18] * s3
    wy = p[13] + p[16] * c3 + p[19] * s3
    wz = p[14] + p[17] * c3 + p[20] * s3
    ux = c2 * wx - s2 * wy
    uy = s2 * wx + c2 * wy
    vx = p[0] + p[3] * ux + p[4] * uy + p[5] * wz
    vy = p[1] + p[6] * ux + p[7] * uy + p[8] * wz
    vz = p[2] + p[9] * ux + p[10] * uy + p[11] * wz
    rho = np.sqrt(vx * vx + vy * vy)
    dr = rho - rt
    dh = vz - ht
    d = np.sqrt(dr * dr + dh * dh)
    r2 = np.sqrt(wx * wx + wy * wy)
    return d, r2 * S2, p[21] * S3


@_jit
def _child(p, rt, ht, c2, s2, c3, s3, k2, k3, tab, tolx):
    """A box's d, B terms and lower bound; the lower bound is d - B when that excludes it (box's
    maximum of the two bounds excludes it then too: the same decision). Not inlined: inlined,
    with its two returns, it once gave other answers than the numpy walk (cause not found)."""
    d, e2, e3 = _first(p, rt, ht, c2, s2, c3, s3, tab[0, k2], tab[0, k3])
    if d - (e2 + e3) > tolx:
        return d, e2, e3, d - (e2 + e3)
    return _box(p, rt, ht, c2, s2, c3, s3, tab[0, k2], tab[0, k3], tab[5, k2], tab[5, k3])


@_inline
def _push(stack, top, c2, s2, c3, s3, k2, k3, d, e2, e3, low):
    stack[top, 0], stack[top, 1], stack[top, 2], stack[top, 3] = c2, s2, c3, s3
    stack[top, 4], stack[top, 5], stack[top, 6], stack[top, 7] = k2, k3, d, e2
    stack[top, 8], stack[top, 9] = e3, low
    return top + 1


@_jit
def _pair(p, rt, ht, tol, n, tab, stack):
    """Whether the tree of one (setting, target) pair (p: the setting's row of bounds_exact.params)
    holds a reachable or undecided box."""
    tolx = tol + SLACK
    g3 = GRID if n == 3 else 1
    top = 0
    for i2 in range(GRID):
        for i3 in range(g3):
            c3 = tab[3, i3] if n == 3 else 1.0
            s3 = tab[4, i3] if n == 3 else 0.0
            d, e2, e3 = _first(p, rt, ht, tab[3, i2], tab[4, i2], c3, s3, tab[0, 0], tab[0, 0])
            low = d - (e2 + e3)
            if d <= tol:
                return True
            top = _push(stack, top, tab[3, i2], tab[4, i2], c3, s3, 0.0, 0.0, d, e2, e3, low)
    for i in range(1, top):  # nearest last (popped first): insertion sort, farthest first
        j = i
        while j > 0 and stack[j - 1, 6] < stack[j, 6]:
            for a in range(10):
                stack[j - 1, a], stack[j, a] = stack[j, a], stack[j - 1, a]
            j -= 1
    for m in range(1, min(2, top) + 1):  # a witness from the two nearest centres spares most walks
        c2, s2, c3, s3 = stack[top - m, 0], stack[top - m, 1], stack[top - m, 2], stack[top - m, 3]
        for _ in range(STEPS + 1):
            d, c2, s2, c3, s3 = _newton(p, rt, ht, c2, s2, c3, s3)
            if d <= tol:
                return True
    while top > 0:
        top -= 1
        c2, s2, c3, s3 = stack[top, 0], stack[top, 1], stack[top, 2], stack[top, 3]
        k2, k3, e2, e3, low = int(stack[top, 4]), int(stack[top, 5]), stack[top, 7], stack[top, 8], stack[top, 9]
        if low > tolx:
            continue
        if e2 + e3 < MARGIN or k2 == LEVELS or k3 == LEVELS:
            return True
        along3 = e3 > e2
        lv = (k3 if along3 else k2) + 1
        cd = tab[1, lv]
        sd = tab[2, lv]
        nd = tab[2, lv] * -1.0
        if along3:
            a0, b0, a1, b1 = c3 * cd - s3 * sd, s3 * cd + c3 * sd, c3 * cd - s3 * nd, s3 * cd + c3 * nd
            d0, f0, g0, l0 = _child(p, rt, ht, c2, s2, a0, b0, k2, lv, tab, tolx)
            d1, f1, g1, l1 = _child(p, rt, ht, c2, s2, a1, b1, k2, lv, tab, tolx)
        else:
            a0, b0, a1, b1 = c2 * cd - s2 * sd, s2 * cd + c2 * sd, c2 * cd - s2 * nd, s2 * cd + c2 * nd
            d0, f0, g0, l0 = _child(p, rt, ht, a0, b0, c3, s3, lv, k3, tab, tolx)
            d1, f1, g1, l1 = _child(p, rt, ht, a1, b1, c3, s3, lv, k3, tab, tolx)
        if d0 <= tol or d1 <= tol:
            return True
        if d0 < d1:  # the farther pushed first: the nearer is walked first
            a0, b0, d0, f0, g0, l0, a1, b1, d1, f1, g1, l1 = a1, b1, d1, f1, g1, l1, a0, b0, d0, f0, g0, l0
        if along3:
            top = _push(stack, top, c2, s2, a0, b0, k2, lv, d0, f0, g0, l0)
            top = _push(stack, top, c2, s2, a1, b1, k2, lv, d1, f1, g1, l1)
        else:
            top = _push(stack, top, a0, b0, c3, s3, lv, k3, d0, f0, g0, l0)
            top = _push(stack, top, a1, b1, c3, s3, lv, k3, d1, f1, g1, l1)
    return False


@_jit
def _reachable(P, rt, ht, tol, n, order, tab):
    C, T = rt.shape
    out = np.zeros(C, np.bool_)
    stack = np.empty((STACK, 10))
    order = order.copy()
    for c in range(C):
        ok = True
        for i in range(T):
            j = order[i]
            if not _pair(P[c], rt[c, j], ht[c, j], tol[j], n, tab, stack):
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
