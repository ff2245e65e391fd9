"""The Python API: load a checked robot and ask it for kinematics.

    import modc
    robot = modc.load("examples/farm.mod")          # the only robot, or robot="name"
    chain = modc.chain(robot)
    chain.T_base_tool([0.1, -0.5, 0.3])              # 4x4, base_link -> tool0
    chain.frames(q)                                  # every unit's frames (T_base_unit, T_base_twist1, …)
"""
from __future__ import annotations

from pathlib import Path

from .diagnostics.render import render_text
from .model import Design, ResolvedRobot


class ModcError(Exception):
    """A file with errors; str() is the rendered diagnostics."""

    def __init__(self, diagnostics, sources):
        super().__init__(render_text([d for d in diagnostics if d.is_error], sources))
        self.diagnostics = diagnostics


def _design(path: str | Path, library: str | None) -> Design:
    from .compiler import InputError, check_file

    try:
        c = check_file(path, library)
    except InputError as e:
        raise ModcError([e.diagnostic], {}) from None
    if not c.ok:
        raise ModcError(c.diagnostics, c.sources)
    return c.design


def load_all(path: str | Path, library: str | None = None) -> list[ResolvedRobot]:
    return list(_design(path, library).resolved_robots())


def load(path: str | Path, robot: str | None = None, library: str | None = None) -> ResolvedRobot:
    """The robot called `robot`, or the file's only one; ModcError (robot-unknown) otherwise."""
    from .model.select import RobotChoiceError, choose_robot

    try:
        return choose_robot(_design(path, library), robot, say="robot=NAME")
    except RobotChoiceError as e:
        raise ModcError([e.diagnostic], {}) from None


def chain(robot: ResolvedRobot):
    from .kinematics import Chain

    return Chain(robot)
