"""The resolved robot (issue 25, item 3): a type whose library is never None, made once by the
resolve_library pass, which every backend and analysis takes instead of asserting."""
from __future__ import annotations

import dataclasses

import pytest

from modc.compiler import build, check_text
from modc.model import Design, ResolvedRobot, Robot, resolved
from modc.model.base import InvalidModel
from modc.model.library import default as default_library
from modc.model.select import choose_robot

TWO = """robot a {
    chain H1 - L4 - L1
}
robot b {
    chain H1 - L1
    library nosuchlib
}
"""


def test_the_pass_makes_resolved_robots_and_only_those_with_a_library():
    c = check_text(TWO, "t.mod")
    a, b = c.design.robots
    assert type(a) is ResolvedRobot and a.library.name == "mark2"
    assert type(b) is Robot and b.library is None  # its library-not-found is reported
    assert not c.ok
    with pytest.raises(InvalidModel, match="robot b"):
        c.design.resolved_robots()
    with pytest.raises(InvalidModel):
        choose_robot(c.design, "a")  # an analysis never sees a design whose robots are not all resolved


def test_a_resolved_robot_needs_its_library():
    lib = default_library()
    with pytest.raises(TypeError, match="library"):
        ResolvedRobot(name="a")  # the field lost Robot's default None
    with pytest.raises(InvalidModel):
        ResolvedRobot(name="a", library=None)
    r = resolved(Robot(name="a"), lib, base=Robot(name="x").base)
    assert type(r) is ResolvedRobot and r.library is lib
    assert type(r.model_copy(update={"name": "b"})) is ResolvedRobot  # copies stay resolved
    with pytest.raises(dataclasses.FrozenInstanceError):
        r.library = None  # type: ignore[misc]
    with pytest.raises(TypeError):
        resolved(Robot(name="a"), lib, nosuch=1)


def test_backends_take_the_resolved_robots_of_the_build():
    c = check_text("robot a {\n    chain H1 - L4 - L1\n    pose ready (0, 10, 0) deg\n}\n", "t.mod")
    files = build(c, only=["urdf"])
    assert "urdf/mod3_a.urdf" in files
    from modc.backends import Build

    with pytest.raises(InvalidModel):
        Build(Design(path="t.mod", robots=(Robot(name="a"),)))  # never a backend with an unresolved robot
