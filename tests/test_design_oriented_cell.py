"""A design cell with full target orientations (`rpy`): the orientation bounds (bounds.posed)
change what the search costs, never what it returns - the same ranking with them off - and a
task cell no chain serves is searched once, not once per round of more candidates."""
from __future__ import annotations

import math

import numpy as np
import pytest

from modc.compiler import check_text
from modc.kinematics import matrix_rpy


def _poses(kinds, pivots, ports, qs):
    """tool0's poses of one chain of the library (its units' types, twists in degrees) at the joint
    vectors qs (rad): xyz (m) and rpy (deg) per joint vector."""
    from modc.design.batch import forward, geometry

    c = check_text("design d {\n    target a at (0.3, 0, 0.2) m\n}\n", "d.mod")
    lib = c.design.problems[0].cell.library
    types = [lib.units[k] for k in kinds]
    g = geometry(types, np.radians([pivots]), np.radians([ports]), [t.x23 for t in types], (0.0, 0.0, 0.0),
                 (0.0, 0.0, 0.0))
    _, _, T, _ = forward(g, np.asarray(qs, float)[None, :, None, :])
    return [(T[0, k, 0, :3, 3], np.degrees(matrix_rpy(T[0, k, 0, :3, :3]))) for k in range(len(qs))]


def _cell(extra: str = "", bounds: str = "    units 1 to 2\n    modules H1, L3, L4\n") -> str:
    """Two posed targets an H1 - L3 arm reaches (with its own twists), and a third 1 cm beside one."""
    poses = _poses((1, 3), (0.0, 45.0), (0.0, 30.0), [(0.3, -0.8), (1.2, 0.6)])
    lines = [f"    target t{k} at ({x[0]:.6f}, {x[1]:.6f}, {x[2]:.6f}) m rpy ({r[0]:.4f}, {r[1]:.4f}, {r[2]:.4f}) deg "
             "within 15 mm, 12 deg\n" for k, (x, r) in enumerate(poses)]
    return "design posed {\n" + "".join(lines) + bounds + extra + "}\n"


def _problem(text: str):
    checked = check_text(text, "cell.mod")
    assert checked.ok, [d.message for d in checked.diagnostics]
    return checked.design.problems[0]


def _ranking(o) -> list[tuple]:
    return [(d.chain(), round(d.mass, 9)) for d in o.designs]


@pytest.mark.parametrize("rank, space", [
    ("modules, mass", "    units 1 to 2\n    modules H1, L3, L4\n"),
    ("mass, margin", "    units 1 to 2\n    modules H1, L3, L4\n"),
    pytest.param("modules, mass", "    units 1 to 3\n    modules H1, L1, L3\n", marks=pytest.mark.slow),
])
def test_the_orientation_bounds_change_no_ranking(monkeypatch, rank, space):
    from modc.design import bounds, prefix, run, search

    monkeypatch.setattr(prefix, "POSED", False)  # the per-setting bounds, not the families' (their own test)
    calls = []
    real = bounds.posed

    def counted(f, tg, every=False):
        out = real(f, tg, every)
        calls.append((out.size, int((~out).sum())))
        return out

    monkeypatch.setattr(bounds, "posed", counted)
    p = _problem(_cell(f"    rank {rank}\n", space))
    on = run.design(p, top=5)
    assert on.designs and calls and sum(c[1] for c in calls) > 0  # the bound ran and excluded settings
    monkeypatch.setattr(search, "ORIENTED", False)
    off = run.design(p, top=5)
    assert _ranking(on) == _ranking(off)
    assert on.excluded > off.excluded  # the IK ran on fewer settings


def test_a_posed_region_no_chain_serves_is_found_out_and_searched_once(monkeypatch):
    from modc.design import run, sweep

    (x, r), _ = _poses((1, 3), (0.0, 45.0), (0.0, 30.0), [(0.3, -0.8), (1.2, 0.6)])
    text = ("design tray {\n"
            f"    target a at ({x[0]:.6f}, {x[1]:.6f}, {x[2]:.6f}) m\n"
            f"    region tray box size (0.06, 0.04, 0) m at ({x[0]:.6f}, {x[1]:.6f}, {x[2]:.6f}) m grid 3 x 2 x 1 "
            f"rpy ({r[0] + 60:.4f}, {r[1]:.4f}, {r[2]:.4f}) deg within 2 mm, 1 deg\n"
            "    task serve { visit a, tray }\n    units 1 to 2\n    modules H1, L3, L4\n"
            "    rank cycle_time, modules\n}\n")
    searches = []
    real = sweep._search

    def counted(*a, **kw):
        searches.append(1)
        return real(*a, **kw)

    monkeypatch.setattr(run, "_search", counted)
    o = run.design(_problem(text), top=2)
    assert not o.designs and not o.stopped
    assert len(searches) == 1  # fewer designs than asked: every shape was searched, a second search finds the same
    assert math.isfinite(o.seconds)
