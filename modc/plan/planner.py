"""Joint-space path planning: OMPL's RRT-Connect (MoveIt's default planner), then shortcutting.

    find_path(checker, q_start, q_goal, seed, timeout, max_checks) -> [q, …] or None

State space: RealVectorStateSpace(n) bounded by the joint limits. Validity: the collision
checker (every checked pair more than the margin apart). Motions: the search uses OMPL's
discrete motion validator at SEARCH_COARSENESS times the certified step (a point of the arm
moves up to 2 x margin between checked states), which is fast; then every edge of the path
found is certified (no point of the arm moves more than margin / 2 between two checked states;
see modc.physical.checker) and an edge that fails is re-planned by RRT-Connect at the certified
resolution. The direct motion start -> goal is tried first.

Determinism: OMPL's RNG is seeded (RNG.setSeed(seed + 1), OMPL seeds being > 0) before the
planner and its samplers are made; the planner stops on a count of validity checks (max_checks)
as well as on time, and a run that ends by finding a path does not depend on the clock. The
shortcutting uses numpy's default_rng(seed). Same robot, target and seed -> same path.

Shortcutting: greedy vertex reduction (from each vertex, jump to the farthest later vertex
reachable in a straight certified motion), then SHORTCUT_TRIES random shortcuts between points
on the path kept when they shorten the motion's duration (the arm stops at every vertex, so
fewer, shorter segments are faster), then the greedy pass again.
"""
from __future__ import annotations

import itertools
import time
from collections.abc import Callable

import numpy as np

from ..physical.checker import CollisionChecker

SHORTCUT_TRIES = 60
SEARCH_COARSENESS = 4.0  # RRT-Connect checks motions 4x coarser than certified; edges are certified after
DEFAULT_TIMEOUT = 20.0  # s of planning in all (every goal tried shares it)
DEFAULT_MAX_CHECKS = 200_000  # validity checks per goal tried (the deterministic budget)


class PlannerUnavailable(RuntimeError):
    """OMPL is not installed (or not importable)."""


class _Budget:
    def __init__(self, checker: CollisionChecker, timeout: float, max_checks: int):
        self.checker = checker
        self.deadline = time.monotonic() + timeout
        self.limit = checker.checks + max_checks

    def spent(self) -> bool:
        return self.checker.checks >= self.limit or time.monotonic() >= self.deadline


def rrt_connect(checker: CollisionChecker, q_start, q_goal, seed: int, budget: _Budget,
                coarseness: float = 1.0) -> list[np.ndarray] | None:
    """OMPL RRT-Connect from q_start to q_goal: its path's vertices, or None. coarseness
    scales the motion-check resolution: 1 = certified, > 1 = faster search whose edges must be
    certified afterwards."""
    try:
        from ompl import base as ob
        from ompl import geometric as og
        from ompl import util as ou
    except ImportError as e:
        raise PlannerUnavailable(f"OMPL's Python bindings cannot be imported ({e})") from None

    n = len(q_start)
    level = ou.getLogLevel()
    ou.setLogLevel(ou.LOG_NONE)  # OMPL's own chatter (seed warnings, planner info) stays quiet
    try:
        ou.RNG.setSeed(int(seed) % 0x7FFFFFFF + 1)
        space = ob.RealVectorStateSpace(n)
        bounds = ob.RealVectorBounds(n)
        for i in range(n):
            bounds.setLow(i, float(checker.lower[i]))
            bounds.setHigh(i, float(checker.upper[i]))
        space.setBounds(bounds)
        ss = og.SimpleSetup(space)
        valid = checker.valid

        def is_valid(state) -> bool:
            return bool(valid(np.fromiter((state[i] for i in range(n)), float, n)))

        ss.setStateValidityChecker(is_valid)
        si = ss.getSpaceInformation()
        # certified resolution: an L2 step d moves no point more than d * |R|_2 (Cauchy-Schwarz)
        step = coarseness * checker.margin / 2.0 / float(np.linalg.norm(checker.radii))
        si.setStateValidityCheckingResolution(min(0.01, step / space.getMaximumExtent()))
        start, goal = space.allocState(), space.allocState()
        for i in range(n):
            start[i] = float(q_start[i])
            goal[i] = float(q_goal[i])
        ss.setStartAndGoalStates(start, goal)
        ss.setPlanner(og.RRTConnect(si))
        ss.setup()
        ss.solve(ob.PlannerTerminationCondition(budget.spent))
        if not ss.haveExactSolutionPath():
            return None
        path = ss.getSolutionPath()
        out = [np.array([path.getState(k)[i] for i in range(n)]) for k in range(path.getStateCount())]
        ss.clear()
        return out
    finally:
        ou.setLogLevel(level)


def reduce_vertices(checker: CollisionChecker, path: list[np.ndarray]) -> list[np.ndarray]:
    """From each vertex, the farthest later vertex reachable by a certified straight motion."""
    out = [path[0]]
    i = 0
    while i < len(path) - 1:
        j = len(path) - 1
        while j > i + 1 and not checker.motion_valid(path[i], path[j]):
            j -= 1
        out.append(path[j])
        i = j
    return out


def _point_at(path, cum, s):
    k = int(np.searchsorted(cum, s, side="right")) - 1
    k = min(max(k, 0), len(path) - 2)
    seg = cum[k + 1] - cum[k]
    a = 0.0 if seg <= 0 else (s - cum[k]) / seg
    return k, path[k] + a * (path[k + 1] - path[k])


def shortcut(checker: CollisionChecker, path: list[np.ndarray], rng: np.random.Generator,
             cost: Callable[[list[np.ndarray]], float], tries: int = SHORTCUT_TRIES) -> list[np.ndarray]:
    """Random shortcuts between two points of the path, kept when cost (duration) drops."""
    path = reduce_vertices(checker, path)
    for _ in range(tries):
        if len(path) < 3:
            break
        lengths = [float(np.linalg.norm(b - a)) for a, b in itertools.pairwise(path)]
        cum = np.concatenate([[0.0], np.cumsum(lengths)])
        s1, s2 = np.sort(rng.random(2) * cum[-1])
        k1, p1 = _point_at(path, cum, s1)
        k2, p2 = _point_at(path, cum, s2)
        if k1 == k2:
            continue
        candidate = path[:k1 + 1] + [p1, p2] + path[k2 + 1:]
        # drop points that coincide with their neighbours (a shortcut starting at a vertex)
        cleaned = [candidate[0]]
        for q in candidate[1:]:
            if np.max(np.abs(q - cleaned[-1])) > 1e-12:
                cleaned.append(q)
        if cost(cleaned) >= cost(path) - 1e-9:
            continue
        if checker.motion_valid(p1, p2):
            path = cleaned
    return reduce_vertices(checker, path)


def find_path(checker: CollisionChecker, q_start, q_goal, seed: int, cost: Callable[[list[np.ndarray]], float],
              timeout: float = DEFAULT_TIMEOUT, max_checks: int = DEFAULT_MAX_CHECKS,
              deadline: float | None = None) -> list[np.ndarray] | None:
    """A certified collision-free polyline q_start -> q_goal (both assumed valid), or None.
    The search stops after max_checks validity checks, or timeout seconds, or at deadline
    (time.monotonic()), whichever comes first."""
    q_start, q_goal = np.asarray(q_start, float), np.asarray(q_goal, float)
    if checker.motion_valid(q_start, q_goal):
        return [q_start, q_goal]
    budget = _Budget(checker, timeout, max_checks)
    if deadline is not None:
        budget.deadline = min(budget.deadline, deadline)
    path = rrt_connect(checker, q_start, q_goal, seed, budget, SEARCH_COARSENESS)
    if path is None:
        return None
    path[0], path[-1] = q_start, q_goal  # exactly (OMPL copies them; keep the same floats)
    path = certify(checker, path, seed, budget)
    if path is None:
        return None
    return shortcut(checker, path, np.random.default_rng(seed), cost)


def certify(checker: CollisionChecker, path: list[np.ndarray], seed: int, budget: _Budget) -> list[np.ndarray] | None:
    """Every edge of a coarsely checked path certified; an edge that fails is replaced by a
    certified RRT-Connect path between its ends (its ends are valid states)."""
    out = [path[0]]
    for k, (a, b) in enumerate(itertools.pairwise(path)):
        if checker.motion_valid(a, b):
            out.append(b)
            continue
        if budget.spent():
            return None
        detour = rrt_connect(checker, a, b, seed + 7919 * (k + 1), budget, 1.0)
        if detour is None:
            return None
        out += detour[1:-1] + [b]
    return out


__all__ = [
    "DEFAULT_MAX_CHECKS",
    "DEFAULT_TIMEOUT",
    "PlannerUnavailable",
    "SHORTCUT_TRIES",
    "find_path",
    "reduce_vertices",
    "rrt_connect",
    "shortcut",
    "certify",
]
