"""Choosing one robot of a file by name: one rule and one diagnostic (robot-unknown) for every
command and the Python API (`--robot NAME`, the "robot" of a trajectory file, modc.load)."""
from __future__ import annotations

from collections.abc import Sequence

from ..diagnostics import Diagnostic, Span, codes
from .robot import Design, ResolvedRobot

COMMAND_LINE = Span.point("<command line>")


class RobotChoiceError(LookupError):
    """No robot, or more than one, answers the request. diagnostic: robot-unknown, with a hint
    that lists the choices; a command-line error (exit 2)."""

    def __init__(self, diagnostic: Diagnostic):
        super().__init__(diagnostic.message)
        self.diagnostic = diagnostic


def _fail(detail: str, known: str, where: Span) -> RobotChoiceError:
    return RobotChoiceError(codes.ROBOT_UNKNOWN.at(where, detail=detail, known=known))


def choose_robot(design: Design, name: str | None = None, among: Sequence[ResolvedRobot] | None = None, why: str = "",
                 say: str = "--robot NAME", where: Span = COMMAND_LINE) -> ResolvedRobot:
    """The robot called `name`; without a name, the only one of `among` (default: every robot of
    the file; `why` says what they have in common, e.g. "have a target 'plant'"); `say` tells the
    user how to name one. Raises RobotChoiceError. The design's checks passed (its robots are
    resolved: InvalidModel otherwise)."""
    robots = list(design.resolved_robots())
    if name is not None:
        found = next((r for r in robots if r.name == name), None)
        if found is None:
            raise _fail(
                f"{design.path} has no robot '{name}'",
                "robots: " + (", ".join(r.name for r in robots) or "none"),
                where,
            )
        return found
    pool = robots if among is None else list(among)
    if len(pool) == 1:
        return pool[0]
    if not robots:
        raise _fail(f"{design.path} defines no robot", "add a block such as: robot arm { chain H1 - L1 }", where)
    if not pool:
        raise _fail(f"no robot of {design.path} fits", "robots: " + ", ".join(r.name for r in robots), where)
    names = ", ".join(r.name for r in pool)
    detail = f"robots {names} all {why}" if why else f"{design.path} defines {len(pool)} robots ({names})"
    raise _fail(detail, f"say which one with {say}", where)


__all__ = ["COMMAND_LINE", "RobotChoiceError", "choose_robot"]
