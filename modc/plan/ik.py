"""Position inverse kinematics of tool0 with pinocchio: Levenberg-Marquardt, projected onto the
joint limits, from many deterministic seeds.

    solve(model, data, frame, target, lower, upper, seeds) -> [Solution]

One run: minimise |p(q) - target|² over lower <= q <= upper. Each step solves the damped normal
equations (J Jᵀ + λ I) y = e, dq = Jᵀ y with J the 3 x n position Jacobian of tool0 in
base_link axes, then clamps q + dq to the limits (projection); a step is kept only if it
lowers the error (then λ shrinks), otherwise λ grows and the step is tried again: LM's
trust-region behaviour, which converges quadratically near a solution and does not blow up
near singular poses. Runs that converge are polished to TOLERANCE (1e-9 m) and, for arms with
more joints than the 3 the position needs, slid along their self-motion towards the start pose
(null-space steps that keep the position) so that "the closest solution" is well defined.

A run that does not reach the target stops at a local minimum of the distance: the smallest
of those over all seeds is what "how far out of reach" reports.

Targets with an orientation (`target … rpy …`): the residual gains the rotation vector of
R_target R(q)^T, weighted by ROTATION_WEIGHT m/rad, and J the angular rows (6-D IK). A target's
tolerances (default 5 mm, 2°) decide what counts as reached for arms that cannot get closer
(fewer joints than the target has constraints); runs still polish towards TOLERANCE.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..kinematics import rotation_error

TOLERANCE = 1e-9  # m: a converged run is within this of the target
MAX_ITERATIONS = 200
LAMBDA0 = 1e-3
LAMBDA_MIN, LAMBDA_MAX = 1e-12, 1e8
STALL = 1e-6  # a step that lowers the error by less than this fraction ends the run
NULL_STEPS = 60  # redundant arms: steps towards the start pose along the self-motion
ROTATION_WEIGHT = 0.2  # m/rad: weight of the orientation error against the position error (6-D IK)


@dataclass(frozen=True)
class Solution:
    q: np.ndarray
    error: float  # m, |p(q) - target|
    seed_index: int


class PositionIK:
    """IK of tool0 to a position, or (rotation given: a 3x3 matrix in base_link) to a full pose."""

    def __init__(self, model, data, frame: int, lower, upper, rotation=None, axis=None):
        import pinocchio as pin

        self.pin = pin
        self.model, self.data, self.frame = model, data, frame
        self.lower, self.upper = np.asarray(lower, float), np.asarray(upper, float)
        self.rotation = None if rotation is None else np.asarray(rotation, float)
        # `pointing`: only tool0's x axis is constrained, to this unit vector (no rotation given)
        self.axis = None if axis is None or rotation is not None else np.asarray(axis, float)

    def _axis_error(self, M) -> np.ndarray:
        """The shortest turn taking tool0's x axis onto self.axis (its norm: the angle between them)."""
        assert self.axis is not None
        x = np.array(M.rotation)[:, 0]
        v = np.cross(x, self.axis)
        s = float(np.linalg.norm(v))
        angle = float(np.arctan2(s, float(x @ self.axis)))
        if s < 1e-12:
            v = np.cross(x, (1.0, 0.0, 0.0) if abs(x[0]) < 0.9 else (0.0, 1.0, 0.0))
        return v * (angle / float(np.linalg.norm(v)))

    def placement(self, q):
        pin = self.pin
        pin.forwardKinematics(self.model, self.data, q)
        return pin.updateFramePlacement(self.model, self.data, self.frame)

    def position(self, q) -> np.ndarray:
        return np.array(self.placement(q).translation)

    def residual(self, q, target) -> np.ndarray:
        """target - p(q), with the weighted rotation error appended for a full pose."""
        M = self.placement(q)
        e = target - np.array(M.translation)
        if self.axis is not None:
            return np.concatenate([e, ROTATION_WEIGHT * self._axis_error(M)])
        if self.rotation is None:
            return e
        return np.concatenate([e, ROTATION_WEIGHT * rotation_error(self.rotation, np.array(M.rotation))])

    def errors(self, q, target) -> tuple[float, float]:
        """(position error m, orientation error rad; 0 without an orientation)."""
        M = self.placement(q)
        pe = float(np.linalg.norm(target - np.array(M.translation)))
        if self.axis is not None:
            return pe, float(np.linalg.norm(self._axis_error(M)))
        if self.rotation is None:
            return pe, 0.0
        return pe, float(np.linalg.norm(rotation_error(self.rotation, np.array(M.rotation))))

    def jacobian(self, q) -> np.ndarray:
        pin = self.pin
        J = pin.computeFrameJacobian(self.model, self.data, q, self.frame, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        J = np.asarray(J).reshape(6, self.model.nv)  # pinocchio hands a one-joint arm's 6 x 1 back as a flat (6,)
        if self.axis is not None:  # turning about tool0's x axis changes nothing the target asks for
            x = np.array(self.placement(q).rotation)[:, 0]
            Jr = np.array(J[3:]) - np.outer(x, x @ np.array(J[3:]))
            return np.vstack([np.array(J[:3]), ROTATION_WEIGHT * Jr])
        if self.rotation is None:
            return np.array(J[:3])
        return np.vstack([np.array(J[:3]), ROTATION_WEIGHT * np.array(J[3:])])

    def run(self, q0, target) -> tuple[np.ndarray, float]:
        """One projected LM descent from q0: (q, final error)."""
        q = np.clip(np.asarray(q0, float), self.lower, self.upper)
        e = self.residual(q, target)
        err = float(np.linalg.norm(e))
        m = e.size
        lam = LAMBDA0
        for _ in range(MAX_ITERATIONS):
            if err <= TOLERANCE:
                break
            J = self.jacobian(q)
            JJt = J @ J.T
            improved = False
            while lam <= LAMBDA_MAX:
                y = np.linalg.solve(JJt + lam * np.eye(m), e)
                qn = np.clip(q + J.T @ y, self.lower, self.upper)
                en = self.residual(qn, target)
                errn = float(np.linalg.norm(en))
                if errn < err:
                    stalled = err - errn < STALL * err
                    q, e, err = qn, en, errn
                    lam = max(lam / 10.0, LAMBDA_MIN)
                    improved = True
                    break
                lam *= 10.0
            if not improved or stalled:  # a local minimum (out of reach from here), or crawling along a limit
                break
        return q, err

    def towards(self, q, q_ref, target) -> np.ndarray:
        """Redundant arms: move a converged q towards q_ref without leaving the target (projected
        gradient steps in the Jacobian's null space, each re-converged; a step that leaves the
        limits or the target is dropped)."""
        n = q.size
        if n <= (6 if self.rotation is not None else 5 if self.axis is not None else 3):
            return q
        for _ in range(NULL_STEPS):
            J = self.jacobian(q)
            Jp = np.linalg.pinv(J, rcond=1e-6)
            N = np.eye(n) - Jp @ J
            step = N @ (q_ref - q) * 0.5
            if np.linalg.norm(step) < 1e-9:
                break
            qn = np.clip(q + step, self.lower, self.upper)
            qn, err = self.run(qn, target)
            if err > TOLERANCE or np.linalg.norm(qn - q_ref) >= np.linalg.norm(q - q_ref) - 1e-12:
                break
            q = qn
        return q


def seeds(start, lower, upper, count: int, seed: int) -> list[np.ndarray]:
    """The start pose first, then uniform samples in the joint limits from default_rng(seed)."""
    rng = np.random.default_rng(seed)
    lower, upper = np.asarray(lower, float), np.asarray(upper, float)
    out = [np.clip(np.asarray(start, float), lower, upper)]
    out += list(lower + (upper - lower) * rng.random((count - 1, lower.size)))
    return out


def solve(ik: PositionIK, target, start, count: int, seed: int, batches: int = 1,
          enough: Callable[[np.ndarray], bool] | None = None,
          tolerance: tuple[float, float] = (TOLERANCE, np.inf)) -> tuple[list[Solution], Solution]:
    """Converged solutions (duplicates within 1e-6 rad dropped), in order of joint-space
    distance to start, and the best run overall (the closest approach, for error messages).
    Up to `batches` batches of `count` seeds; after a batch, stop if some solution is
    `enough` (e.g. collision-free: redundant arms have a continuum of solutions, and a few
    more seeds find a free one where the first batch's all collide). A run counts as a solution
    when it ends within `tolerance` (m, rad) of the target: the target's own tolerances."""
    target = np.asarray(target, float)
    start = np.asarray(start, float)
    found: list[Solution] = []
    best: Solution | None = None
    all_seeds = seeds(start, ik.lower, ik.upper, count * batches, seed)
    for b in range(batches):
        for k in range(b * count, (b + 1) * count):
            q, _ = ik.run(all_seeds[k], target)
            pe, oe = ik.errors(q, target)
            if best is None or pe < best.error:
                best = Solution(q, pe, k)
            if pe > max(tolerance[0], TOLERANCE) or oe > tolerance[1]:
                continue
            if pe <= TOLERANCE:
                q = ik.towards(q, start, target)
            if any(np.max(np.abs(s.q - q)) < 1e-6 for s in found):
                continue
            found.append(Solution(q, ik.errors(q, target)[0], k))
        if not found and b == 0:
            break  # nothing converged from count seeds: out of reach, more seeds will not help
        if enough is None or any(enough(s.q) for s in found):
            break
    found.sort(key=lambda s: (float(np.linalg.norm(s.q - start)), s.seed_index))
    assert best is not None
    return found, best


__all__ = [
    "MAX_ITERATIONS",
    "ROTATION_WEIGHT",
    "TOLERANCE",
    "PositionIK",
    "Solution",
    "seeds",
    "solve",
]
