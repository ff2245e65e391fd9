"""Time-optimal timing of a task's segments under every joint's speed and peak-torque limits
(docs/language.md: `cycle_time`, `energy`), by toppra (reachability analysis, Pham & Pham 2018)
with pinocchio's inverse dynamics (RNEA) for the torque constraint.

    limits = Limits.of(robot)                      # rated speed (library RPM), peak torque
    timed = time_polyline(path, limits)            # a joint-space polyline: rest at every vertex
    timed = time_smooth(path, limits)              # dense waypoints (a straight tool path): one spline

A polyline (the planner's certified collision-free motion) is timed edge by edge, each a
straight joint-space line from rest to rest: the arm follows exactly the edges that were
certified. Dense waypoints along a Cartesian path are joined by a cubic spline through them and
timed in one go, from rest to rest.

toppra holds the constraints at its grid points; between them the constant-acceleration
parametrisation may exceed them slightly, so the limits handed to it are LIMIT_SHARE of the
real ones. Every sample of the result carries q, q̇, q̈ and τ = RNEA(q, q̇, q̈) with the payload:
energy = ∫|τ·q̇| dt (trapezoidal rule over the samples), peak share = max |τ_i| / τ_peak,i. The
samples are every SAMPLE_PERIOD and at toppra's knots (where the acceleration switches).
"""
from __future__ import annotations

import itertools
import logging
from dataclasses import dataclass

import numpy as np

from ..model import ResolvedRobot

LIMIT_SHARE = 0.98  # of each speed and torque limit, given to toppra (it checks at grid points only)
GRID_POINTS = 120  # toppra grid points per timed piece
SAMPLE_PERIOD = 0.01  # s between samples of a timed piece (energy, torque, the output trajectory)
MIN_MOTION = 1e-9  # rad: a piece shorter than this is no motion
MAX_STRETCHES = 8


class TimingError(RuntimeError):
    """toppra found no parametrisation (a pose the arm cannot hold under its peak torque)."""


@dataclass(frozen=True)
class Limits:
    velocity: np.ndarray  # rad/s per joint: the actuator's rated speed (library RPM)
    torque: np.ndarray  # N·m per joint: the actuator's peak torque
    dynamics: object  # modc.dynamics.model.Dynamics (with the robot's payload)

    @classmethod
    def of(cls, robot: ResolvedRobot) -> Limits:
        from ..dynamics.model import Dynamics

        acts = [robot.library.variants[u.variant].actuator for u in robot.units]
        return cls(np.array([a.velocity for a in acts]), np.array([a.torque_peak for a in acts]), Dynamics(robot))

    def rnea(self, q, v, a) -> np.ndarray:
        return self.dynamics.rnea(q, v, a)  # type: ignore[attr-defined]


@dataclass(frozen=True)
class Timed:
    """A timed motion, sampled: t (s, from 0), q, qd, qdd (rad, /s, /s²) and tau (N·m) per sample."""

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    tau: np.ndarray
    limits: Limits
    # over toppra's knot intervals (_knot_figures), when known: its ramps can be shorter than a sample
    exact_energy: float | None = None
    exact_peak: float | None = None

    @property
    def duration(self) -> float:
        return float(self.t[-1]) if len(self.t) else 0.0

    @property
    def energy(self) -> float:
        """∫|τ·q̇| dt, J."""
        if self.exact_energy is not None:
            return self.exact_energy
        power = np.abs(np.einsum("ij,ij->i", self.tau, self.qd))
        return float(np.sum((power[1:] + power[:-1]) * np.diff(self.t)) / 2.0) if len(self.t) > 1 else 0.0

    @property
    def peak_share(self) -> float:
        """max over samples and joints of |τ_i| / τ_peak,i."""
        sampled = float(np.max(np.abs(self.tau) / self.limits.torque)) if len(self.t) else 0.0
        return sampled if self.exact_peak is None else max(sampled, self.exact_peak)

    @property
    def speed_share(self) -> float:
        """max over joints of the speed over the speed limit: at the samples, and between them as
        the written trajectory moves (linearly from sample to sample: a chord can be faster than
        both its ends where toppra's speed peaks between two samples)."""
        if not len(self.t):
            return 0.0
        sampled = float(np.max(np.abs(self.qd) / self.limits.velocity))
        if len(self.t) < 2:
            return sampled
        chords = np.abs(np.diff(self.q, axis=0)) / np.diff(self.t)[:, None]
        return max(sampled, float(np.max(chords / self.limits.velocity)))


def _toppra_piece(path, limits: Limits, grid_points: int = GRID_POINTS):
    """toppra's time-optimal trajectory along path (a toppra interpolator), rest to rest."""
    import toppra.algorithm as algo
    import toppra.constraint as constraint

    # toppra's own chatter stays quiet (its setup_logging would add a console handler per call)
    logging.getLogger("toppra").setLevel(logging.ERROR)
    vlim = LIMIT_SHARE * limits.velocity
    tlim = LIMIT_SHARE * limits.torque
    vel = constraint.JointVelocityConstraint(np.column_stack([-vlim, vlim]))
    tau = constraint.JointTorqueConstraint(
        lambda q, v, a: limits.rnea(q, v, a), np.column_stack([-tlim, tlim]), np.zeros(len(tlim)),
        discretization_scheme=constraint.DiscretizationType.Interpolation)
    lo, hi = path.path_interval
    grid = np.linspace(lo, hi, max(GRID_POINTS, grid_points))
    solver = algo.TOPPRA([vel, tau], path, gridpoints=grid, parametrizer="ParametrizeConstAccel")
    traj = solver.compute_trajectory(0.0, 0.0)
    if traj is None:
        raise TimingError("no time parametrisation within the speed and peak-torque limits")
    return traj


def _sampled(traj, limits: Limits) -> Timed:
    """Samples of toppra's trajectory; slowed down uniformly (t -> k t) if a sample still exceeds
    a limit (between toppra's grid points): speeds shrink by 1/k, the dynamic torques by about 1/k²."""
    k = 1.0
    for _ in range(MAX_STRETCHES):
        timed = _at_scale(traj, limits, k)
        over = max(timed.speed_share, float(np.max(np.abs(timed.tau - _static(timed)) /
                                                   np.maximum(limits.torque - np.abs(_static(timed)), 1e-9))))
        if timed.speed_share <= 1.0 and timed.peak_share <= 1.0:
            return timed
        k *= max(timed.speed_share, np.sqrt(max(over, 1.0)), 1.0) * 1.002
    return timed


def _static(timed: Timed) -> np.ndarray:
    z = np.zeros(timed.q.shape[1])
    return np.array([timed.limits.rnea(q, z, z) for q in timed.q])


def _at_scale(traj, limits: Limits, k: float) -> Timed:
    T = float(traj.duration) * k
    n = max(2, int(np.ceil(T / SAMPLE_PERIOD)) + 1)
    # every SAMPLE_PERIOD, and at toppra's knots, where its piecewise-constant path acceleration
    # switches: a torque-limited start or stop can last ~2 ms, between two periodic samples, and
    # the energy, the peak torque and the written trajectory would all miss it (toppra keeps the
    # knots in `_ts`, with no public accessor: without them, the periodic samples alone)
    knots = np.asarray(getattr(traj, "_ts", None) if getattr(traj, "_ts", None) is not None else [], float) * k
    t = np.union1d(np.linspace(0.0, T, n), knots[(knots > 0.0) & (knots < T)])
    t = t[np.concatenate([[True], np.diff(t) > 1e-6])]  # (a knot on a periodic sample: once)
    q, qd, qdd = (np.atleast_2d(traj(t / k, o)) / k**o for o in (0, 1, 2))
    qd[0] = qd[-1] = 0.0  # from rest to rest: the spline's end derivatives are 0 up to rounding
    tau = np.array([limits.rnea(a, b, c) for a, b, c in zip(q, qd, qdd, strict=True)])
    energy, peak = _knot_figures(traj, limits, k)
    return Timed(t, q, qd, qdd, tau, limits, energy, peak)


def _knot_figures(traj, limits: Limits, k: float) -> tuple[float | None, float | None]:
    """∫|τ·q̇| dt and the peak torque share, knot interval by knot interval of toppra's
    trajectory (its path acceleration is constant on each): Simpson's rule on the interval's
    inside (its ends a millionth of it in, so each takes the interval's own acceleration)."""
    knots = getattr(traj, "_ts", None)
    if knots is None or len(knots) < 2:
        return None, None
    a, b = np.asarray(knots[:-1], float), np.asarray(knots[1:], float)
    keep = b - a > 1e-12
    a, b = a[keep], b[keep]
    d = 1e-6 * (b - a)
    ts = np.stack([a + d, (a + b) / 2, b - d], axis=1).reshape(-1)  # in toppra's time
    q, qd, qdd = (np.atleast_2d(traj(ts, o)) / k**o for o in (0, 1, 2))
    tau = np.array([limits.rnea(x, v, w) for x, v, w in zip(q, qd, qdd, strict=True)])
    power = np.abs(np.einsum("ij,ij->i", tau, qd)).reshape(-1, 3)
    width = k * (b - a - 2 * d)
    energy = float(np.sum(width / 6.0 * (power[:, 0] + 4 * power[:, 1] + power[:, 2])))
    return energy, float(np.max(np.abs(tau) / limits.torque))


def _concat(pieces: list[Timed], limits: Limits, q0) -> Timed:
    if not pieces:
        z = np.zeros((1, len(q0)))
        q0 = np.asarray(q0, float)[None, :]
        return Timed(np.zeros(1), q0, z, z.copy(), np.array([limits.rnea(q0[0], z[0], z[0])]), limits)
    ts, qs, qds, qdds, taus = [pieces[0].t], [pieces[0].q], [pieces[0].qd], [pieces[0].qdd], [pieces[0].tau]
    offset = pieces[0].duration
    for p in pieces[1:]:  # each piece starts where (and at rest as) the previous one ended: drop its first sample
        ts.append(p.t[1:] + offset)
        qs.append(p.q[1:])
        qds.append(p.qd[1:])
        qdds.append(p.qdd[1:])
        taus.append(p.tau[1:])
        offset += p.duration
    exact = all(p.exact_energy is not None for p in pieces)
    return Timed(np.concatenate(ts), np.vstack(qs), np.vstack(qds), np.vstack(qdds), np.vstack(taus), limits,
                 sum(p.energy for p in pieces) if exact else None,
                 max(p.peak_share for p in pieces) if exact else None)


def time_polyline(path, limits: Limits) -> Timed:
    """Each straight joint-space edge timed from rest to rest, in turn."""
    import toppra

    pieces = []
    for a, b in itertools.pairwise([np.asarray(p, float) for p in path]):
        if float(np.max(np.abs(b - a))) < MIN_MOTION:
            continue
        line = toppra.SplineInterpolator([0.0, 1.0], np.vstack([a, b]))
        pieces.append(_sampled(_toppra_piece(line, limits), limits))
    return _concat(pieces, limits, path[0])


def time_smooth(path, limits: Limits) -> Timed:
    """A cubic spline through dense waypoints (parametrised by joint-space arc length), from rest to rest."""
    import toppra

    qs = [np.asarray(path[0], float)]
    for p in path[1:]:
        if float(np.max(np.abs(np.asarray(p, float) - qs[-1]))) >= MIN_MOTION:
            qs.append(np.asarray(p, float))
    if len(qs) < 2:
        return _concat([], limits, qs[0])
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(qs, axis=0), axis=1))])
    spline = toppra.SplineInterpolator(s / s[-1], np.vstack(qs), bc_type="clamped")
    return _sampled(_toppra_piece(spline, limits, 4 * len(qs)), limits)


def join(pieces: list[Timed], limits: Limits, q0) -> Timed:
    """Timed motions one after the other (each ends at rest where the next starts)."""
    return _concat([p for p in pieces if len(p.t) > 1], limits, q0)


__all__ = ["LIMIT_SHARE", "Limits", "Timed", "TimingError", "join", "time_polyline", "time_smooth"]
