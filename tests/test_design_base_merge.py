"""`base within`: the grid search (modc.design.grid) against a brute force written here from
every base pose searched alone. A shape's candidates are (setting, pose) pairs: its kept list is
the KEEP best settings, each at its best pose (least search.order_key, then the nearest pose),
the merge of every pose's own kept list; its design per H/L split is the first of them (up to
TRIES) that passes the exact check at its pose; the designs are ranked. The H/L alternatives of
the designs kept are those their pose's own search checks."""
from __future__ import annotations

import pytest

from modc.compiler import check_text

# two-unit arms of equal mass reach a from several poses, with different torque margins: the
# margin decides across poses, and the mirrored poses (y = +-0.05 m) tie on every objective
ONE = """design one {
    target a at (0.3, 0, 0.35) m
    units 2
    base within box size (0.2, 0.1, 0) m at (0.1, 0, 0) m step 100 mm
}
"""
# the two best designs come from two different poses
TWO = ONE.replace("    target a at (0.3, 0, 0.35) m\n",
                  "    target a at (0.25, 0.05, 0.3) m\n    target b at (0.3, -0.05, 0.3) m\n")
# three units: the design kept has an H/L swap that passes too (its alternative), checked at its
# own pose after the merge; the pose farther from a ranks first on margin
THREE = """design three {
    target a at (0.3, 0, 0.45) m
    units 3
    modules H1, H2, L2, L3
    base within box size (0.1, 0, 0) m at (0.05, 0, 0) m step 100 mm
}
"""


def _problem(text: str):
    checked = check_text(text, "cell.mod")
    assert checked.ok, [d.message for d in checked.diagnostics]
    return checked.design.problems[0]


def _row(d) -> tuple:
    return (d.chain(), tuple(round(x, 9) for x in d.verified.robot.base.xyz), d.modules, round(d.mass, 9),
            round(d.margin, 9), tuple((a.chain(), round(a.mass, 9), round(a.margin, 9)) for a in d.alternatives))


def _cells(p):
    from modc.design import placement, run

    kept, _, _ = placement.poses(p, run.longest_reach(p, p.max_units))
    return [p.model_copy(update={"cell": placement.cell_at(p.cell, pose), "base_grid": None}) for pose in kept]


def _merged(p, subs, shape) -> list:
    """The shape searched alone at every pose, the kept lists merged: (Found, pose index)."""
    from modc.design import search
    from modc.design.evaluate import Spec

    entries = []
    for i, sub in enumerate(subs):
        entries += [(search.order_key(f), i, f) for f in search.search_shape(Spec.of(sub), shape, 0).found]
    best: dict = {}
    for k, i, f in sorted(entries, key=lambda e: e[:2]):
        best.setdefault((f.pivots, f.ports), (k, i, f))
    return [(f, i) for _, i, f in sorted(best.values(), key=lambda e: e[:2])[:search.KEEP]]


def _brute_force(p, top: int) -> list:
    from modc.design import space
    from modc.design.evaluate import Candidate, verify
    from modc.design.rank import Design, order
    from modc.design.verify_order import TRIES

    subs = _cells(p)
    every = []
    for n in range(p.min_units, p.max_units + 1):
        for shape in space.shapes(p, n):
            merged = _merged(p, subs, shape)
            for variants in space.variant_splits(p, n):
                if not all(space.allowed(p, v, k) for v, k in zip(variants, shape.kinds, strict=True)):
                    continue
                for f, i in merged[:TRIES]:
                    v = verify(subs[i], Candidate(shape, variants, f.pivots, f.ports, f.solutions))
                    if not isinstance(v, str):
                        every.append(Design(Candidate(shape, variants, f.pivots, f.ports, f.solutions), v))
                        break
    seen, out = set(), []
    for d in order(every, p.rank):
        if d.chain() not in seen:
            seen.add(d.chain())
            out.append(d)
    return out[:top]


def _same_as_brute_force(text: str, top: int) -> list:
    from modc.design import run

    p = _problem(text)
    got = run.design(p, top=top)
    want = _brute_force(p, top)
    assert [_row(d)[:5] for d in got.designs] == [_row(d)[:5] for d in want]
    return got.designs


def test_each_shape_keeps_the_best_settings_of_every_pose_searched_alone():
    from modc.design import grid, space
    from modc.design.evaluate import Spec

    for text in (ONE, THREE):
        p = _problem(text)
        subs = _cells(p)
        shapes = space.shapes(p, p.max_units)
        results = grid.search_shapes([Spec.of(s) for s in subs], shapes, 0, None, None, lambda: None)
        some = False
        for shape, r in zip(shapes, results, strict=True):
            want = [(f.pivots, f.ports, i, round(f.worst, 2)) for f, i in _merged(p, subs, shape)]
            assert [(f.pivots, f.ports, f.pose, round(f.worst, 2)) for f in r.found] == want, shape.label()
            assert r.complete and r.finished
            some |= bool(want)
        assert some


def test_the_grid_ranks_as_every_pose_searched_alone_and_merged():
    designs = _same_as_brute_force(ONE, 2)
    assert len(designs) == 2 and len({round(d.mass, 9) for d in designs}) == 1  # equal mass: the margin ranks


def test_the_designs_kept_have_the_alternatives_their_own_pose_checks():
    designs = _same_as_brute_force(THREE, 1)
    assert designs[0].alternatives and designs[0].verified.robot.base.xyz[0] == pytest.approx(0.1)
    assert all(a.verified.robot.base == designs[0].verified.robot.base for a in designs[0].alternatives)


@pytest.mark.slow
def test_the_best_designs_of_two_poses_merge_as_each_pose_alone():
    designs = _same_as_brute_force(TWO, 2)
    assert len({d.verified.robot.base.xyz for d in designs}) == 2


def test_the_grid_search_shows_progress_within_a_group_of_shapes():
    """A group of shapes of equal least mass is searched at every pose before its results come
    in (minutes in a large cell): the display's count of settings moves while it runs, not only
    when the group is done, and it ends at the outcome's count."""
    from modc.design import run

    seen: list = []
    out = run.design(_problem(THREE), top=1, seed=0, progress=lambda st, force=False: seen.append(st))
    during = [st.screened for st in seen if st.shapes_done == 0]
    assert during and max(during) > 0  # before the first group of shapes came back
    counts = [st.screened for st in seen]
    assert counts == sorted(counts) and counts[-1] == out.evaluated
