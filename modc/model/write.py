"""Model -> .mod text (what dh2mod prints). Angles in degrees, lengths in mm, both exact to 1e-9."""
from __future__ import annotations

import math
from collections.abc import Sequence

from ..formatting import fixed as _num
from .robot import Robot


def angle(x: float) -> str:
    return f"{_num(math.degrees(x))}deg"


def length(x: float) -> str:
    return f"{_num(x * 1000, 6)}mm"


def unit_text(robot: Robot, i: int) -> str:
    u = robot.units[i]
    params = []
    if u.pivot:
        params.append(f"pivot={angle(u.pivot)}")
    if u.port:
        params.append(f"port={angle(u.port)}")
    if u.link is not None:
        params.append(f"link={length(u.link)}")
    return u.name + (f"({', '.join(params)})" if params else "")


def vec(values, unit: str) -> str:
    return "(" + ", ".join(values) + f") {unit}"


def robot_text(robot: Robot, comments: Sequence[str] = ()) -> str:
    # a comment ends at a line break: text from outside (a file name) must not start a new line
    lines = [f"# {' '.join(c.splitlines())}" if c else "#" for c in comments]
    lines.append(f"robot {robot.name} {{")
    lines.append("    chain " + " - ".join(unit_text(robot, i) for i in range(robot.dof)))
    if robot.library_ref != "mark2":
        lines.append(f"    library {robot.library_ref}")
    t = robot.tool
    if t.xyz != (0.0, 0.0, 0.0) or t.rpy != (0.0, 0.0, 0.0):
        parts = ["    tool"]
        if t.xyz != (0.0, 0.0, 0.0):
            parts.append("at " + vec([_num(v) for v in t.xyz], "m"))
        if t.rpy != (0.0, 0.0, 0.0):
            parts.append("rpy " + vec([_num(math.degrees(v)) for v in t.rpy], "deg"))
        lines.append(" ".join(parts))
    lines.append("}")
    return "\n".join(lines) + "\n"


def _placement(keyword: str, t) -> str | None:
    if t.xyz == (0.0, 0.0, 0.0) and t.rpy == (0.0, 0.0, 0.0):
        return None
    parts = [f"    {keyword}"]
    if t.xyz != (0.0, 0.0, 0.0):
        parts.append("at " + vec([_num(v) for v in t.xyz], "m"))
    if t.rpy != (0.0, 0.0, 0.0):
        parts.append("rpy " + vec([_num(math.degrees(v)) for v in t.rpy], "deg"))
    return " ".join(parts)


def _obstacle(o) -> str:
    at = "at " + vec([_num(v) for v in o.origin.xyz], "m")
    rpy = " rpy " + vec([_num(math.degrees(v)) for v in o.origin.rpy], "deg") if o.origin.rpy != (0.0, 0.0, 0.0) else ""
    if o.shape == "box":
        return f"    box {o.name} size {vec([_num(v) for v in o.size], 'm')} {at}{rpy}"
    if o.shape == "sphere":
        return f"    sphere {o.name} radius {_num(o.size[0])} m {at}"
    return f"    cylinder {o.name} radius {_num(o.size[0])} m length {_num(o.size[1])} m {at}{rpy}"


def _pointing(d) -> str:
    return "" if d is None else " pointing (" + ", ".join(_num(v) for v in d) + ")"


def target_text(t) -> str:
    from .robot import ORIENTATION_TOLERANCE, POSITION_TOLERANCE

    s = f"    target {t.name} at {vec([_num(v) for v in t.xyz], 'm')}"
    if t.rpy is not None:
        s += " rpy " + vec([_num(math.degrees(v)) for v in t.rpy], "deg")
    s += _pointing(t.pointing)
    if t.position_tolerance != POSITION_TOLERANCE or t.orientation_tolerance != ORIENTATION_TOLERANCE:
        s += f" within {_num(t.position_tolerance * 1000, 6)} mm"
        if t.rpy is not None or t.pointing is not None:
            s += f", {_num(math.degrees(t.orientation_tolerance))} deg"
    return s


def robot_file_text(robot: Robot, comments: Sequence[str] = (), state_base: bool = False) -> str:
    """A complete robot block: chain, library, placements, payload, limits, poses, the cell and its
    targets. state_base: write `base at` even when the base is the origin (a searched base pose
    says where it is)."""
    lines = robot_text(robot, comments).rstrip("\n").split("\n")[:-1]  # without the closing brace
    if robot.library_ref != "mark2" and robot.library_dir is not None:
        from pathlib import Path

        # a library file named relative to the source: name it absolutely (the text came from a
        # quoted string, so it holds no quote or newline)
        path = (Path(robot.library_dir) / robot.library_ref).resolve()
        lines = [f'    library "{path}"' if ln.startswith("    library ") else ln for ln in lines]
    base = _placement("base", robot.base) or ("    base at (0, 0, 0) m" if state_base else None)
    if base:
        lines.append(base)
    if robot.payload is not None:
        at = "" if robot.payload.com == (0.0, 0.0, 0.0) else " at " + vec([_num(v) for v in robot.payload.com], "m")
        lines.append(f"    payload {_num(robot.payload.mass * 1000, 6)} g{at}")
    for lim in robot.limits:
        lines.append(
            f"    limit {lim.joint} " + vec([_num(math.degrees(lim.lower)), _num(math.degrees(lim.upper))], "deg")
        )
    for p in robot.poses:
        lines.append(f"    pose {p.name} " + vec([_num(math.degrees(x), 6) for x in p.q], "deg"))
    lines += [_obstacle(o) for o in robot.obstacles]
    lines += [target_text(t) for t in robot.targets]
    lines += task_lines(robot)
    if robot.allow:
        lines.append("    allow " + ", ".join(sorted(robot.allow)))
    lines.append("}")
    return "\n".join(lines) + "\n"


def task_lines(robot: Robot) -> list[str]:
    """The robot's regions, tasks and paths as .mod statements (a task lists its region points one by one)."""
    from .robot import ORIENTATION_TOLERANCE, POSITION_TOLERANCE

    lines = []
    for r in robot.regions:
        s = (f"    region {r.name} box size {vec([_num(v) for v in r.size], 'm')} at "
             f"{vec([_num(v) for v in r.center], 'm')}")
        if r.turned is not None:
            s += " turned " + vec([_num(math.degrees(v)) for v in r.turned], "deg")
        s += f" grid {r.grid[0]} x {r.grid[1]} x {r.grid[2]}"
        if r.rpy is not None:
            s += " rpy " + vec([_num(math.degrees(v)) for v in r.rpy], "deg")
        s += _pointing(r.pointing)
        if r.position_tolerance != POSITION_TOLERANCE or r.orientation_tolerance != ORIENTATION_TOLERANCE:
            s += f" within {_num(r.position_tolerance * 1000, 6)} mm, {_num(math.degrees(r.orientation_tolerance))} deg"
        lines.append(s)
    lines += [f"    task {t.name} {{ visit {', '.join(t.visits)} }}" for t in robot.tasks]
    lines += [f"    path {p.name} from {p.start} to {p.end} straight" for p in robot.paths]
    return lines
