"""Time parameterisation of a joint-space polyline: the arm stops at every vertex and follows each
straight segment with a trapezoidal velocity profile shared by all joints (synchronised: every
joint starts, cruises and stops together, so the tool stays on the checked straight segment).

Segment qa -> qb, dq = qb - qa, path parameter s in [0, 1], q(t) = qa + s(t) dq:
    s' <= V = min_i v_i / |dq_i|        (every joint within its velocity limit)
    |s''| <= A = min_i a_i / |dq_i|      (and its acceleration limit)
    a trapezoid (accelerate at A, cruise at V, brake at A) when V² / A <= 1, else a triangle
    peaking at sqrt(A) — the fastest motion along the segment that starts and ends at rest.
Limits: velocity = the URDF's (the actuator's rated speed, rad/s); acceleration = velocity /
ACCEL_RAMP_TIME (the rated speed is reached in 0.5 s), the ROS backend's joint_limits.yaml.

Samples: each segment is cut into equal time steps no longer than SAMPLE_PERIOD, and its ends
are points of the output. Between two samples the mean velocity of joint i is at most V |dq_i|
<= v_i, so the finite differences of the output never exceed the limits either.
"""
from __future__ import annotations

import itertools
import math

import numpy as np

from ..physical.constants import ACCEL_RAMP_TIME  # acceleration limit = velocity limit / this

SAMPLE_PERIOD = 0.05  # s between output points (at most)
MIN_MOTION = 1e-9  # rad: a segment whose joints all move less than this is skipped (a repeated vertex)


def segment_limits(dq, vmax, amax) -> tuple[float, float]:
    """(V, A): bounds on s' and s'' for one segment."""
    dq = np.abs(np.asarray(dq, float))
    moving = dq > 0
    if not moving.any():
        return math.inf, math.inf
    V = float(np.min(np.asarray(vmax, float)[moving] / dq[moving]))
    A = float(np.min(np.asarray(amax, float)[moving] / dq[moving]))
    return V, A


def segment_duration(dq, vmax, amax) -> float:
    V, A = segment_limits(dq, vmax, amax)
    if math.isinf(V):
        return 0.0
    if V * V / A <= 1.0:  # trapezoid: reaches V
        return 1.0 / V + V / A
    return 2.0 * math.sqrt(1.0 / A)  # triangle


def s_of_t(t: float, V: float, A: float, T: float) -> float:
    """Path parameter of the trapezoid (or triangle) at time t in [0, T]."""
    if V * V / A <= 1.0:
        ta = V / A
        if t <= ta:
            return 0.5 * A * t * t
        if t <= T - ta:
            return 0.5 * A * ta * ta + V * (t - ta)
        r = T - t
        return 1.0 - 0.5 * A * r * r
    th = T / 2.0
    if t <= th:
        return 0.5 * A * t * t
    r = T - t
    return 1.0 - 0.5 * A * r * r


def path_duration(path, vmax, amax) -> float:
    return sum(segment_duration(b - a, vmax, amax) for a, b in itertools.pairwise(path))


def parameterise(path, vmax, amax, period: float = SAMPLE_PERIOD) -> tuple[list[float], list[np.ndarray]]:
    """Times (strictly increasing, from 0) and joint vectors of the sampled motion."""
    path = [np.asarray(p, float) for p in path]
    ts: list[float] = [0.0]
    qs: list[np.ndarray] = [path[0].copy()]
    t0 = 0.0
    for a, b in itertools.pairwise(path):
        dq = b - a
        T = segment_duration(dq, vmax, amax)
        if T <= 0.0 or float(np.max(np.abs(dq))) < MIN_MOTION:
            continue  # a repeated vertex
        V, A = segment_limits(dq, vmax, amax)
        n = max(1, math.ceil(T / period - 1e-9))
        for k in range(1, n + 1):
            t = T * k / n
            s = 1.0 if k == n else s_of_t(t, V, A, T)
            ts.append(t0 + t)
            qs.append(b.copy() if k == n else a + s * dq)
        t0 += T
    return ts, qs


__all__ = ["ACCEL_RAMP_TIME", "SAMPLE_PERIOD", "parameterise", "path_duration", "s_of_t", "segment_duration",
           "segment_limits"]
