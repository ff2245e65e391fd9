"""Evaluating candidate chains: the fast screen over many twist settings at once (screen_batch),
and the exact check of one design with modc's own analyses (verify).

screen_batch: batched IK per target within the joint limits (position, or 6-D with an
orientation), then the sphere-swept obstacle screen on the solutions found; a solution that
collides gets one retry aimed off the target's centre, inside its tolerance, away from the
obstacle (clear_within: a target is met anywhere within its tolerance). Fast and approximate:
it decides what is worth checking.

verify: the one place a design is accepted. It writes the design as a robot, checks it with the
compiler's passes and analyses (check_text: assembly rules, twists, poses within limits, the
torque check with the payload), re-measures every target with modc.kinematics.Chain, and tests
the chosen joint vectors with modc.physical.checker.CollisionChecker (the emitted meshes against
the cell and against themselves beyond the SRDF's disabled pairs). A faster physical model
(pinocchio/coal built in memory) drops in behind these same calls.
"""
from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..model import Pose, ResolvedProblem, ResolvedRobot, Robot, UnitSpec
from . import reach
from .batch import Geometry, forward, geometry
from .screen import Obstacles, collides, escape, segment_radii
from .space import Shape

SEEDS = 4  # IK starts per target (the zero pose first)
FEW = 2048  # candidates left for a target: their remaining seeds run in one batch
VERIFY_MARGIN = 0.001  # m kept from the cell and between links in the chosen poses
RETRY_SHARE = 0.9  # of a position tolerance: how far off its centre a colliding run's retry aims
RETRY_ITERATIONS = 12  # IK iterations of that retry (it starts a tolerance away, from a solution)
RETRY = True  # that retry (off: tests compare)


@dataclass(frozen=True)
class Spec:
    """What a worker needs to screen shapes of one problem (picklable)."""

    problem: ResolvedProblem
    targets: reach.Targets
    obstacles: Obstacles
    radii: np.ndarray
    lower: float
    upper: float

    @classmethod
    def of(cls, problem: ResolvedProblem) -> Spec:
        lib = problem.cell.library
        lower = max(v.joint_range[0] for v in lib.variants.values())
        upper = min(v.joint_range[1] for v in lib.variants.values())
        return cls(problem, reach.Targets.of(problem.cell.targets), Obstacles.of(problem.cell.obstacles),
                   segment_radii(lib), float(lower), float(upper))


@dataclass
class Screened:
    """Per candidate (C): feasible; a score (0 when feasible; else how far from it); per target
    the closest position error (C, T), whether an IK run got within tolerance at all (C, T,
    collisions aside), whether the target was tried; per feasible candidate its worst error as
    a share of the tolerance (0: dead on, 1: at the edge; 1 + the share where a target was met
    only by the retry inside its tolerance, clear_within) and the joint vectors that pass the
    screen, best first (solution(j), built on demand: a search keeps a few of thousands)."""

    feasible: np.ndarray
    score: np.ndarray
    closest: np.ndarray
    hit: np.ndarray = field(default_factory=lambda: np.zeros(0))
    tried: np.ndarray = field(default_factory=lambda: np.zeros(0))
    worst: np.ndarray = field(default_factory=lambda: np.zeros(0))
    reached: np.ndarray = field(default_factory=lambda: np.zeros(0))  # (C, T): within tolerance, clear of the cell
    runs: tuple = ()  # q (C, T, S, n), ratio (C, T, S), passed (C, T, S) of every run

    def solution(self, j: int) -> list[list[np.ndarray]]:
        """The j-th feasible candidate's joint vectors per target, best first."""
        q, ratio, passed = self.runs
        cand = int(np.flatnonzero(self.feasible)[j])
        out = []
        for t in range(ratio.shape[1]):
            order = np.argsort(ratio[cand, t] + 1e3 * ~passed[cand, t], kind="stable")
            out.append([q[cand, t, s] for s in order if passed[cand, t, s]])
        return out

    @functools.cached_property
    def solutions(self) -> list[list[list[np.ndarray]]]:
        return [self.solution(j) for j in range(int(self.feasible.sum()))]


def _sub_targets(tg: reach.Targets, t: int) -> reach.Targets:
    return tg.take(slice(t, t + 1))


def screen_batch(spec: Spec, shape: Shape, pivots: np.ndarray, ports: np.ndarray, seed: int,
                 g: Geometry | None = None, interrupted: Callable[[], bool] | None = None) -> Screened | None:
    """Targets one at a time, farthest from the base first: a candidate leaves the batch at the
    first target it cannot reach (most twist settings miss the hardest one), so the rest of the
    work is spent on candidates that may pass. interrupted() is asked before each target (a
    region of thousands of points makes one batch long): True abandons the batch (None).
    A run that reaches a target only in collision gets one retry inside the tolerance
    (clear_within): it only adds hits, every run made without it still runs (RETRY off: the
    screen as it was, for the tests to compare)."""
    lib = spec.problem.cell.library
    if g is None:
        types = [lib.units[k] for k in shape.kinds]
        links = [(x if x is not None else t.x23) for t, x in zip(types, shape.links, strict=True)]
        tool = spec.problem.cell.tool
        g = geometry(types, pivots, ports, links, tool.xyz, tool.rpy)
    n, C = shape.n, len(pivots)
    g.joints  # noqa: B018  (once: the IK calls of every target and seed index them)
    tg = spec.targets
    T = len(tg.names)
    lo, hi = np.full(n, spec.lower), np.full(n, spec.upper)
    q0 = reach.seeds(n, SEEDS, lo, hi, seed)
    S = SEEDS + 1  # slot SEEDS: the warm start (below)
    q = np.zeros((C, T, S, n))
    ep = np.full((C, T, S), np.inf)
    ratio = np.full((C, T, S), np.inf)
    hit = np.zeros((C, T, S), bool)
    direct = np.zeros((C, T, S), bool)  # hit at the IK's own end (without clear_within's retry)
    ik_hit = np.zeros((C, T), bool)
    tried = np.zeros((C, T), bool)
    live = np.arange(C)
    done: list[int] = []
    for t in np.argsort(-np.linalg.norm(tg.xyz, axis=1), kind="stable"):
        if live.size == 0:
            break
        if interrupted is not None and interrupted():
            return None
        tried[live, t] = True
        # seeds one after the other: a candidate stops at its first run that reaches the target
        # clear of the cell (whether any seed does is the same as running them all). First a
        # warm start: each candidate's own solution at the nearest target it already reached
        # (a region's points lie centimetres apart: a few LM steps from there); an extra seed
        # only adds runs, so the screen passes at least what the common seeds pass.
        need = live
        warm = min(done, key=lambda u: float(np.linalg.norm(tg.xyz[u] - tg.xyz[t]))) if done else None
        done.append(int(t))
        seeds = ([SEEDS] if warm is not None else []) + list(range(SEEDS))
        while need.size and seeds:
            # few candidates left: the rest of the seeds in one call (a call costs its
            # iterations more than its runs)
            group = seeds if seeds[0] < SEEDS and need.size <= FEW else seeds[:1]
            seeds = seeds[len(group):]
            # the first direct hit as before (a retried one only when there is none): the runs of
            # the screen without the retry all still run, from the same starts
            first = np.where(direct[need, warm].any(-1), direct[need, warm].argmax(-1), hit[need, warm].argmax(-1))
            start = q[need, warm, first][:, None] if group == [SEEDS] else q0[group]
            qt, ept, ert = reach.solve(g, _sub_targets(tg, t), start, lo, hi, rows=need)
            got = np.zeros(need.size, bool)
            redo: list[tuple] = []  # per seed: the runs that reached the target only in collision
            for j, s in enumerate(group):
                ik, h, r, bad, frames = _passes(spec, g, int(t), need, qt[:, 0, j], ept[:, 0, j], ert[:, 0, j])
                ik_hit[need, t] |= ik
                if bad.size:
                    redo.append((s, bad, frames))
                q[need, t, s], ep[need, t, s], hit[need, t, s], ratio[need, t, s] = qt[:, 0, j], ept[:, 0, j], h, r
                direct[need, t, s] = h
                got |= h
            if RETRY and redo and tg.tol_p[t] > 0:
                _retry(spec, g, int(t), need, redo, (q, ep, ratio, hit), lo, hi)
            need = need[~got]
        live = live[hit[live, t].any(-1)]
    reached = hit.any(-1)  # (C, T)
    feasible = reached.all(-1)
    closest = ep.min(-1)
    # how far from feasible: metres missed on the targets tried, plus a metre per target not reached
    excess = np.where(np.isfinite(closest), np.maximum(closest - tg.tol_p[None], 0.0), 0.0)
    score = np.where(feasible, 0.0, excess.sum(-1) + (~reached).sum(-1) * 1.0)
    # the worst target's best run that passed, as a share of the tolerance (min and max are exact);
    # a target reached only by clear_within's retry counts 1 + its share: such a setting orders
    # after every setting the IK reached directly (search.order_key, dominance's 0.0), so the
    # settings a shape kept without the retry are kept, and checked, first
    if T:
        own = np.where(direct[feasible], ratio[feasible], np.inf).min(-1)
        worst = np.where(np.isfinite(own), own, 1.0 + np.where(hit[feasible], ratio[feasible], np.inf).min(-1)).max(-1)
    else:
        worst = np.zeros(int(feasible.sum()))
    return Screened(np.asarray(feasible), np.asarray(score), closest, ik_hit, tried, np.asarray(worst, float),
                    np.asarray(reached), (q, ratio, hit))


def _passes(spec: Spec, g: Geometry, t: int, rows: np.ndarray, qt: np.ndarray, ept: np.ndarray,
            ert: np.ndarray) -> tuple[np.ndarray, ...]:
    """One seed's runs of candidates `rows` at target t (joint vectors qt, position and rotation
    errors): whether each got within the tolerances (the IK's hit), whether it did clear of the
    cell, its error as a share of the tolerances, and the runs that hit only in collision
    (indices into rows) with their unit frames (for clear_within)."""
    tg = spec.targets
    r = ept / max(tg.tol_p[t], 1e-12)
    if tg.oriented[t]:
        r = np.maximum(r, ert / max(tg.tol_r[t], 1e-12))
    ik = r <= 1.0
    h = ik.copy()
    bad, frames = np.zeros(0, int), np.zeros((0, g.dof, 4, 3))
    if h.any() and len(spec.obstacles.shape):
        # only the runs that reached their target are worth a collision test
        c = np.flatnonzero(h)
        _, _, _, pts = forward(g.take(rows[c]), qt[c][:, None, None, :], points=True)
        collided = collides(spec.obstacles, pts[:, 0, 0], spec.radii)
        h[c] = ~collided
        bad, frames = c[collided], pts[collided, 0, 0]
    return ik, h, r, bad, frames


def _retry(spec: Spec, g: Geometry, t: int, need: np.ndarray, redo: list[tuple], runs: tuple[np.ndarray, ...],
           lo: np.ndarray, hi: np.ndarray) -> None:
    """The seeds' collided runs (redo: slot, indices into need, frames) retried in one call
    (clear_within), their hits written into runs = (q, ep, ratio, hit). A retried hit does not end
    the candidate's seeds: its tool0 lies off the centre and the exact check may still refuse it,
    so the runs the screen made without the retry all run (their solutions come first)."""
    q, ep, ratio, hit = runs
    slot = np.concatenate([np.full(len(k), s) for s, k, _ in redo])
    k = np.concatenate([k for _, k, _ in redo])
    qk, epk, rk, ok = clear_within(spec, g, t, need[k], q[need[k], t, slot], np.concatenate([f for _, _, f in redo]),
                                   lo, hi)
    rows, slot = need[k[ok]], slot[ok]
    q[rows, t, slot], ep[rows, t, slot], ratio[rows, t, slot] = qk[ok], epk[ok], rk[ok]
    hit[rows, t, slot] = True


def clear_within(spec: Spec, g: Geometry, t: int, rows: np.ndarray, q0: np.ndarray, frames: np.ndarray,
                 lower: np.ndarray, upper: np.ndarray) -> tuple[np.ndarray, ...]:
    """Runs of candidates `rows` that reached target t at q0 (m, n) but collide (frames: their
    unit frames there, as screen.collides takes them): one more try each, inside the tolerance.

    A target is met anywhere within its position tolerance (verify measures tool0 against it),
    while the IK aims at its centre: an arm whose last unit grazes an obstacle there may be clear
    with tool0 a few millimetres off. Each run is re-solved from q0, a few iterations, towards
    the target moved RETRY_SHARE of its tolerance along screen.escape (out of the obstacle the arm
    goes deepest into); its orientation and tolerances stay. Moving a target by d is moving the
    chain by -d (the translation of its first fixed transform), so every run keeps its own
    target in one batched IK call. Returns q (m, n), the position error from the real target
    (m,), the error as a share of the tolerances (m,), and whether the run is kept: within both
    tolerances and clear by the same screen."""
    tg = _sub_targets(spec.targets, t)
    shift = RETRY_SHARE * float(tg.tol_p[0])
    way, depth = escape(spec.obstacles, frames, spec.radii)
    # a run in deeper than the shift (and the screen's 1 mm) would need some part of the arm to
    # move farther than tool0: it is left as it is (an extra try, not a search); so is one whose
    # first actuator collides (no joint moves it)
    try_ = np.flatnonzero(depth <= shift + 1e-3)
    m = len(rows)
    qn, ep, r, ok = q0.copy(), np.full(m, np.inf), np.full(m, np.inf), np.zeros(m, bool)
    if not try_.size:
        return qn, ep, r, ok
    rows, q0, d = rows[try_], q0[try_], way[try_] * shift
    moved = g.take(rows)
    pre = moved.pre.copy()
    pre[:, 0, :3, 3] -= d
    q, _, er = reach.solve(Geometry(pre, moved.post, moved.t1, moved.flange_tool), tg, q0[:, None, :], lower, upper,
                           RETRY_ITERATIONS)
    got = q[:, 0, 0]
    _, _, T, pts = forward(g.take(rows), got[:, None, None, :], points=True)
    e = np.linalg.norm(T[:, 0, 0, :3, 3] - tg.xyz[0], axis=-1)
    share = e / max(float(tg.tol_p[0]), 1e-12)
    if tg.oriented[0]:
        share = np.maximum(share, er[:, 0, 0] / max(float(tg.tol_r[0]), 1e-12))
    fine = share <= 1.0
    if fine.any():
        fine[fine] = ~collides(spec.obstacles, pts[fine, 0, 0], spec.radii)
    qn[try_], ep[try_], r[try_], ok[try_] = got, e, share, fine
    return qn, ep, r, ok


@dataclass(frozen=True)
class Candidate:
    """A chain the screen passed, with its joint vectors per target (best first)."""

    shape: Shape
    variants: tuple[str, ...]
    pivots: tuple[float, ...]
    ports: tuple[float, ...]
    solutions: tuple[tuple[tuple[float, ...], ...], ...]  # per target, per solution

    def units(self) -> tuple[UnitSpec, ...]:
        parts = zip(self.variants, self.shape.kinds, self.pivots, self.ports, self.shape.links, strict=True)
        return tuple(UnitSpec(name=f"{v}{k}", variant=v, kind=k, pivot=p, port=o, link=x) for v, k, p, o, x in parts)


@dataclass(frozen=True)
class Verified:
    robot: ResolvedRobot  # checked, with one pose per target
    mass: float  # kg, the arm without payload
    margin: float  # smallest share of peak torque left over the joints
    targets: dict[str, dict]  # name -> {"q", "position_error_m", "orientation_error_deg"}


def pose_name(target: str) -> str:
    return f"at_{target}"


def robot_for(problem: ResolvedProblem, cand: Candidate, poses: dict[str, tuple[float, ...]], name: str) -> Robot:
    cell = problem.cell
    return cell.model_copy(update={
        "name": name, "units": cand.units(),
        "poses": tuple(Pose(name=pose_name(t), q=tuple(q)) for t, q in poses.items())})


def verify(problem: ResolvedProblem, cand: Candidate) -> Verified | str:
    """The exact check of one design; a string says why it fails."""
    from ..compiler import check_text
    from ..kinematics import Chain, target_errors
    from ..model.write import robot_file_text
    from ..physical.assembly import library_mass
    from ..physical.checker import CollisionChecker

    names = [t.name for t in problem.cell.targets]
    first = {t: sols[0] for t, sols in zip(names, cand.solutions, strict=True)}
    text = robot_file_text(robot_for(problem, cand, first, problem.name))
    checked = check_text(text, f"{problem.name}.mod", analyses=frozenset({"torque"}))
    if not checked.ok:
        d = next(d for d in checked.diagnostics if d.is_error)
        return f"{d.code}: {d.message}"
    robot = checked.design.resolved_robots()[0]
    checker = CollisionChecker(robot, margin=VERIFY_MARGIN)
    if checker.static_contacts():
        return "base_link touches the cell"
    chain = Chain(robot)
    chosen: dict[str, tuple[float, ...]] = {}
    report: dict[str, dict] = {}
    for target, sols in zip(problem.cell.targets, cand.solutions, strict=True):
        q = next((q for q in sols if checker.valid(np.asarray(q))), None)
        if q is None:
            contacts = checker.contacts(np.asarray(sols[0]))
            what = contacts[0].describe() if contacts else "a collision"
            return f"target '{target.name}' is reached only in collision ({what})"
        perr, angle = target_errors(target, chain.T_base_tool(np.asarray(q)))
        oerr = None if angle is None else math.degrees(angle)
        tol_p, tol_o = target.tolerance
        if angle is not None and angle > tol_o + 1e-9:
            return f"target '{target.name}' orientation off by {oerr:.2g}°"
        if perr > tol_p + 1e-12:
            return f"target '{target.name}' missed by {perr * 1000:.2g} mm"
        chosen[target.name] = tuple(float(x) for x in q)
        report[target.name] = {"q": [round(float(x), 9) for x in q], "position_error_m": round(perr, 9),
                               "orientation_error_deg": None if oerr is None else round(oerr, 6)}
    robot = robot.model_copy(update={"poses": tuple(Pose(name=pose_name(t), q=q) for t, q in chosen.items())})
    payload = robot.payload.mass if robot.payload else 0.0
    margin = min(j.margin for j in robot.torque) if robot.torque else 1.0
    return Verified(robot, library_mass(robot) - payload, float(margin), report)
