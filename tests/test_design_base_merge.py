"""`base within`: the merged ranking over the grid is the best of every base pose searched alone
(a brute force written here), to the chain, the pose and the numbers; the H/L alternatives of the
designs kept are those their pose's own search checks."""
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


def _brute_force(p, top: int) -> list:
    """Every kept pose searched alone (its base as written there), nearest first, then merged:
    the designs ordered by the ranking (stable: of equal designs the pose searched first), one
    entry per chain, the first `top`."""
    from modc.design import placement, run
    from modc.design.rank import order

    kept, _, _ = placement.poses(p, run.longest_reach(p, p.max_units))
    every = []
    for pose in kept:
        sub = p.model_copy(update={"cell": placement.cell_at(p.cell, pose), "base_grid": None})
        every += run.design(sub, top=top).designs
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
    assert [_row(d) for d in got.designs] == [_row(d) for d in want]
    return got.designs


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
