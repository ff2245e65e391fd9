"""A ranking led by mass (`rank mass`, or `rank cycle_time, mass` whose static search ranks by
mass) stops the static search as soon as enough designs are lighter than every shape not yet
searched - later tiers (more units) included - and finds what the whole search finds."""
from __future__ import annotations

import pytest
from conftest import SMALL_CELL

from modc.compiler import check_text
from modc.design import run
from modc.design.verify_order import Verifier


def _problem(text: str):
    c = check_text(text, "cell.mod")
    assert c.ok, c.diagnostics
    return c.design.problems[0]


def _verifier(*rank: str) -> Verifier:
    """The exact checks' order for the small cell ranked by exactly these objectives (a task
    cell's static search ranks without margin)."""
    p = _problem(SMALL_CELL).model_copy(update={"rank": rank})
    return Verifier(p, 2, None, None)


def test_a_design_is_ahead_only_of_what_no_unsearched_shape_can_beat():
    v = _verifier("mass", "modules")  # no margin: level on every objective counts as ahead
    v.floors = {2: 1.5}  # a shape of 3 units weighing 1.5 kg is still to search
    bound = v.frontier(2, 1.6)
    assert bound == (1.5, 3.0)
    assert not v._ahead((1.55, 2.0, "H1-L3"), bound)  # a lighter 3-unit arm may still come
    assert v._ahead((1.4, 3.0, "H1-L3-L3"), bound)
    assert v._ahead((1.5 + 1e-12, 3.0, "x"), bound)  # level: masses summed in another order
    assert not v._ahead((1.5, 4.0, "x"), bound)  # level on mass, more modules
    assert v.frontier(3, float("inf")) is None  # nothing left


def test_an_unbounded_objective_keeps_a_design_from_being_ahead_on_it():
    v = _verifier("modules", "mass", "margin")
    v.floors = {2: 1.0}
    bound = v.frontier(2, 1.6)
    assert bound[:2] == (2.0, 1.6)
    assert not v._ahead((2.0, 1.6, -0.99, "x"), bound)  # the unsearched shape's margin may be larger
    assert v._ahead((2.0, 1.5, -0.5, "x"), bound)
    assert not v._ahead((3.0, 0.1, -1.0, "x"), bound)
    assert v._ahead((2.0, 9.0, -0.1, "x"), v.frontier(2, float("inf")))  # the tier done: 3 units next
    assert not _verifier("margin", "mass").bounded and v.bounded


CELL = """design light {
    payload 100 g
    box post size (0.05, 0.05, 0.6) m at (0.2, 0.25, 0.3) m
    target a at (0.30, 0.10, 0.25) m
    target b at (0.25, -0.15, 0.30) m
    units 2 to 3
    modules H1, L3, L4
    rank %s
}
"""


@pytest.mark.slow
@pytest.mark.parametrize("rank", ["mass", "mass, modules",
                                  "mass\n    base within box size (0.05, 0.05, 0) m at (0, 0, 0) m step 50 mm"])
def test_mass_first_stops_early_and_returns_what_the_whole_search_returns(monkeypatch, rank):
    p = _problem(CELL % rank)
    early = run.design(p, top=2, seed=0)
    monkeypatch.setattr(Verifier, "bounded", property(lambda self: False))
    whole = run.design(p, top=2, seed=0)
    assert [d.chain() for d in early.designs] == [d.chain() for d in whole.designs]
    assert [d.verified.robot.base for d in early.designs] == [d.verified.robot.base for d in whole.designs]
    assert [round(d.mass, 9) for d in early.designs] == [round(d.mass, 9) for d in whole.designs]
    assert early.designs and early.evaluated < whole.evaluated  # it stopped before the end
    assert early.complete and whole.complete
