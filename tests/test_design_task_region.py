"""What makes a region cheap to design for: the screen starts each region point from the
candidate's own solution at the nearest point already reached, and a round of shapes stops at
the shape where the top designs are found (no unsearched shape could rank before them)."""
from __future__ import annotations

import numpy as np
import pytest
from conftest import THREE_TARGETS

from modc.compiler import check_text

# a tray of 3 x 2 points 2 cm apart, every one required (no `rank coverage`)
TRAY = """design tray {
    target above at (0.30, 0, 0.25) m
    region tray box size (0.04, 0.02, 0) m at (0.30, 0, 0.20) m grid 3 x 2 x 1 within 5 mm
    units 3
    modules H1, L1, L3, L4
}
"""


def problem(text: str = TRAY):
    checked = check_text(text, "cell.mod")
    assert checked.ok, [d.message for d in checked.diagnostics]
    return checked.design.problems[0]


def test_region_points_start_from_the_nearest_point_already_reached(monkeypatch):
    from modc.design import reach, space, tasks
    from modc.design.evaluate import Spec, screen_batch
    from modc.design.settings import axes
    from modc.design.settings import range_settings as _settings

    p, _names = tasks.with_points(problem())
    spec = Spec.of(p)
    shape = next(s for s in space.shapes(p, 3) if s.kinds == (1, 1, 3))
    ax = axes(spec, shape)
    pivots, ports = _settings(ax, 3, 0, min(ax.count, 4096))
    calls: list[tuple[str, int, int]] = []
    real = reach.solve

    def counted(g, tg, q0, lo, hi, *a, **kw):
        calls.append((tg.names[0], q0.ndim, g.pre.shape[0]))
        return real(g, tg, q0, lo, hi, *a, **kw)

    monkeypatch.setattr(reach, "solve", counted)
    s = screen_batch(spec, shape, pivots, ports, 0)
    assert s.feasible.any()  # some of these settings serve the whole tray
    first = calls[0][0]
    later = [c for c in calls if c[0] != first]
    assert later and all(c[0] == first for c in calls[:len(calls) - len(later)])
    starts: dict[str, tuple[int, int]] = {}
    for name, ndim, count in later:
        starts.setdefault(name, (ndim, count))
    # every later point: first one run per candidate from its own solution at a point it reached
    assert all(ndim == 3 for ndim, _ in starts.values())
    for j, k in enumerate(np.flatnonzero(s.feasible)):
        assert all(sols and s.reached[k, t] for t, sols in enumerate(s.solutions[j]))


def test_a_round_stops_at_the_shape_where_the_top_designs_are_found(monkeypatch):
    """Shapes are searched lightest first: once the top designs are checked and no shape left
    is lighter, the rest of the round is not searched (it was, to the round's end)."""
    from modc.design import run, search, space

    seen: list = []
    real = search.search_part

    def counted(spec, shape, *a, **kw):
        if shape not in seen:
            seen.append(shape)
        return real(spec, shape, *a, **kw)

    monkeypatch.setattr(search, "search_part", counted)
    p = problem(TRAY.replace("    units 3\n", "    units 3\n    rank modules, mass\n"))
    o = run.design(p, top=1)
    assert len(o.designs) == 1
    best = o.designs[0]
    splits = space.variant_splits(p, 3)
    masses = [run._min_mass(p, s, splits) for s in seen]
    assert masses == sorted(masses)
    # nothing heavier than the design was searched; shapes were left unsearched
    assert max(masses) <= best.mass + 1e-9
    assert len(space.shapes(p, 3)) > len(seen)
    assert o.complete and not o.unfinished


@pytest.mark.slow
def test_the_region_is_served_by_a_planned_design():
    from modc.design import run

    p = problem(TRAY.replace("    units 3\n", "    units 3\n    task serve { visit above, tray }\n"
                             "    rank modules, cycle_time\n"))
    o = run.design(p, top=1)
    assert len(o.designs) == 1
    d = o.designs[0]
    visits = [s.end for s in d.plans[0].counted]
    assert visits == [f"tray[{i},{j},0]" for i in range(3) for j in range(2)]
    assert d.cycle_time > 0 and d.coverage == 1.0


def test_with_margin_ranked_every_shape_as_light_as_the_design_is_searched(monkeypatch):
    """A round stops at a shape only once nothing unsearched can beat the design: with margin
    ranked, a shape as light as the design (even by the last bits of a sum, 1.82 vs
    1.8199999999999998 kg) may still beat it on torque margin, so it is searched."""
    from modc.design import run, search

    seen: set = set()
    real = search.search_part

    def counted(spec, shape, *a, **kw):
        seen.add(shape)
        return real(spec, shape, *a, **kw)

    monkeypatch.setattr(search, "search_part", counted)
    p = problem(THREE_TARGETS.replace("    units 2 to 3\n", "    units 3\n"))
    assert "margin" in p.rank
    o = run.design(p, top=1)
    assert len(o.designs) == 1
    from modc.design.evaluate import Spec

    closest = {t.name: float("inf") for t in p.cell.targets}
    (_n, _splits, shapes), = run._tiers(p, Spec.of(p), 3, closest)  # the shapes within the reach bound
    as_light = {s for m, _, s in shapes if m <= o.designs[0].mass + 1e-6}
    assert len(as_light) > 1 and as_light <= seen
