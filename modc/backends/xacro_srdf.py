"""The SRDF part of the xacro macro form: config/mod<n>_<name>_macro.srdf.xacro per robot.

The macro form (urdf/mod<n>_<name>_macro.xacro) splits each link of the URDF into the bodies of
its parts (xacro.LINKS), so the SRDF of the URDF, which names only base_link and link_i, leaves
the pairs of those bodies enabled: at the zero pose MoveIt would see the arm in collision.

This file is a macro (prefix, like the arm's own macro) of disable_collisions over the macro
form's links, derived from the URDF's collision matrix (common.collision_matrix) without sampling
again. A macro link's geometry is part of exactly one URDF link's (its body, body_of); so
    - two bodies of the same URDF link are rigidly joined: disabled ("Adjacent", as the Setup
      Assistant does for links that cannot move relative to each other);
    - bodies of two different URDF links: disabled, for the URDF's reason, exactly when the URDF's
      pair is (a pair that never touches in the samples has no part that touches).
"""
from __future__ import annotations

from itertools import combinations

from .._version import __version__
from ..model import ResolvedRobot
from .build import Build
from .common import collision_matrix
from .templates import comment, render


def body_of(robot: ResolvedRobot) -> dict[str, str]:
    """Macro-form link with geometry -> the URDF link whose geometry contains it (xacro.LINKS)."""
    lib = robot.library
    out: dict[str, str] = {}
    for n, unit in enumerate(robot.units, start=1):
        carrier = "base_link" if n == 1 else f"link_{n - 1}"  # the input side rides on the previous link
        out[f"unit_{n}_base"] = carrier
        out[f"unit_{n}_twist1"] = carrier
        out[f"link_{n}"] = f"link_{n}"
        if lib.units[unit.kind].link:
            out[f"unit_{n}_twist2"] = f"link_{n}"
    return out


def disabled_pairs(build: Build, robot: ResolvedRobot) -> list[tuple[str, str, str]]:
    """(link1, link2, reason) over the macro form's links with geometry, in macro-link order."""
    urdf_reasons = {frozenset((p.link1, p.link2)): p.reason for p in collision_matrix(build, robot).disabled}
    bodies = body_of(robot)
    out = []
    for a, b in combinations(bodies, 2):
        if bodies[a] == bodies[b]:
            out.append((a, b, "Adjacent"))
        elif (reason := urdf_reasons.get(frozenset((bodies[a], bodies[b])))) is not None:
            out.append((a, b, reason))
    return out


def macro_srdf_text(build: Build, robot: ResolvedRobot, macro: str, source: str) -> str:
    return render("xacro/robot_macro.srdf.xacro.j2", {
        "version": __version__, "source": comment(source), "robot": robot.name, "sequence": robot.sequence,
        "name": robot.file_stem, "macro": f"{macro}_srdf",
        "pairs": [{"link1": a, "link2": b, "reason": r} for a, b, r in disabled_pairs(build, robot)],
    })
