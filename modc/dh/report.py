"""Requested vs realised DH, as tables for people and as JSON (docs/conventions.md, dh2mod --json)."""
from __future__ import annotations

import math

from ..kinematics import Chain
from ..model import ResolvedRobot
from .extract import realised_dh


def _row(a: float, alpha: float, d: float) -> dict:
    return {"a": round(a, 12) + 0.0, "alpha": round(alpha, 12) + 0.0, "d": round(d, 12) + 0.0}


def compare(robot: ResolvedRobot) -> list[dict]:
    """Per joint: realised (a, alpha, d), and the requested row when the robot came from a DH table."""
    requested = list(robot.dh) if robot.dh else None
    prefer = [r.alpha for r in requested] if requested else None
    rows = realised_dh(Chain(robot), prefer=prefer)
    out = []
    for i, real in enumerate(rows):
        item = {}
        if requested is not None and i < len(requested):
            q = requested[i]
            item["requested"] = _row(q.a, q.alpha, q.d)
        item["realised"] = _row(real.a, real.alpha, real.d)
        out.append(item)
    return out


def text_table(robot: ResolvedRobot) -> str:
    rows = compare(robot)
    has_req = any("requested" in r for r in rows)
    head = f"{'joint':<8}{'a (m)':>10}{'alpha (deg)':>13}{'d (m)':>10}"
    if has_req:
        head += "   |" + f"{'req a':>9}{'req alpha':>11}{'req d':>9}"
    lines = [f"robot {robot.name} ({robot.sequence}), realised standard DH at q = 0", head]
    for i, r in enumerate(rows, start=1):
        x = r["realised"]
        line = f"joint_{i:<2}{x['a']:>10.4f}{math.degrees(x['alpha']):>13.3f}{x['d']:>10.4f}"
        if "requested" in r:
            y = r["requested"]
            line += "   |" + f"{y['a']:>9.4f}{math.degrees(y['alpha']):>11.3f}{y['d']:>9.4f}"
        lines.append(line)
    return "\n".join(lines)
