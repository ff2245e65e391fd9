"""Model -> .mod text (what dh2mod prints). Angles in degrees, lengths in mm, both exact to 1e-9."""
from __future__ import annotations

import math

from .robot import Robot


def _num(x: float, digits: int = 9) -> str:
    s = f"{round(x, digits):.{digits}f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


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


def robot_text(robot: Robot, comments: list[str] = ()) -> str:
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
