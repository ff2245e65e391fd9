"""`modc plan FILE --to TARGET`: a collision-free motion of the arm from a pose (home) to a named
target (docs/conventions.md).

    from modc.plan import plan, PlanError
    result = plan("examples/farm.mod", "plant", seed=0)     # -> Plan, or raises PlanError
    sys.stdout.write(result.dumps())                         # {"joint_names": …, "points": …}
    print(result.summary())

Steps (modules of this package):
    collision.py  the compiled URDF's collision meshes + the file's obstacles, pinocchio + coal;
                  self-collision pairs from the SRDF's matrix; certified straight motions
    ik.py         IK of tool0, position or full pose (projected Levenberg-Marquardt, many seeded starts);
                  the collision-free solution closest to the start pose is the goal
    planner.py    OMPL RRT-Connect in joint space, then shortcutting
    timing.py     stop-at-every-vertex trapezoidal timing within the velocity limits
    errors.py     PlanError (diagnostics of the registry, exit code)
    advice.py     why a target is out of reach: too far, too close, orientation, joint limits

Everything is deterministic for a given file, target, start pose and seed: numpy's
default_rng(seed) for IK seeds and shortcuts, OMPL's RNG seeded from it, and a planner budget
counted in validity checks. Output numbers are rounded (t to 1e-9 s, q to 1e-12 rad) and
written in a fixed layout, so the JSON is byte-for-byte reproducible.
"""
from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass, field
from typing import Any

from ..diagnostics import codes
from ..model import ResolvedRobot
from ..model.select import COMMAND_LINE, RobotChoiceError, choose_robot
from ..trajectory import Trajectory
from .errors import EXIT_FAILED, EXIT_USAGE, PlanError

IK_SEEDS_PER_JOINT = 16  # IK runs: 16 per joint (48 for a 3-joint arm), the start pose first
IK_BATCHES = 4  # more batches of seeds while every solution found collides
MAX_GOALS = 3  # collision-free IK solutions tried as goals, closest first
MIN_MARGIN = 5e-4  # m: a start or goal closer than 2 x this to an obstacle counts as colliding


@dataclass(frozen=True)
class Plan:
    robot: str
    target: str
    start: str  # name of the start pose
    target_xyz: tuple[float, float, float]
    joint_names: tuple[str, ...]
    t: tuple[float, ...]
    q: tuple[tuple[float, ...], ...]
    waypoints: tuple[tuple[float, ...], ...]  # the polyline the motion follows (stops at each)
    tool_error: float  # m, |tool0(q_final) - target|
    min_clearance: float | None  # m, smallest distance of a checked pair over the output points; None: no pair
    margin: float  # m, the clearance the planner kept
    seed: int
    velocity_limits: tuple[float, ...]  # rad/s
    with_robot_name: bool = False  # files with several robots: say which one in the JSON
    stats: dict = field(default_factory=dict, compare=False)

    @property
    def duration(self) -> float:
        return self.t[-1] - self.t[0]

    @property
    def trajectory(self) -> Trajectory:
        """The motion as a trajectory file (docs/conventions.md), naming the robot in several-robot files."""
        return Trajectory(self.joint_names, self.t, self.q, self.robot if self.with_robot_name else None)

    def to_json(self) -> dict:
        return self.trajectory.to_json()

    def dumps(self) -> str:
        """docs/conventions.md JSON, one point per line, fixed number formatting."""
        return self.trajectory.dumps()

    def summary(self) -> str:
        deg = lambda q: "(" + ", ".join(f"{math.degrees(x):.1f}" for x in q) + ") deg"  # noqa: E731
        out = [f"robot {self.robot}: '{self.start}' -> target '{self.target}' "
               f"({', '.join(f'{v:g}' for v in self.target_xyz)}) m",
               f"  duration        {self.duration:.3f} s, {len(self.t)} points, "
               f"{len(self.waypoints) - 1} straight segment(s) in joint space",
               f"  start           {deg(self.q[0])}",
               f"  goal            {deg(self.q[-1])}",
               f"  tool0 error     {self.tool_error:.2e} m"]
        if self.min_clearance is not None:
            out.append(f"  clearance       >= {self.margin * 1000:.1f} mm along the whole motion (certified), "
                       f"{self.min_clearance * 1000:.1f} mm at the closest output point")
        else:
            out.append("  clearance       nothing to check: no obstacle, and no pair of links the SRDF leaves checked")
        s = self.stats
        if s:
            out.append(f"  planning        {s.get('time', 0.0):.2f} s, {s.get('checks', 0)} collision checks, "
                       f"{s.get('ik_solutions', 0)} IK solution(s), seed {self.seed}")
        return "\n".join(out)


def start_pose(robot: ResolvedRobot, name: str | None):
    """(name, q, span) of the start pose: the pose named `name`, else home (Robot.home); None
    when the robot has no pose `name`."""
    if name is not None:
        p = robot.pose(name)
        return (p.name, tuple(p.q), p.span) if p is not None else None
    p = robot.pose("home")
    return ("home", robot.home(), p.span if p is not None else robot.name_span)


def clear_solution(robot: ResolvedRobot, checker, target, start, seed: int):
    """A joint vector within the limits that puts tool0 on the target (a Target: its position,
    orientation or pointing, and tolerances) clear of the cell and of the arm itself, from
    seeded starts around `start`; None when none is found."""
    from ..kinematics import rpy_matrix
    from . import ik as plan_ik

    rotation = None if target.rpy is None else rpy_matrix(target.rpy)
    solver = plan_ik.PositionIK(checker.model, checker.data, checker.tool_frame, checker.lower, checker.upper,
                                rotation, target.pointing)
    sols, _best = plan_ik.solve(solver, target.xyz, start, IK_SEEDS_PER_JOINT * robot.dof, seed,
                                batches=IK_BATCHES, enough=checker.valid, tolerance=target.tolerance)
    return next((s.q for s in sols if checker.valid(s.q)), None)


def _known(kind: str, names) -> str:
    names = list(names)
    if not names:
        return {"targets": "the robot declares no targets: add `target NAME at (x, y, z) m` to its block",
                "poses": "the robot declares no poses: add `pose NAME (…) deg` to its block"}[kind]
    return f"{kind}: {', '.join(names)}"


def _contacts_text(contacts) -> str:
    return "; ".join(c.describe() for c in contacts)


def checked_or_raise(path, library: str | None = None):
    """The checked file, or PlanError: exit 2 when it cannot be read, 1 when it has errors."""
    from ..compiler import InputError, check_file

    try:
        checked = check_file(path, library)
    except InputError as e:
        raise PlanError([e.diagnostic], {}, EXIT_USAGE) from None
    if not checked.ok:
        raise PlanError([d for d in checked.diagnostics if d.is_error], checked.sources, EXIT_FAILED)
    return checked


def plan(path, target: str, robot: str | None = None, seed: int = 0, start: str | None = None,
         library: str | None = None, **options) -> Plan:
    """Read a .mod (or YAML) file and plan robot's motion from `start` (default home) to
    `target`. robot may be omitted when exactly one robot of the file declares the target.
    options go to plan_robot (margin, timeout, max_checks). Raises PlanError."""
    checked = checked_or_raise(path, library)
    robots = list(checked.design.robots)
    among = None
    if robot is None and len(robots) > 1:
        among = [r for r in robots if any(t.name == target for t in r.targets)]
        if not among:
            known = "; ".join(f"{r.name}: {', '.join(t.name for t in r.targets) or 'none'}" for r in robots)
            raise PlanError.of(codes.TARGET_UNKNOWN, COMMAND_LINE, robot=" or ".join(r.name for r in robots),
                               target=target, known=f"targets per robot: {known}")
    try:
        chosen = choose_robot(checked.design, robot, among, why=f"have a target '{target}'")
    except RobotChoiceError as e:
        raise PlanError([e.diagnostic], {}, EXIT_USAGE) from None
    return plan_robot(chosen, target, seed=seed, start=start, sources=checked.sources,
                      with_robot_name=len(robots) > 1, **options)


def plan_robot(robot: ResolvedRobot, target: str, seed: int = 0, start: str | None = None, margin: float | None = None,
               timeout: float | None = None, max_checks: int | None = None, files=None, sources=None,
               with_robot_name: bool = False) -> Plan:
    """Plan for one checked robot (modc.model.Robot). files: its URDF and meshes as the compiler
    emits them ({relative path: content}); generated when omitted. Raises PlanError."""
    import numpy as np

    from ..physical.checker import DEFAULT_MARGIN, CollisionChecker
    from . import planner

    t_begin = time.perf_counter()
    if seed < 0:
        raise ValueError("seed must be >= 0")
    job = _job(robot, target, start, seed, sources or {})
    margin = DEFAULT_MARGIN if margin is None else float(margin)
    timeout = planner.DEFAULT_TIMEOUT if timeout is None else float(timeout)
    max_checks = planner.DEFAULT_MAX_CHECKS if max_checks is None else int(max_checks)

    checker = CollisionChecker(robot, files, margin)
    q_start = np.clip(np.array(job.q_start, float), checker.lower, checker.upper)
    _check_start(job, checker, q_start)
    solver, solutions, goals = _goals(job, checker, q_start)
    path, tried = _path(job, checker, q_start, goals, timeout, max_checks)
    result = _timed(job, checker, solver, path, with_robot_name)
    result.stats.update({"time": time.perf_counter() - t_begin, "checks": checker.checks,
                         "ik_solutions": len(solutions), "goals_tried": tried})
    return result


@dataclass(frozen=True)
class _Job:
    """What one plan_robot call is asked: the robot, its target, where it starts, the seed."""

    robot: ResolvedRobot
    target: Any  # modc.model.Target
    start: str  # name of the start pose
    q_start: tuple[float, ...]
    start_span: Any
    seed: int
    sources: dict

    def fail(self, code, span, **fields) -> PlanError:
        return PlanError.of(code, span, self.sources, **fields)


def _job(robot: ResolvedRobot, target: str, start: str | None, seed: int, sources: dict) -> _Job:
    """The target and start pose named on the command line (target-unknown, pose-unknown)."""
    tgt = next((t for t in robot.targets if t.name == target), None)
    if tgt is None:
        raise PlanError.of(codes.TARGET_UNKNOWN, COMMAND_LINE, sources, robot=robot.name, target=target,
                           known=_known("targets", (t.name for t in robot.targets)))
    sp = start_pose(robot, start)
    if sp is None:
        raise PlanError.of(codes.POSE_UNKNOWN, COMMAND_LINE, sources, robot=robot.name, pose=start,
                           known=_known("poses", (p.name for p in robot.poses)))
    return _Job(robot, tgt, sp[0], sp[1], sp[2], seed, sources)


def _check_start(job: _Job, checker, q_start) -> None:
    """The start pose must be collision-free; closer than the margin, the margin shrinks to fit."""
    fixed = checker.static_contacts()
    hit = fixed + checker.contacts(q_start, 0.0)
    if hit:
        hint = ("base_link never moves: move or shrink the obstacle so that it does not reach into the arm's base "
                "(a floor may touch it)" if fixed else
                "choose another start pose with --start, or move the obstacle")
        if job.robot.pose(job.start) is None:  # the implicit home pose
            hint += ("; the file declares no `pose home`, so the start is every joint at 0 (or mid-range where 0 is "
                     "outside its limits)")
        raise job.fail(
            codes.START_IN_COLLISION, job.start_span, pose=job.start, contacts=_contacts_text(hit), hint=hint
        )
    if not checker.valid(q_start):
        clearance, pair = checker.clearance(q_start)
        if clearance / 2 < MIN_MARGIN:
            raise job.fail(codes.START_IN_COLLISION, job.start_span, pose=job.start,
                           contacts=f"{pair.describe()} are {clearance * 1000:.2f} mm apart",
                           hint=f"the planner needs {2 * MIN_MARGIN * 1000:.1f} mm of clearance at the start")
        checker.set_margin(clearance / 2)


def _goals(job: _Job, checker, q_start):
    """(IK solver, every IK solution, the collision-free goal poses closest first): IK of the
    target, then the solutions that keep the margin (or, failing that, some clearance)."""
    import numpy as np

    from ..kinematics import rpy_matrix
    from . import advice, ik

    tgt = job.target
    rotation = None if tgt.rpy is None else rpy_matrix(tgt.rpy)
    solver = ik.PositionIK(checker.model, checker.data, checker.tool_frame, checker.lower, checker.upper, rotation,
                           tgt.pointing)
    verdict: dict[bytes, bool] = {}

    def free(q) -> bool:
        key = np.asarray(q, float).tobytes()
        if key not in verdict:
            verdict[key] = checker.valid(q)
        return verdict[key]

    solutions, best = ik.solve(
        solver,
        tgt.xyz,
        q_start,
        IK_SEEDS_PER_JOINT * job.robot.dof,
        job.seed,
        batches=IK_BATCHES,
        enough=free,
        tolerance=tgt.tolerance,
    )
    if not solutions:  # say why: too far, too close, orientation or limits (advice.py)
        raise advice.unreachable(job, checker, solver, best, q_start)
    return solver, solutions, _free_goals(job, checker, solutions, free)


def _free_goals(job: _Job, checker, solutions, free) -> list:
    """The IK solutions that keep the margin (closest to the start first); else the first with
    more than 2 MIN_MARGIN of clearance, the margin shrunk to it; else target-in-collision."""
    from . import advice

    goals: list = []
    near: list = []
    colliding: list = []
    for s in solutions:
        if free(s.q):
            goals.append(s.q)
        else:
            contacts = checker.contacts(s.q, 0.0)
            (colliding if contacts else near).append((s.q, contacts))
    if not goals and near:  # reachable, but closer to an obstacle than the margin: plan with less
        scored = []
        for q, _ in near:
            c, _pair = checker.clearance(q)
            if c / 2 >= MIN_MARGIN:
                scored.append((q, c))
        if scored:
            q, c = scored[0]
            checker.set_margin(min(checker.margin, c / 2))
            goals = [q]
    if not goals:
        names: list[str] = []
        for _q, contacts in colliding + near:
            for c in contacts:
                if c.describe() not in names:
                    names.append(c.describe())
        what = "; ".join(names) if names else f"closer than {2 * MIN_MARGIN * 1000:.1f} mm to an obstacle"
        inside = advice.inside_obstacle(job.robot, job.target.xyz)
        raise job.fail(codes.TARGET_IN_COLLISION, job.target.span, target=job.target.name, contacts=what,
                       hint=f"all {len(solutions)} arm pose(s) that put tool0 on the target collide; "
                            + (f"the target lies {inside}: move it out" if inside else
                               "move the target or the obstacle"))
    return goals


def _limits(robot: ResolvedRobot):
    """(velocity, acceleration) limits per joint, rad/s and rad/s² (timing.py)."""
    import numpy as np

    from . import timing

    vmax = np.array([_velocity(robot, i) for i in range(1, robot.dof + 1)])
    return vmax, vmax / timing.ACCEL_RAMP_TIME


def _path(job: _Job, checker, q_start, goals, timeout: float, max_checks: int):
    """(polyline of joint vectors, goals tried): RRT-Connect towards the goals in turn, every
    edge of the result certified again."""
    from . import planner, timing

    vmax, amax = _limits(job.robot)
    cost = lambda p: timing.path_duration(p, vmax, amax)  # noqa: E731
    tgt = job.target
    path = None
    tried = 0
    deadline = time.monotonic() + timeout
    for q_goal in goals[:MAX_GOALS]:
        if time.monotonic() >= deadline:
            break
        tried += 1
        try:
            path = planner.find_path(checker, q_start, q_goal, job.seed, cost, timeout=timeout, max_checks=max_checks,
                                     deadline=deadline)
        except planner.PlannerUnavailable as e:
            raise job.fail(codes.NO_PATH, tgt.span, pose=job.start, target=tgt.name,
                           detail=f"the straight motion collides and {e}",
                           hint="install OMPL 2: pip install 'ompl>=2.0'") from None
        if path is not None:
            break
    if path is None:
        raise job.fail(
            codes.NO_PATH, tgt.span, pose=job.start, target=tgt.name,
            detail=f"RRT-Connect towards {tried} of the {len(goals)} collision-free goal pose(s), "
                   f"{max_checks} collision checks each, {timeout:g} s in all",
            hint="try another --seed or --start pose; the target may be enclosed by obstacles")
    # an independent pass over the final polyline (every edge certified again)
    for a, b in itertools.pairwise(path):
        if not checker.motion_valid(a, b, check_ends=True):  # pragma: no cover - the planner certified it
            raise job.fail(codes.NO_PATH, tgt.span, pose=job.start, target=tgt.name,
                           detail="the simplified path failed its final collision check",
                           hint="try another --seed")
    return path, tried


def _timed(job: _Job, checker, solver, path, with_robot_name: bool) -> Plan:
    """The polyline timed (timing.py) and rounded into the Plan."""
    import numpy as np

    from . import timing

    robot, tgt = job.robot, job.target
    vmax, amax = _limits(robot)
    ts, qs = timing.parameterise(path, vmax, amax)
    q_rows = tuple(tuple(round(float(v), 12) + 0.0 for v in q) for q in qs)
    t_rows = tuple(round(float(t), 9) for t in ts)
    final = np.array(q_rows[-1])
    tool_error = float(np.linalg.norm(solver.position(final) - np.asarray(tgt.xyz)))
    clear = min(checker.clearance(np.array(q))[0] for q in q_rows)  # inf: no pair to check
    return Plan(
        robot=robot.name, target=tgt.name, start=job.start, target_xyz=tuple(tgt.xyz),
        joint_names=tuple(f"joint_{i}" for i in range(1, robot.dof + 1)), t=t_rows, q=q_rows,
        waypoints=tuple(tuple(float(v) for v in p) for p in path), tool_error=tool_error,
        min_clearance=float(clear) if math.isfinite(clear) else None, margin=checker.margin, seed=job.seed,
        velocity_limits=tuple(float(v) for v in vmax),
        with_robot_name=with_robot_name)


def _velocity(robot: ResolvedRobot, i: int) -> float:
    """The URDF velocity limit of joint i (1-based): the actuator's rated speed, rad/s."""
    return float(robot.library.variants[robot.units[i - 1].variant].actuator.velocity)


__all__ = ["EXIT_FAILED", "EXIT_USAGE", "Plan", "PlanError", "plan", "plan_robot", "start_pose"]
