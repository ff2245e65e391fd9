"""`base within`, the grid search (modc.design.grid): only a shifted base works; two poses that
serve a setting equally well tie, and the nearer pose in the grid's order (then the grid's own
order) wins, the same with one process, a process pool and Dask."""
from __future__ import annotations

import warnings
from concurrent.futures import ProcessPoolExecutor

import pytest

from modc.compiler import check_text

# target a 0.35 m straight above x = 0.3 m, the box's centre: no 2-unit H1/L3 arm reaches it from
# there; from x = 0.2 m or x = 0.4 m one does
SHIFTED = """design tied {
    target a at (0.3, 0, 0.35) m
    units 2
    modules H1, L3
    base within box size (0.2, 0, 0) m at (0.3, 0, 0) m step 100 mm
}
"""


def _problem(text: str):
    checked = check_text(text, "cell.mod")
    assert checked.ok, [d.message for d in checked.diagnostics]
    return checked.design.problems[0]


def _rows(out) -> list:
    return [(d.chain(), tuple(round(x, 9) for x in d.verified.robot.base.xyz), round(d.mass, 9), round(d.margin, 9))
            for d in out.designs]


def test_only_a_shifted_base_works():
    from modc.design import run

    p = _problem(SHIFTED)
    centre = _problem(SHIFTED.replace("    base within box size (0.2, 0, 0) m at (0.3, 0, 0) m step 100 mm\n",
                                   "    base at (0.3, 0, 0) m\n"))
    assert not run.design(centre, top=1).designs
    o = run.design(p, top=1)
    assert len(o.designs) == 1 and o.designs[0].modules == 2
    assert o.designs[0].verified.robot.base.xyz[0] != pytest.approx(0.3)


# a two-unit arm reaches a from the poses at y = -0.05 m and y = +0.05 m equally (a turn about the
# target's vertical maps one onto the other): the tie goes to the first in the grid's order
MIRRORED = """design mirrored {
    target a at (0.3, 0, 0.35) m
    units 2
    base within box size (0.2, 0.1, 0) m at (0.1, 0, 0) m step 100 mm
}
"""


def test_two_poses_that_tie_give_the_first_in_the_grids_order_on_every_engine():
    from modc.design import placement, run, search
    from modc.design.evaluate import Spec

    p = _problem(MIRRORED)
    kept, _, _ = placement.poses(p, run.longest_reach(p, 2))
    assert [k.xyz[:2] for k in kept[:2]] == [pytest.approx((0.2, -0.05)), pytest.approx((0.2, 0.05))]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        serial = run.design(p, top=2, seed=3)
        with ProcessPoolExecutor(max_workers=2) as pool:
            pooled = run.design(p, top=2, seed=3, executor=pool)
        distributed = pytest.importorskip("distributed")
        with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                      dashboard_address=None) as cluster, distributed.Client(cluster) as client:
            dasked = run.design(p, top=2, seed=3, executor=client.get_executor())
    assert _rows(serial) == _rows(pooled) == _rows(dasked)
    assert serial.evaluated == pooled.evaluated == dasked.evaluated > 0
    best = serial.designs[0]
    assert best.verified.robot.base.xyz[:2] == pytest.approx((0.2, -0.05))
    # the tie is real: the mirrored pose serves the same setting as deep inside the tolerance
    c = best.candidate
    share = []
    for pose in kept[:2]:
        sub = p.model_copy(update={"cell": placement.cell_at(p.cell, pose), "base_grid": None})
        share.append(next(round(f.worst, 2) for f in search.search_shape(Spec.of(sub), c.shape, 3).found
                          if (f.pivots, f.ports) == (c.pivots, c.ports)))
    assert share[0] == share[1]


def test_a_spent_budget_stops_the_grid_search_with_what_it_left():
    import time

    from modc.design import run

    o = run.design(_problem(MIRRORED), top=1, deadline=time.time() - 1)
    assert o.stopped == "time budget" and not o.complete and o.unfinished
    assert not o.designs


def test_a_target_walled_off_at_every_pose_needs_no_ik(monkeypatch):
    """A target deep inside an obstacle (bounds.blocked) rules a pose out before any IK, as it
    rules out one pose's search."""
    from modc.design import grid, run

    block = "    box block size (0.1, 0.1, 0.1) m at (0.3, 0, 0.35) m\n"
    p = _problem(SHIFTED.replace("    units 2\n", block + "    units 2\n"))
    calls = []
    real = grid.search_chunk

    def counted(*a):
        calls.append(a)
        return real(*a)

    monkeypatch.setattr(grid, "search_chunk", counted)
    o = run.design(p, top=1)
    assert not o.designs and o.bases_searched == 3 and not calls
    assert "block" in o.why_none()
