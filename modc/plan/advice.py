"""Why a target is out of reach (target-unreachable), said with the numbers.

Called once IK found no pose within the target's tolerances. More IK, on cheaper questions,
tells the cases apart:
    orientation   the target has `rpy`, and tool0 does reach its position within the limits:
                  the orientation is what fails (the closest orientation found, in degrees);
    limits        tool0 reaches the target (position, or full pose) when every joint may turn
                  a full circle, but not within the joints' ranges: which joint would have to
                  go where;
    too far       otherwise, when the target is farther from joint_1 than tool0 gets in the
                  closest pose found;
    too close     when it is nearer to joint_1 than tool0 gets (the arm cannot fold that tight);
    to the side   when tool0 gets as far from joint_1 as the target, only not in its direction.
Obstacles are another code (target-in-collision), whose hint says when the target itself lies
inside an obstacle (inside_obstacle). Every number printed is finite.
"""
from __future__ import annotations

import math

import numpy as np

from ..diagnostics import codes
from ..model import ResolvedRobot
from ..passes.check_reach import reach_shell
from . import ik
from .errors import PlanError

FULL_TURN = (-math.pi, math.pi)  # a revolute joint free of limits: every angle once


def _deg(q) -> str:
    return "(" + ", ".join(f"{math.degrees(v):.1f}" for v in q) + ") deg"


def _xyz(p) -> str:
    return "(" + ", ".join(f"{v:.3f}" for v in p) + ") m"


def _solve(job, checker, rotation, lower, upper, q_start):
    solver = ik.PositionIK(checker.model, checker.data, checker.tool_frame, lower, upper, rotation)
    tgt = job.target
    tolerance = (tgt.position_tolerance, tgt.orientation_tolerance if rotation is not None else np.inf)
    count = max(8, 8 * job.robot.dof)  # a diagnosis, not a plan: half the planner's seeds
    solutions, best = ik.solve(solver, tgt.xyz, np.clip(q_start, lower, upper), count, job.seed, tolerance=tolerance)
    return solver, solutions, best


def unreachable(job, checker, solver, best, q_start) -> PlanError:
    """The target-unreachable diagnostic for job's target; solver and best: the failed IK."""
    if solver.rotation is not None:
        position_solver, at_position, position_best = _solve(job, checker, None, checker.lower, checker.upper,
                                                             q_start)
        if at_position:
            return _limits(job, checker, solver.rotation, q_start) or _orientation(job, solver, at_position, best)
        solver, best = position_solver, position_best  # the position fails: say by how much
    closest = f"the closest tool0 gets is {_xyz(solver.position(best.q))}, at joint angles {_deg(best.q)}"
    return _limits(job, checker, None, q_start) or _distance(job, solver, best, closest)


def _limits(job, checker, rotation, q_start) -> PlanError | None:
    """The limits case, if every joint turning a full circle reaches the target."""
    n = job.robot.dof
    lower, upper = np.full(n, FULL_TURN[0]), np.full(n, FULL_TURN[1])
    _, free, _ = _solve(job, checker, rotation, lower, upper, q_start)

    def outside(q) -> float:
        return float(np.sum(np.maximum(checker.lower - q, 0.0) + np.maximum(q - checker.upper, 0.0)))

    free = [s for s in free if outside(s.q) > 1e-9]
    if not free:
        return None
    q = min(free, key=lambda s: outside(s.q)).q
    needs = []
    limited = False
    for i in range(n):
        if checker.lower[i] - 1e-9 <= q[i] <= checker.upper[i] + 1e-9:
            continue
        joint = f"joint_{i + 1}"
        limited |= any(lim.joint == joint for lim in job.robot.limits)
        needs.append(f"{joint} at {math.degrees(q[i]):.1f}° (its range is {math.degrees(checker.lower[i]):.1f}.."
                     f"{math.degrees(checker.upper[i]):.1f}°)")
    what = "its pose" if rotation is not None else "it"
    hint = ("widen the `limit` of those joints, or move the target" if limited else
            "the modules turn no further: move the target, or turn the arm's base (`base … rpy`)")
    return job.fail(codes.TARGET_UNREACHABLE, job.target.span, target=job.target.name,
                    why=f"outside the joint limits: tool0 reaches {what} only with {', '.join(needs)}",
                    hint=f"joint angles that reach it: {_deg(q)}; {hint}")


def _orientation(job, solver, at_position, best) -> PlanError:
    """Position reachable, orientation not: the orientation closest to the target's found at the position."""
    tgt = job.target
    errors = [(solver.errors(s.q, np.asarray(tgt.xyz, float))[1], s.q) for s in at_position]
    pe, oe = solver.errors(best.q, np.asarray(tgt.xyz, float))
    if pe <= tgt.position_tolerance:
        errors.append((oe, best.q))
    angle, q = min(errors, key=lambda e: e[0])
    dof = job.robot.dof
    more = (f" (a {dof}-joint arm cannot give tool0 every orientation at a point; that takes 6 joints)"
            if dof < 6 else "")
    return job.fail(
        codes.TARGET_UNREACHABLE, tgt.span, target=tgt.name,
        why=(f"in orientation: tool0 reaches the position, but turns no closer than {math.degrees(angle):.1f}° "
             f"to the target's rpy (tolerance {math.degrees(tgt.orientation_tolerance):.1f}°)"),
        hint=(f"the closest orientation is at joint angles {_deg(q)}; change the target's `rpy`, widen its "
              f"`within` tolerance, or drop the rpy{more}"))


def _distance(job, solver, best, closest: str) -> PlanError:
    """Too far, too close, or beside the workspace: the target against tool0's closest pose, both
    measured from joint_1. Radial when the distances from joint_1 differ by at least half the gap
    (or the reach bound proves it); otherwise the arm gets that far out, only not that way."""
    tgt = job.target
    origin, r_min, r_max, _ = reach_shell(job.robot)
    o = np.asarray(origin, float)
    d_target = float(np.linalg.norm(np.asarray(tgt.xyz, float) - o))
    d_tool = float(np.linalg.norm(solver.position(best.q) - o))
    gap = f"tool0 gets no closer than {best.error:.3f} m"
    where = f"joint_1 is at {_xyz(origin)} in base_link"
    radial = abs(d_target - d_tool) >= 0.5 * best.error or d_target > r_max or d_target < r_min
    if radial and d_target >= d_tool:
        reach = (f"no pose puts tool0 farther than {r_max:.3f} m from it" if d_target > r_max else
                 f"the closest pose puts tool0 {d_tool:.3f} m from it")
        why = f"too far: {gap} (the target is {d_target:.3f} m from joint_1, {reach})"
        hint = f"{closest}; move the target towards the arm ({where}), or lengthen the arm (link=…, more units)"
    elif radial:
        reach = (f"no pose puts tool0 nearer than {r_min:.3f} m to it" if d_target < r_min else
                 f"the closest pose puts tool0 {d_tool:.3f} m from it")
        why = f"too close to the arm: {gap} (the target is {d_target:.3f} m from joint_1, {reach})"
        hint = (f"{closest}; move the target away from the arm ({where}), or make the arm fold tighter "
                "(shorter links, other pivots or ports)")
    else:
        dof = job.robot.dof
        shape = {1: " (one joint moves tool0 along a circle)", 2: " (two joints move tool0 over a surface)"}
        why = (f"off to the side of what the arm sweeps: {gap} (the target is {d_target:.3f} m from joint_1; "
               f"tool0 gets {d_tool:.3f} m from it, but not in the target's direction)")
        hint = (f"{closest}; move the target towards that point ({where}), or change pivots and ports so that "
                f"the arm points there{shape.get(dof, '')}")
    return job.fail(codes.TARGET_UNREACHABLE, tgt.span, target=tgt.name, why=why, hint=hint)


def inside_obstacle(robot: ResolvedRobot, xyz) -> str | None:
    """'0.125 m inside box 'crate'' when the target point lies in one of the robot's obstacles
    (the deepest), else None: then no arm pose can put tool0 there without touching it."""
    from ..kinematics import rpy_matrix

    deepest: tuple[float, str] | None = None
    for o in robot.obstacles:
        p = rpy_matrix(o.origin.rpy).T @ (np.asarray(xyz, float) - np.asarray(o.origin.xyz, float))
        if o.shape == "box":
            depth = float(np.min(np.asarray(o.size) / 2 - np.abs(p)))
        elif o.shape == "sphere":
            depth = o.size[0] - float(np.linalg.norm(p))
        else:  # cylinder: radius, length along its z
            depth = min(o.size[0] - float(np.hypot(p[0], p[1])), o.size[1] / 2 - abs(float(p[2])))
        if depth >= 0 and (deepest is None or depth > deepest[0]):
            deepest = (depth, f"{o.shape} '{o.name}'")
    return None if deepest is None else f"{deepest[0]:.3f} m inside {deepest[1]}"


__all__ = ["inside_obstacle", "unreachable"]
