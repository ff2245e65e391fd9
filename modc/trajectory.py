"""The trajectory file (docs/conventions.md): what `modc plan --json` prints (Trajectory.dumps, the one
writer) and `modc play --traj` and `modc check --traj` read (load, the one reader).

    {"joint_names": ["joint_1", …, "joint_n"],
     "points": [{"t": 0.0, "q": [rad, …]}, {"t": 0.1, "q": [...]}, …],
     "robot": "farm"}                       optional: which robot of the file (for multi-robot files)

Rules (validate / validate_for): joint_names are the robot's joints, each once, in any order; at
least one point; every t a finite number >= 0, strictly increasing; every q a list of finite
numbers, one per joint name, inside the joint's range (the library's, narrowed by `limit`).
Between points the motion is linear in joint space (Trajectory.at). Errors are plain strings
naming the place in the file ("points[3].t: …"); nothing here raises on bad content.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import TypeGuard

from .formatting import json_number as _num

RANGE_TOL = 1e-9  # rad: q on a joint limit, written with rounding, is still inside


@dataclass(frozen=True)
class Trajectory:
    joint_names: tuple[str, ...]
    t: tuple[float, ...]
    q: tuple[tuple[float, ...], ...]
    robot: str | None = None

    @property
    def duration(self) -> float:
        return self.t[-1] - self.t[0]

    def in_order(self, names) -> Trajectory:
        """The same motion with columns in the order of `names` (e.g. joint_1 … joint_n)."""
        idx = [self.joint_names.index(n) for n in names]
        return Trajectory(tuple(names), self.t, tuple(tuple(row[i] for i in idx) for row in self.q), self.robot)

    def at(self, time: float) -> tuple[float, ...]:
        """Joint values at `time`, linear between points, held before the first and after the last."""
        import bisect

        if time <= self.t[0]:
            return self.q[0]
        if time >= self.t[-1]:
            return self.q[-1]
        k = bisect.bisect_right(self.t, time)
        t0, t1 = self.t[k - 1], self.t[k]
        a = (time - t0) / (t1 - t0)
        return tuple(x0 + a * (x1 - x0) for x0, x1 in zip(self.q[k - 1], self.q[k], strict=True))

    def to_json(self) -> dict:
        doc: dict = {"joint_names": list(self.joint_names)}
        if self.robot is not None:
            doc["robot"] = self.robot
        doc["points"] = [{"t": t, "q": list(q)} for t, q in zip(self.t, self.q, strict=True)]
        return doc

    def dumps(self) -> str:
        """The file's text: one point per line, numbers rounded to 1e-12 and written in a fixed
        way, so the same trajectory always gives the same bytes."""
        lines = ["{", f'  "joint_names": {json.dumps(list(self.joint_names))},']
        if self.robot is not None:
            lines.append(f'  "robot": {json.dumps(self.robot)},')
        lines.append('  "points": [')
        pts = [
            f'    {{"t": {_num(t)}, "q": [{", ".join(_num(x) for x in q)}]}}'
            for t, q in zip(self.t, self.q, strict=True)
        ]
        lines.append(",\n".join(pts))
        lines += ["  ]", "}"]
        return "\n".join(lines) + "\n"


def _number(x: object) -> TypeGuard[float]:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def parse(doc) -> tuple[Trajectory | None, list[str]]:
    """Structure of a loaded JSON document -> (trajectory or None, errors)."""
    errors: list[str] = []
    if not isinstance(doc, dict):
        return None, [f"the top level must be an object with joint_names and points, not {type(doc).__name__}"]
    names = _joint_names(doc.get("joint_names"), errors)
    robot = doc.get("robot")
    if robot is not None and not isinstance(robot, str):
        errors.append("robot: expected a robot name")
        robot = None
    points = doc.get("points")
    if not isinstance(points, list) or not points:
        errors.append("points: expected a non-empty list of {\"t\": seconds, \"q\": [radians…]}")
        return None, errors
    ts: list[float | None] = []  # None: not a valid time (an error says why)
    qs: list[tuple[float, ...] | None] = []
    for k, pt in enumerate(points):
        if not isinstance(pt, dict):
            errors.append(f"points[{k}]: expected an object {{\"t\": …, \"q\": […]}}")
            continue
        ts.append(_time(k, pt.get("t"), ts, errors))
        qs.append(_joints(k, pt.get("q"), names, errors))
    if errors or names is None:
        return None, errors
    # no errors: every time and every q is valid
    times = tuple(float(t) for t in ts if t is not None)
    return Trajectory(tuple(names), times, tuple(q for q in qs if q is not None), robot), []


def _joint_names(names, errors: list[str]) -> list[str] | None:
    if not isinstance(names, list) or not names or not all(isinstance(n, str) for n in names):
        errors.append("joint_names: expected a non-empty list of joint names")
        return None
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        errors.append(f"joint_names: {', '.join(dup)} listed more than once")
    return names


def _time(k: int, t, before: list[float | None], errors: list[str]) -> float | None:
    """points[k].t, or None when it is not a number (errors says why)."""
    where = f"points[{k}].t"
    if not _number(t):
        errors.append(f"{where}: expected a finite number of seconds, got {json.dumps(t)}")
        return None
    if t < 0:
        errors.append(f"{where}: {t:g} s is negative")
    elif before and before[-1] is not None and t <= before[-1]:
        errors.append(f"{where}: {t:g} s does not come after points[{k - 1}].t = {before[-1]:g} s "
                      "(times must increase)")
    return t


def _joints(k: int, q, names: list[str] | None, errors: list[str]) -> tuple[float, ...] | None:
    """points[k].q, or None when it is not a list of finite numbers (errors says why)."""
    where = f"points[{k}].q"
    if not isinstance(q, list) or not all(_number(x) for x in q):
        errors.append(f"{where}: expected a list of finite numbers (radians)")
        return None
    if names is not None and len(q) != len(names):
        errors.append(f"{where}: {len(q)} value(s) for {len(names)} joint name(s)")
    return tuple(float(x) for x in q)


def validate_for(traj: Trajectory, robot) -> list[str]:
    """The trajectory fits this robot: its joints, inside their ranges."""
    want = [f"joint_{i}" for i in range(1, robot.dof + 1)]
    errors = []
    unknown = [n for n in traj.joint_names if n not in want]
    missing = [n for n in want if n not in traj.joint_names]
    if unknown:
        errors.append(
            f"joint_names: robot {robot.name} has no joint(s) {', '.join(unknown)} (its joints: {', '.join(want)})"
        )
    if missing:
        errors.append(f"joint_names: joint(s) {', '.join(missing)} of robot {robot.name} missing")
    if errors:
        return errors
    ordered = traj.in_order(want)
    for i, name in enumerate(want):
        lo, hi = robot.joint_range(i + 1)
        for k, row in enumerate(ordered.q):
            v = row[i]
            if v < lo - RANGE_TOL or v > hi + RANGE_TOL:
                errors.append(f"points[{k}].q: {name} = {v:.6g} rad ({math.degrees(v):.1f}°) is outside its range "
                              f"[{math.degrees(lo):.1f}°, {math.degrees(hi):.1f}°]")
                break  # one message per joint is enough
    return errors


class Problem(str):
    """An error message with the place in the file it is about (1-based; 1, 1 when it has none)."""

    line: int = 1
    col: int = 1

    @classmethod
    def at(cls, message: str, line: int, col: int) -> Problem:
        p = cls(message)
        p.line, p.col = line, col
        return p


def load(path: str | Path) -> tuple[Trajectory | None, list[str]]:
    """Read and check the structure, under the limits of every input file (files.read_json).
    Raises OSError when the file cannot be read (missing, a directory, a FIFO or a device)."""
    from .files import InputProblem, read_json

    try:
        doc = read_json(path)
    except InputProblem as e:
        return None, [Problem.at(str(e), e.line, e.col)]
    return parse(doc)


def diagnostics(path: str, errors: list[str]) -> list:
    """traj-invalid diagnostics for load's or validate_for's errors, at their place in the file."""
    from .diagnostics import Span, codes

    return [codes.TRAJ_INVALID.at(Span.point(path, getattr(e, "line", 1), getattr(e, "col", 1)), detail=e)
            for e in errors]
