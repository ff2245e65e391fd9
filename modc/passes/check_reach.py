"""Targets lie within the arm's reach: a cheap, sound bound (warning target-out-of-reach).

Joint_1's origin O lies on its axis and never moves. Between consecutive joint origins, and from
the last joint's origin to tool0, the distance is fixed whatever the joint angles (each joint
turns about an axis through its own origin). So tool0 is joined to O by a chain of segments of
known lengths l_0 … l_n, and in every configuration

    max(0, 2 max_k l_k - sum_k l_k)  <=  |tool0 - O|  <=  sum_k l_k

(triangle inequality; joint limits only shrink the set). A target outside this shell by more
than its position tolerance cannot be reached by any joint angles: that is a proof, so the
warning never fires on a reachable target. The converse does not hold (obstacles, limits and
orientation are `modc plan`'s business).

The lengths come from the paper's per-unit frames (eqs. 4-6, modc.kinematics) at q = 0, computed
here in plain Python: `modc lint` runs this pass and imports no numpy.
"""
from __future__ import annotations

import math
from typing import TypeGuard

from ..diagnostics import codes
from ..model import Design, ResolvedRobot, Robot
from .context import Context

_Mat = tuple[tuple[float, float, float], ...]
_Vec = tuple[float, float, float]
EPS = 1e-9  # m: rounding of the sums below


def _rx(a: float) -> _Mat:
    c, s = math.cos(a), math.sin(a)
    return ((1.0, 0.0, 0.0), (0.0, c, -s), (0.0, s, c))


def _ry(a: float) -> _Mat:
    c, s = math.cos(a), math.sin(a)
    return ((c, 0.0, s), (0.0, 1.0, 0.0), (-s, 0.0, c))


def _mul(A: _Mat, B: _Mat) -> _Mat:
    def row(i: int) -> _Vec:
        return (A[i][0] * B[0][0] + A[i][1] * B[1][0] + A[i][2] * B[2][0],
                A[i][0] * B[0][1] + A[i][1] * B[1][1] + A[i][2] * B[2][1],
                A[i][0] * B[0][2] + A[i][1] * B[1][2] + A[i][2] * B[2][2])

    return (row(0), row(1), row(2))


def _apply(A: _Mat, v: _Vec) -> _Vec:
    return (A[0][0] * v[0] + A[0][1] * v[1] + A[0][2] * v[2],
            A[1][0] * v[0] + A[1][1] * v[1] + A[1][2] * v[2],
            A[2][0] * v[0] + A[2][1] * v[1] + A[2][2] * v[2])


def _add(a: _Vec, b: _Vec) -> _Vec:
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def _dist(a: _Vec, b: _Vec) -> float:
    return math.dist(a, b)


def chain_points(robot: ResolvedRobot) -> list[_Vec]:
    """Joint origins 1 … n and tool0 in base_link at q = 0 (the frames of modc.kinematics.Chain)."""
    lib = robot.library
    R: _Mat = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    p: _Vec = (0.0, 0.0, 0.0)
    points: list[_Vec] = []
    for u in robot.units:
        t = lib.units[u.kind]
        p = _add(p, _apply(R, (t.x01, 0.0, t.z01)))  # eq. 4: unit base -> twist1
        R = _mul(R, _ry(u.pivot))
        p = _add(p, _apply(R, (0.0, 0.0, t.z12)))  # eq. 5 at q = 0: twist1 -> joint
        points.append(p)
        if t.link:  # eq. 6: joint -> twist2 at the end of the link module
            p = _add(p, _apply(R, (robot.link_length(u), 0.0, 0.0)))
            R = _mul(R, _rx(u.port))
    points.append(_add(p, _apply(R, robot.tool.xyz)))
    return points


def reach_shell(robot: ResolvedRobot) -> tuple[_Vec, float, float, float]:
    """(O, r_min, r_max, longest): joint_1's origin in base_link, the bounds on |tool0 - O| (m)
    and the longest fixed segment of the chain."""
    pts = chain_points(robot)
    lengths = [_dist(a, b) for a, b in zip(pts, pts[1:], strict=False)]
    total = math.fsum(lengths)
    longest = max(lengths, default=0.0)
    return pts[0], max(0.0, 2.0 * longest - total), total, longest


def _m(x: float, other: float) -> str:
    """x in metres, with enough digits to differ from `other` where they differ."""
    for digits in (3, 4, 6):
        s = f"{x:.{digits}f}"
        if s != f"{other:.{digits}f}":
            return s
    return f"{x:.6f}"


def _checkable(robot: Robot) -> TypeGuard[ResolvedRobot]:
    if not isinstance(robot, ResolvedRobot) or not robot.units or not robot.targets:
        return False
    lib = robot.library
    if any(not u.variant or u.kind not in lib.units for u in robot.units):
        return False
    numbers = [robot.link_length(u) for u in robot.units] + [*robot.tool.xyz]
    numbers += [v for t in robot.targets for v in t.xyz]
    return all(math.isfinite(v) for v in numbers)


def run(design: Design, ctx: Context) -> Design:
    for r in design.robots:
        if not _checkable(r):
            continue
        origin, r_min, r_max, longest = reach_shell(r)
        if not all(math.isfinite(v) for v in (*origin, r_min, r_max)):
            continue  # beyond any real arm: out-of-range has said so
        at = "(" + ", ".join(f"{v:.3f}" for v in origin) + ") m"
        for t in r.targets:
            d = _dist(t.xyz, origin)
            if not math.isfinite(d):
                continue
            slack = t.position_tolerance + EPS
            if d > r_max + slack:
                ctx.report(codes.TARGET_OUT_OF_REACH.at(
                    t.span, target=t.name, distance=_m(d, r_max), bound=f"within {_m(r_max, d)} m of it",
                    hint=f"joint_1 is at {at} in base_link: move the target within {r_max:.3f} m of it, or "
                         "lengthen the arm (link=…, more units)"), r)
            elif d < r_min - slack:
                ctx.report(codes.TARGET_OUT_OF_REACH.at(
                    t.span, target=t.name, distance=_m(d, r_min), bound=f"at least {_m(r_min, d)} m from it",
                    hint=f"joint_1 is at {at} in base_link and the arm cannot fold closer (its longest fixed "
                         f"segment is {longest:.3f} m, the others add up to {r_max - longest:.3f} m): move the target "
                         f"at least {r_min:.3f} m away from it"), r)
    return design
