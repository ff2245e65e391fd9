"""Shapes too large for their live settings to be listed one by one are searched by complexity
level (fewest nonzero twists first) and closed by a dominance bound (modc.design.dominance):
the level lists are checked against an enumeration written here, the kept settings against a
brute force over every setting of the shape ranked by a key written here, and a cell of 4-unit
arms with targets in reach is complete."""
from __future__ import annotations

import itertools
import warnings
from concurrent.futures import ProcessPoolExecutor

import numpy as np
import pytest

from modc.compiler import check_text

TWO = """design d {
    target a at (0.30, 0.10, 0.25) m
    target b at (0.25, -0.15, 0.30) m
    units 4
    modules H1, L1
}
"""


def _problem(text):
    c = check_text(text, "cell.mod")
    assert c.ok, c.diagnostics
    return c.design.problems[0]


def test_level_lists_are_every_live_setting_with_that_many_nonzero_twists():
    """Axes with and without the value 0, families alive at random: each level's list is the
    live settings (numbers in the row-major order of the axes) with exactly c nonzero values."""
    from modc.design import dominance

    values = (np.array([-1.0, 0.0, 1.0]), np.array([0.5, 1.0]), np.array([0.0, 2.0, 3.0, 4.0]),
              np.array([-2.0, 0.0]), np.array([0.0, 7.0, 8.0]))
    lengths = [len(v) for v in values]
    every = np.array(list(itertools.product(*values)))  # row-major: setting i is row i
    nonzero = (every != 0).sum(-1)
    rng = np.random.default_rng(2)
    for head in range(len(values) + 1):
        per = int(np.prod(lengths[head:]))
        families = int(np.prod(lengths[:head]))
        alive = np.sort(rng.choice(families, size=max(1, families // 2), replace=False))
        lv = dominance.levels_of(values, alive, per)
        live = np.isin(np.arange(len(every)) // per, alive)
        for c in range(len(values) + 1):
            want = np.flatnonzero(live & (nonzero == c))
            assert lv.counts[c] == len(want), (head, c)
            assert np.array_equal(dominance.level_numbers(lv, c), want), (head, c)
        assert sum(lv.counts) == live.sum()


def test_the_dominance_rule_needs_keep_settings_at_rounded_worst_zero():
    from modc.design import dominance
    from modc.design.search import Found

    def kept(*worst):
        return [Found((0.0,), (0.0,), (), w) for w in worst]

    assert dominance.dominates(kept(0.0, 0.001, 0.0049), 3)
    assert not dominance.dominates(kept(0.0, 0.001), 3)  # fewer than KEEP
    assert not dominance.dominates(kept(0.0, 0.001, 0.0051), 3)  # rounds to 0.01: a level-(c+1) setting may beat it
    assert dominance.dominates(kept(0.0, 0.0, 0.0, 0.7), 3)  # only the first KEEP count


def _key(f):
    """The ranking within a shape, written here: worst share to 1 %, then fewest nonzero twists,
    then the smallest sum of |angles|, then the values."""
    vals = np.concatenate([f.pivots, f.ports])
    return (round(f.worst, 2), int((np.abs(vals) > 1e-9).sum()), round(float(np.abs(vals).sum()), 9),
            tuple(round(float(v), 9) for v in vals))


@pytest.mark.slow
@pytest.mark.parametrize("keep", [6, 200])
def test_kept_settings_equal_a_brute_force_over_every_setting(monkeypatch, keep):
    """Shape 1-1-1-1 (13^4 = 28,561 settings, the targets in reach), searched by level with a small
    first round (levels 1-2: no setting of level 0 is alive), against every setting screened and
    ranked by the test's key. keep=6 needs level 3 too, then closes level 4 by dominance;
    keep=200 needs every level."""
    from modc.design import dominance, search, settings
    from modc.design.evaluate import Spec
    from modc.design.space import Shape

    p = _problem(TWO)
    spec = Spec.of(p)
    shape = Shape((1, 1, 1, 1), (None,) * 4)
    count = settings.full_axes(spec, shape).count
    assert count == 13 ** 4
    monkeypatch.setattr(search, "KEEP", 10 ** 6)
    brute = search.search_part(spec, shape, ((0, count),), 0)
    assert brute.upto == count
    want = sorted(brute.found, key=_key)[:keep]

    monkeypatch.setattr(search, "KEEP", keep)
    monkeypatch.setattr(dominance, "FIRST", 1000)
    search._PLANS.clear()
    plan = search.plan(spec, shape)
    assert plan.levels is not None and plan.how[0] == "levels" and plan.excluded > 0  # some families out
    res = search.search_shape(spec, shape, 0)
    assert res.complete and res.finished and res.evaluated == count
    got = [(f.pivots, f.ports, round(f.worst, 2)) for f in res.found]
    assert got == [(f.pivots, f.ports, round(f.worst, 2)) for f in want]
    rounds = sorted({q.how for q in res.parts})
    assert rounds[0] == plan.how and len(rounds) >= 2  # the first round did not close it
    last = rounds[-1][2]
    if keep == 6:  # closed by dominance: the levels above the last one searched
        assert round(want[-1].worst, 2) == 0.0 and res.dominated == sum(plan.levels.counts[last + 1:]) > 0
    else:
        assert res.dominated == 0 and last == len(plan.levels.counts) - 1


def test_a_level_over_the_budget_falls_back_to_the_coarse_grid_and_says_so(monkeypatch):
    """Kept settings that cannot close the shape (KEEP larger than its feasible settings at
    rounded worst 0.0 among the levels that fit the budget): the levels above the last one
    searched go on the coarse grid and the shape is not complete."""
    from modc.design import dominance, search, settings
    from modc.design.evaluate import Spec
    from modc.design.space import Shape

    spec = Spec.of(_problem(TWO))
    shape = Shape((1, 1, 1, 1), (None,) * 4)
    monkeypatch.setattr(search, "KEEP", 10 ** 6)
    monkeypatch.setattr(search, "COMPLETE", 5000)
    monkeypatch.setattr(dominance, "FIRST", 1000)
    search._PLANS.clear()
    res = search.search_shape(spec, shape, 0)
    plan = search.plan(spec, shape)
    hows = [q.how for q in res.parts]
    assert hows[0] == plan.how and hows[-1][0] == "rest"
    done = hows[-1][1]
    assert sum(plan.levels.counts[:done + 1]) <= 5000 < sum(plan.levels.counts[:done + 2])
    assert not res.complete and res.finished and res.dominated == 0
    ax, rest = search._listed(spec, shape, hows[-1])
    piv, por = settings.settings_at(ax, 4, rest)
    assert not ax.full and ((piv != 0).sum(-1) + (por != 0).sum(-1) > done).all()  # only the levels left
    assert res.screened + sum(q.excluded for q in res.parts) == sum(plan.levels.counts[:done + 1]) + len(rest)


@pytest.mark.slow
def test_four_unit_arms_with_targets_in_reach_are_complete_and_the_same_on_any_engine():
    """Units 4 of H4/L3 (three shapes of 394,827,264 settings each, every family alive: before
    levels, searched on a 2,048-setting coarse grid and reported not complete): complete, by
    dominance, with the same ranking for one process and two; ranking.json says so."""
    from modc.design import run, search
    from modc.design.evaluate import Spec
    from modc.design.write import ranking

    p = _problem(TWO.replace("modules H1, L1", "modules H4, L3"))
    spec = Spec.of(p)
    from modc.design.space import shapes

    assert all(search.plan(spec, s).levels is not None and search.plan(spec, s).total - search.plan(spec, s).excluded
               > search.COMPLETE for s in shapes(p, 4))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        serial = run.design(p, top=2, seed=0)
        with ProcessPoolExecutor(max_workers=2) as pool:
            pooled = run.design(p, top=2, seed=0, executor=pool)
    assert serial.designs and serial.complete and not serial.coarse and serial.dominated > 10 ** 8
    assert [d.chain() for d in serial.designs] == [d.chain() for d in pooled.designs]
    assert (serial.evaluated, serial.excluded, serial.dominated) == (pooled.evaluated, pooled.excluded,
                                                                    pooled.dominated)
    js = ranking([serial])
    assert js["complete"] and js["coarse_shapes"] == [] and js["dominated"] == serial.dominated


def test_rounds_are_decided_only_when_whole_and_in_their_fixed_chain():
    """dominance.decide: the next level while the kept list can be beaten, the dominated levels
    once it cannot, the coarse rest past the budget, nothing while a round is not whole."""
    from modc.design import dominance
    from modc.design.search import Found

    values = tuple(np.array([-1.0, 0.0, 1.0, 2.0]) for _ in range(4))
    lv = dominance.levels_of(values, np.arange(4 ** 4), 1)
    assert lv.counts == (1, 12, 54, 108, 81)
    first = ("levels", 0, 1)
    zero = [Found((0.0,), (0.0,), (), 0.0)] * 3
    length = {first: 13, ("levels", 2, 2): 54, ("levels", 3, 3): 108, ("rest", 2): 7}.__getitem__

    def decide(done, kept, budget=1000):
        return dominance.decide(lv, first, done, kept if callable(kept) else lambda rounds: kept, length, 3, budget)

    assert decide({first: 13}, zero) == (None, 54 + 108 + 81, True, True)
    assert decide({first: 13}, zero[:2]) == (("levels", 2, 2), 0, False, False)
    assert decide({first: 12}, zero) == (None, 0, False, False)  # a unit missing: nothing decided
    later = {first: 13, ("levels", 2, 2): 54}
    assert decide(later, lambda rounds: zero[:len(rounds) + 1]) == (None, 108 + 81, True, True)
    assert decide(later, zero) == (None, 0, False, False)  # the first round closed it: level 2 is not its chain
    assert decide({first: 13, ("levels", 2, 2): 54}, zero[:2], budget=100) == (("rest", 2), 0, False, False)
    assert decide({first: 13, ("levels", 2, 2): 54, ("rest", 2): 7}, [], budget=100) == (None, 0, False, True)
    assert decide({first: 13, ("levels", 3, 3): 108}, zero) == (None, 0, False, False)  # not its chain
