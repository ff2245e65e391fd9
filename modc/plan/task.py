"""`modc plan FILE --task NAME`: plan and time a robot's whole task (docs/language.md, docs/conventions.md).

    from modc.plan.task import plan_task
    result = plan_task("examples/farm_task.mod", "serve")     # -> TaskPlan, or raises PlanError
    sys.stdout.write(result.dumps())                           # one trajectory, docs/conventions.md
    print(result.summary())

A `task NAME { visit a, b, … }` is an approach from the home pose to a, then one segment per
consecutive pair: each a collision-free joint-space motion within the joint limits, planned by
modc.plan.plan_robot (IK, the collision-free goal closest to where the arm is, RRT-Connect,
certified edges) from where the previous segment ended. A `path NAME from a to b straight` is
an approach to a, then tool0 along the segment a -> b: positions linearly interpolated,
orientation slerped (or, when an end asks only for a direction with `pointing`, tool0's x axis
turned along the great circle between the ends' directions), IK at waypoints STRAIGHT_STEP
apart, each seeded from the previous
solution; every waypoint within the targets' tolerances, joints moving at most MAX_JOINT_STEP
between waypoints (no jump to another IK branch), every motion between waypoints certified
collision-free.

Every segment is then timed time-optimally from rest to rest under the speed and peak-torque
limits (modc.plan.retime, toppra + RNEA). The cycle time and energy are the sums over the
task's segments (the approach from home is reported, and in the trajectory, but not counted).
"""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..diagnostics import codes
from ..model import ResolvedRobot
from ..model.robot import StraightPath, Task
from ..model.select import COMMAND_LINE, RobotChoiceError, choose_robot
from ..trajectory import Trajectory
from .errors import EXIT_FAILED, EXIT_USAGE, PlanError

STRAIGHT_STEP = 0.002  # m between IK waypoints along a straight path
STRAIGHT_ANGLE_STEP = math.radians(1.0)  # and at most this much rotation of tool0
MAX_JOINT_STEP = 0.1  # rad: more between neighbouring waypoints is a jump (the IK changed branch)
START = "task start"  # the name the pose each segment starts from is given (in plan_robot's messages)
# progress(k, n, kind, a, b): segment k of n (0: the approach from home) starts (modc plan's display)
Progress = Callable[[int, int, str, str, str], None]


@dataclass(frozen=True)
class Segment:
    kind: str  # approach | motion | straight
    start: str
    end: str
    t0: float  # s, when it starts in the task's trajectory
    duration: float  # s
    energy: float  # J
    peak_share: float  # max |τ_i| / τ_peak,i along it
    speed_share: float  # max |q̇_i| / v_max,i along it
    waypoints: tuple[tuple[float, ...], ...]  # the geometric path it follows

    def to_json(self) -> dict:
        return {"kind": self.kind, "from": self.start, "to": self.end, "t_start_s": round(self.t0, 9),
                "duration_s": round(self.duration, 9), "energy_j": round(self.energy, 9),
                "peak_torque_share": round(self.peak_share, 6), "peak_speed_share": round(self.speed_share, 6)}


@dataclass(frozen=True)
class TaskPlan:
    robot: str
    task: str
    kind: str  # task | path
    joint_names: tuple[str, ...]
    t: tuple[float, ...]
    q: tuple[tuple[float, ...], ...]
    segments: tuple[Segment, ...]
    with_robot_name: bool = False

    @property
    def counted(self) -> list[Segment]:
        return [s for s in self.segments if s.kind != "approach"]

    @property
    def cycle_time(self) -> float:
        return sum(s.duration for s in self.counted)

    @property
    def energy(self) -> float:
        return sum(s.energy for s in self.counted)

    @property
    def peak_share(self) -> float:
        """Over the counted segments, as cycle time and energy are (the approach from home has its
        own figure in its segment)."""
        return max((s.peak_share for s in self.counted), default=0.0)

    @property
    def trajectory(self) -> Trajectory:
        return Trajectory(self.joint_names, self.t, self.q, self.robot if self.with_robot_name else None)

    def dumps(self) -> str:
        """docs/conventions.md plan JSON for the whole task, with the task's figures as extra keys."""
        import json

        text = self.trajectory.dumps()
        extra = {"task": self.task, "cycle_time_s": round(self.cycle_time, 9), "energy_j": round(self.energy, 9),
                 "peak_torque_share": round(self.peak_share, 6), "segments": [s.to_json() for s in self.segments]}
        lines = "".join(f"  {json.dumps(k)}: {json.dumps(v)},\n" for k, v in extra.items())
        head, _, rest = text.partition('  "points": [')
        return head + lines + '  "points": [' + rest

    def summary(self) -> str:
        out = [f"robot {self.robot}: {self.kind} '{self.task}', {len(self.counted)} segment(s): cycle time "
               f"{self.cycle_time:.3f} s, energy {self.energy:.2f} J, peak torque {self.peak_share:.0%} of peak"]
        width = max(len(f"{s.start} -> {s.end}") for s in self.segments)
        first = int(not self.segments or self.segments[0].kind != "approach")  # no approach: home touches the cell
        for i, s in enumerate(self.segments, start=first):
            label = "approach" if s.kind == "approach" else f"{i:>2} {s.kind}"
            out.append(f"  {label:<11} {f'{s.start} -> {s.end}':<{width}}  {s.duration:7.3f} s  {s.energy:7.2f} J  "
                       f"torque {s.peak_share:4.0%}  speed {s.speed_share:4.0%}")
        start = "with the approach" if not first else "from the first waypoint (home touches the cell: no approach)"
        out.append(f"  trajectory  {len(self.t)} points, {self.t[-1]:.3f} s {start}; "
                   "each segment time-optimal from rest to rest (speed: library RPM, torque: peak, with the payload)")
        return "\n".join(out)


def plan_task(path, task: str, robot: str | None = None, seed: int = 0, library: str | None = None,
              timeout: float | None = None, progress: Progress | None = None) -> TaskPlan:
    """Read a .mod (or YAML) file and plan and time the robot's task or path `task`. Raises PlanError."""
    from . import checked_or_raise

    checked = checked_or_raise(path, library)
    robots = list(checked.design.robots)
    has = [r for r in robots if _find(r, task) is not None]
    if robot is None and len(robots) > 1 and not has:
        raise _unknown(robots, task, checked.sources)
    try:
        chosen = choose_robot(checked.design, robot, has if robot is None and len(robots) > 1 else None,
                              why=f"have a task '{task}'")
    except RobotChoiceError as e:
        raise PlanError([e.diagnostic], {}, EXIT_USAGE) from None
    return plan_task_robot(chosen, task, seed=seed, sources=checked.sources, with_robot_name=len(robots) > 1,
                           timeout=timeout, progress=progress)


def _find(robot: ResolvedRobot, name: str) -> Task | StraightPath | None:
    either: list[Task | StraightPath] = [*robot.tasks, *robot.paths]
    return next((t for t in either if t.name == name), None)


def _unknown(robots, task: str, sources) -> PlanError:
    names = [f"{r.name}: {', '.join(t.name for t in (*r.tasks, *r.paths)) or 'none'}" for r in robots]
    known = ("tasks and paths per robot: " + "; ".join(names)) if any(r.tasks or r.paths for r in robots) else \
        "the robot declares no tasks: add `task NAME { visit a, b }` or `path NAME from a to b straight`"
    d = codes.TASK_UNKNOWN.at(COMMAND_LINE, robot=" or ".join(r.name for r in robots), task=task, known=known)
    return PlanError([d], sources, EXIT_USAGE)


def plan_task_robot(robot: ResolvedRobot, task: str, seed: int = 0, sources=None, with_robot_name: bool = False,
                    timeout: float | None = None, progress: Progress | None = None) -> TaskPlan:
    """Plan and time one checked robot's task or path. Raises PlanError. progress(k, n, kind, a,
    b) is called as segment k of n (0: the approach) starts, and (n, n, "done", "", "") at the end."""
    from ..physical.checker import CollisionChecker
    from . import clear_solution, start_pose
    from .retime import Limits, TimingError, join

    sources = sources or {}
    item = _find(robot, task)
    if item is None:
        raise _unknown([robot], task, sources)
    kind = "task" if isinstance(item, Task) else "path"
    visits = list(item.visits) if isinstance(item, Task) else [item.start, item.end]
    checker = CollisionChecker(robot)
    limits = Limits.of(robot)
    job = _Job(robot, item, kind, seed, sources, checker, limits, timeout)
    where, q_home, _span = start_pose(robot, None)
    q = np.array(q_home, float)
    pieces, segments, t0 = [], [], 0.0
    steps = [("approach", where, visits[0])]
    if len(visits) > 1 and not checker.valid(q):
        # home touches the cell (a ceiling over the arm): the task starts at its first waypoint,
        # reached clear of the cell - the approach is not part of the task, so it cannot veto it
        first = clear_solution(robot, checker, job.target(visits[0]), q, seed)
        if first is not None:
            q, steps = np.array(first, float), []
    steps += [("motion" if kind == "task" else "straight", a, b) for a, b in zip(visits, visits[1:], strict=False)]
    # segment numbers: 0 is the approach (even when there is none), the task's own from 1
    skipped = int(steps[0][0] != "approach")
    total = len(steps) + skipped
    for number, (what, a, b) in enumerate(steps, start=skipped):
        if what != "approach" and a == b:
            continue
        if progress is not None:
            progress(number, total, what, a, b)
        try:
            if what == "straight":
                path, timed = job.straight(number, a, b, q)
            else:
                path, timed = job.motion(number, what, a, b, q)
        except TimingError as e:
            raise job.fail(number, a, b, str(e), "lighten the payload, or choose a stronger module") from None
        pieces.append(timed)
        segments.append(Segment(what, a, b, t0, timed.duration, timed.energy, timed.peak_share, timed.speed_share,
                                tuple(tuple(float(v) for v in p) for p in path)))
        t0 += timed.duration
        q = np.array(path[-1], float)
    whole = join(pieces, limits, q)
    if progress is not None:
        progress(total, total, "done", "", "")
    t_rows = tuple(round(float(t), 9) for t in whole.t)
    q_rows = tuple(tuple(round(float(v), 12) + 0.0 for v in row) for row in whole.q)
    return TaskPlan(robot.name, task, kind, tuple(f"joint_{i}" for i in range(1, robot.dof + 1)), t_rows, q_rows,
                    tuple(segments), with_robot_name)


@dataclass(frozen=True)
class _Job:
    robot: ResolvedRobot
    item: Any  # its Task or StraightPath
    kind: str
    seed: int
    sources: dict
    checker: Any  # modc.physical.checker.CollisionChecker
    limits: Any  # modc.plan.retime.Limits
    timeout: float | None

    def fail(self, number: int, a: str, b: str, detail: str, hint: str, exit_code: int = EXIT_FAILED) -> PlanError:
        seg = "approach" if number == 0 else str(number)
        d = codes.TASK_SEGMENT_FAILED.at(self.item.span, kind=self.kind, task=self.item.name,
                                         segment=f"{seg} ({a} -> {b})", detail=detail, hint=hint)
        return PlanError([d], self.sources, exit_code)

    def target(self, name: str):
        t = self.robot.task_target(name)
        assert t is not None, name  # lowering resolved every name of the task
        return t

    def motion(self, number: int, what: str, a: str, b: str, q):
        """A collision-free joint-space motion from q (at a) to target b: plan_robot on the robot
        with b among its targets and q as its start pose."""
        from ..model.robot import Pose
        from . import plan_robot
        from .retime import time_polyline

        robot = self.robot
        start = Pose.model_construct(name=START, q=tuple(float(v) for v in q), span=self.item.span)
        targets = tuple(t for t in robot.targets if t.name != b) + (self.target(b),)
        poses = tuple(p for p in robot.poses if p.name != START) + (start,)
        seg_robot = robot.model_copy(update={"targets": targets, "poses": poses})
        try:
            result = plan_robot(seg_robot, b, seed=self.seed, start=START, sources=self.sources, timeout=self.timeout)
        except PlanError as e:
            first = next((d for d in e.diagnostics if d.is_error), None)
            detail = first.message if first is not None else e.message
            raise self.fail(number, a, b, f"{detail} [{e.code}]", first.hint if first is not None else "",
                            e.exit_code) from None
        path = [np.array(p, float) for p in result.waypoints]
        return path, time_polyline(path, self.limits)

    def straight(self, number: int, a: str, b: str, q):
        """tool0 along a -> b from q (the arm at a); then timed, and the timed motion checked."""
        from .retime import time_smooth

        ta, tb = self.target(a), self.target(b)
        path = self._waypoints(number, ta, tb, q)
        timed = time_smooth(path, self.limits)
        self._check_timed(number, ta, tb, timed.q)
        return path, timed

    def _frames(self, ta, tb):
        """(positions, orientation goals) along a -> b at the waypoints: rotations slerped when both
        targets give `rpy`, tool0's x axis turned along the great circle when both ask for a
        direction (`pointing`, or the x axis of an `rpy`), else None."""
        pa, pb = np.asarray(ta.xyz, float), np.asarray(tb.xyz, float)
        mode = _orientation_mode(ta, tb)
        turn = 0.0
        if mode == "rpy":
            import pinocchio as pin

            from ..kinematics import rpy_matrix

            Ra, Rb = np.asarray(rpy_matrix(ta.rpy), float), np.asarray(rpy_matrix(tb.rpy), float)
            turn = float(np.linalg.norm(pin.log3(Ra.T @ Rb)))
        elif mode == "axis":
            turn = _angle(_axis_of(ta), _axis_of(tb))
        n = max(1, math.ceil(max(np.linalg.norm(pb - pa) / STRAIGHT_STEP, turn / STRAIGHT_ANGLE_STEP)))
        s = np.linspace(0.0, 1.0, n + 1)
        return [pa + x * (pb - pa) for x in s], [_goal_at(ta, tb, mode, float(x)) for x in s]

    def _tolerance(self, ta, tb) -> tuple[float, float]:
        return (min(ta.position_tolerance, tb.position_tolerance),
                min(ta.orientation_tolerance, tb.orientation_tolerance) if _orientation_mode(ta, tb) else math.inf)

    def _waypoints(self, number: int, ta, tb, q) -> list[np.ndarray]:
        from .ik import PositionIK

        ch = self.checker
        positions, rotations = self._frames(ta, tb)
        tol_p, tol_o = self._tolerance(ta, tb)
        path = [np.asarray(q, float)]
        mode = _orientation_mode(ta, tb)
        for k in range(1, len(positions)):
            x, goal = positions[k], rotations[k]
            solver = PositionIK(ch.model, ch.data, ch.tool_frame, ch.lower, ch.upper,
                                goal if mode == "rpy" else None, goal if mode == "axis" else None)
            qn, _ = solver.run(path[-1], x)
            pe, oe = solver.errors(qn, x)
            at = f"{k / (len(positions) - 1):.0%} of the way"
            if pe > tol_p or oe > tol_o:
                raise self.fail(number, ta.name, tb.name, f"tool0 cannot stay on the segment: {at}, it is "
                                f"{pe * 1000:.1f} mm and {math.degrees(oe):.1f} deg off",
                                "move the targets, or loosen their tolerances (`within`)")
            jump = float(np.max(np.abs(qn - path[-1])))
            if jump > MAX_JOINT_STEP:
                raise self.fail(number, ta.name, tb.name, f"the joints jump by {math.degrees(jump):.0f} deg {at} "
                                "(the arm passes a singular or limit pose)",
                                "move the segment away from the arm's singular poses and joint limits")
            if not ch.motion_valid(path[-1], qn):
                raise self.fail(number, ta.name, tb.name, f"the arm collides {at}: {self._contacts(qn)}",
                                "move the segment or the obstacle")
            path.append(qn)
        return path

    def _contacts(self, q) -> str:
        ch = self.checker
        contacts = ch.contacts(q, 0.0)
        if contacts:
            return "; ".join(c.describe() for c in contacts)
        clearance, pair = ch.clearance(q)
        what = pair.describe() if pair is not None else "two bodies"
        return f"{what}, {clearance * 1000:.1f} mm apart (the planner keeps {ch.margin * 1000:.1f} mm)"

    def _check_timed(self, number: int, ta, tb, qs) -> None:
        """The spline through the waypoints stays within the tolerances of the segment (position,
        and orientation against the goal at the same fraction of the way: the slerp, or the turned
        approach axis), the joint limits, and
        free of collisions, at every sample."""

        from .ik import PositionIK

        ch = self.checker
        solver = PositionIK(ch.model, ch.data, ch.tool_frame, ch.lower, ch.upper)
        pa, pb = np.asarray(ta.xyz, float), np.asarray(tb.xyz, float)
        tol_p, tol_o = self._tolerance(ta, tb)
        mode = _orientation_mode(ta, tb)
        for q in qs:
            M = solver.placement(q)
            p = np.array(M.translation)
            off = distance_to_segment(p, pa, pb) > tol_p
            if mode is not None and not off:
                d = pb - pa
                x = float(np.clip(np.dot(p - pa, d) / max(float(np.dot(d, d)), 1e-18), 0.0, 1.0))
                off = _orientation_error(_goal_at(ta, tb, mode, x), np.array(M.rotation), mode) > tol_o
            if off or np.any(q < ch.lower - 1e-9) or np.any(q > ch.upper + 1e-9) or ch.contacts(q, 0.0):
                raise self.fail(number, ta.name, tb.name, "the timed motion leaves the segment's tolerances, a joint "
                                "limit or the free space between the waypoints", "move the segment away from obstacles")


def _axis_of(t) -> np.ndarray | None:
    """The direction a target asks tool0's x axis to point in: its `pointing`, or its rpy's x axis."""
    if t.pointing is not None:
        d = np.asarray(t.pointing, float)
        return d / np.linalg.norm(d)
    if t.rpy is not None:
        from ..kinematics import rpy_matrix

        return np.asarray(rpy_matrix(t.rpy), float)[:, 0]
    return None


def _orientation_mode(ta, tb) -> str | None:
    """What a straight path holds of tool0's orientation: the whole frame when both ends give rpy,
    the approach axis when both ask for one at least (pointing), nothing when an end asks none."""
    if ta.rpy is not None and tb.rpy is not None:
        return "rpy"
    if _axis_of(ta) is not None and _axis_of(tb) is not None:
        return "axis"
    return None


def _angle(u, v) -> float:
    return float(np.arctan2(np.linalg.norm(np.cross(u, v)), float(np.dot(u, v))))


def _goal_at(ta, tb, mode: str | None, x: float) -> np.ndarray | None:
    """The orientation goal a fraction x of the way from a to b: the slerped rotation (rpy), or
    the approach axis turned along the great circle from a's to b's (axis)."""
    if mode == "rpy":
        import pinocchio as pin

        from ..kinematics import rpy_matrix

        Ra, Rb = np.asarray(rpy_matrix(ta.rpy), float), np.asarray(rpy_matrix(tb.rpy), float)
        return Ra @ np.asarray(pin.exp3(x * np.asarray(pin.log3(Ra.T @ Rb))))
    if mode == "axis":
        u, v = _axis_of(ta), _axis_of(tb)
        assert u is not None and v is not None
        theta = _angle(u, v)
        if theta < 1e-9:
            return u
        w = np.cross(u, v)
        if np.linalg.norm(w) < 1e-12:  # opposite directions: turn about any axis across them
            w = np.cross(u, (1.0, 0.0, 0.0) if abs(u[0]) < 0.9 else (0.0, 1.0, 0.0))
        w = w / np.linalg.norm(w)
        t = x * theta  # Rodrigues: u turned by t about w (w is perpendicular to u)
        return u * math.cos(t) + np.cross(w, u) * math.sin(t)
    return None


def _orientation_error(goal, R: np.ndarray, mode: str | None) -> float:
    """rad between tool0's orientation R and the goal (a rotation, or an axis for tool0's x)."""
    if mode == "rpy":
        from ..kinematics import rotation_error

        return float(np.linalg.norm(rotation_error(goal, R)))
    if mode == "axis":
        return _angle(R[:, 0], goal)
    return 0.0


def distance_to_segment(p, a, b) -> float:
    d = b - a
    s = float(np.clip(np.dot(p - a, d) / max(float(np.dot(d, d)), 1e-18), 0.0, 1.0))
    return float(np.linalg.norm(p - (a + s * d)))


__all__ = ["Segment", "TaskPlan", "distance_to_segment", "plan_task", "plan_task_robot"]
