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
from .model import Robot


class ModcError(Exception):
    """A file with errors; str() is the rendered diagnostics."""

    def __init__(self, diagnostics, sources):
        super().__init__(render_text([d for d in diagnostics if d.is_error], sources))
        self.diagnostics = diagnostics


def load_all(path: str | Path, library: str | None = None) -> list[Robot]:
    from .compiler import InputError, check_file

    try:
        c = check_file(path, library)
    except InputError as e:
        raise ModcError([e.diagnostic], {}) from None
    if not c.ok:
        raise ModcError(c.diagnostics, c.sources)
    return list(c.design.robots)


def load(path: str | Path, robot: str | None = None, library: str | None = None) -> Robot:
    robots = load_all(path, library)
    if robot is None:
        if len(robots) != 1:
            raise ValueError(f"{path} defines {len(robots)} robots; pass robot=NAME")
        return robots[0]
    for r in robots:
        if r.name == robot:
            return r
    raise KeyError(f"{path} has no robot '{robot}'")


def chain(robot: Robot):
    from .kinematics import Chain

    return Chain(robot)
