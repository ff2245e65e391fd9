"""`rank coverage` in `modc design`: the share of region points reached ranks designs that serve
only part of a region; without it every point of every region is required."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from conftest import modc_design

from modc.compiler import check_file, check_text

ROOT = Path(__file__).resolve().parent.parent

# the region's far point (0.9 m out) is beyond every 3-unit H1/L3 arm (reach bound 0.88 m)
PARTLY = """design partly {
    payload 100 g
    target a at (0.30, -0.10, 0.25) m
    region row box size (0.6, 0, 0) m at (0.6, 0.1, 0.25) m grid 3 x 1 x 1
    units 3
    modules H1, L3
    task serve { visit a, row }
    rank coverage, cycle_time
}
"""


def problem(text: str = PARTLY):
    checked = check_text(text, "cell.mod")
    assert checked.ok, [d.message for d in checked.diagnostics]
    return checked.design.problems[0]


def test_served_drops_only_the_points_not_reached():
    from modc.design import coverage

    cell = problem().cell
    served = coverage.served(cell, {"row[0,0,0]", "row[1,0,0]"})
    assert served.tasks[0].visits == ("a", "row[0,0,0]", "row[1,0,0]")
    assert served.regions == cell.regions and served.targets == cell.targets


def test_coverage_ranks_larger_shares_first():
    from modc.design.rank import TASK, static
    from modc.objectives import REGISTRY

    class D:
        def __init__(self, c):
            self.coverage = c

    key = REGISTRY["coverage"].key
    assert key(D(1.0)) < key(D(2 / 3)) < key(D(0.1))
    assert "coverage" in TASK and static(("coverage", "modules")) == ("modules",)


def test_without_coverage_every_region_point_is_required():
    from modc.design import run

    o = run.design(problem(PARTLY.replace("rank coverage, cycle_time", "rank modules")), top=1)
    assert not o.designs
    assert "row[2,0,0]" in o.why_none() and "row_2_0_0" not in o.why_none()


@pytest.mark.slow
def test_rank_coverage_ranks_a_design_that_serves_part_of_the_region(tmp_path):
    from modc.kinematics import Chain
    from modc.plan.collision import CollisionChecker

    r = modc_design(tmp_path, PARTLY, "--top", "2")
    assert r.returncode == 0, r.stderr
    ranking = json.loads((tmp_path / "out" / "ranking.json").read_text())
    shares = [d["coverage"] for d in ranking["designs"]]
    assert shares == sorted(shares, reverse=True) and 0 < shares[0] < 1
    for d in ranking["designs"]:
        robot = check_file(tmp_path / "out" / d["file"]).design.robots[0]
        visits = robot.tasks[0].visits
        assert "row[2,0,0]" not in visits and visits[:1] == ("a",)
        points = [v for v in visits if v.startswith("row[")]
        assert d["coverage"] == pytest.approx(len(points) / 3, abs=1e-6)
        # each point the task visits is reached where its trajectory says, re-measured here
        traj = json.loads((tmp_path / "out" / d["traj"]).read_text())
        chain, checker = Chain(robot), CollisionChecker(robot)
        for seg in traj["segments"]:
            if seg["to"] in points:
                end = seg["t_start_s"] + seg["duration_s"]
                q = np.asarray(min(traj["points"], key=lambda p, end=end: abs(p["t"] - end))["q"])
                tgt = robot.task_target(seg["to"])
                assert np.linalg.norm(chain.T_base_tool(q)[:3, 3] - tgt.xyz) <= tgt.position_tolerance + 1e-6
                assert checker.contacts(q, 0.0) == []


PAIR = """design cov {
    tool at (0.05, 0, 0) m
    box table size (0.16, 0.30, 0.02) m at (0.32, 0, -0.02) m
    target rest at (0.22, 0.18, 0.25) m
    region pair box size (0.16, 0, 0) m at (0.38, 0, 0.06) m grid 2 x 1 x 1 pointing (0, 0, -1) within 5 mm, 5 deg
    task pick { visit rest, pair, rest }
    units 3
    modules H1, L3, L4
    rank coverage, modules
}
"""


@pytest.mark.slow
def test_coverage_finds_an_arm_serving_some_points_when_none_serves_all(tmp_path):
    """No arm of the bounds serves both points pointing down; the arms that reach `rest` by the
    simplest twists serve neither. The candidates come from the points one at a time, so a design
    serving one of the two is found (it was "no design": every candidate reached no point)."""
    r = modc_design(tmp_path, PAIR, "--top", "1")
    assert r.returncode == 0, r.stderr
    d = json.loads((tmp_path / "out" / "ranking.json").read_text())["designs"][0]
    assert d["coverage"] == 0.5
    robot = check_file(tmp_path / "out" / d["file"]).design.robots[0]
    visits = next(t for t in robot.tasks if t.name == "pick").visits
    served = [v for v in visits if v.startswith("pair[")]
    assert len(served) == 1  # the point it reaches, and only that one, is visited


def test_coverage_searches_at_most_a_few_points_one_at_a_time():
    """The point-by-point candidate search of `rank coverage` runs at most POINT_SEARCHES static
    searches, spread over the region (a 100 x 100 region would be 10,000 searches)."""
    from modc.design import tasks
    from modc.design.run import Outcome

    text = PAIR.replace("grid 2 x 1 x 1", "grid 100 x 100 x 1").replace("(0.16, 0, 0) m", "(0.16, 0.16, 0) m")
    c = check_text(text, "cell.mod")
    assert c.ok, [d.message for d in c.diagnostics]
    problem = c.design.resolved_problems()[0]
    asked: list[str] = []

    def search(screen):
        asked.extend(t.name for t in screen.cell.targets if t.name.startswith("pair_"))
        return Outcome(screen, [])

    out = tasks.by_points(problem, search, 5, seed=0)
    assert out is not None and out.designs == []
    assert 1 < len(asked) <= tasks.POINT_SEARCHES and len(set(asked)) == len(asked)
    assert asked[0] == "pair_0_0_0" and asked[-1] > "pair_90"  # from the first point to the far end


def test_with_coverage_a_straight_paths_region_end_stays_required():
    """A path must reach its ends (coverage.missing_ends): with `rank coverage` the static search
    screens a region point a path ends at, also when it searches the points one at a time (it
    returned arms that missed the end, each then refused by its planning: "no design" after
    planning them all, where the search can tell at once)."""
    from modc.design import tasks

    text = PAIR.replace("    task pick", "    path drop from rest to pair[1,0,0] straight\n    task pick")
    p = problem(text)
    screen, names = tasks.with_points(p)
    assert [names[t.name] for t in screen.cell.targets if t.name in names and "[" in names[t.name]] == ["pair[1,0,0]"]
    one, names = tasks.with_points(p, only="pair[0,0,0]")
    assert sorted(v for v in names.values() if "[" in v) == ["pair[0,0,0]", "pair[1,0,0]"]
    every, names = tasks.with_points(p, every=True)
    assert sorted(v for v in names.values() if "[" in v) == ["pair[0,0,0]", "pair[1,0,0]"]
    # without a path the points stay optional
    _, names = tasks.with_points(problem())
    assert not [v for v in names.values() if "[" in v]


def test_coverage_starts_the_planners_ik_at_the_joint_values_the_search_verified(monkeypatch):
    """A point the search reached (and verified) is measured from its own joint values first: the
    planner's seeds around home can miss a pose its seeds found (a tool pointing down)."""
    import modc.plan as plan
    from modc.design import coverage

    arm = PAIR.replace("design cov {", "robot cov {\n    chain H1 - L3 - L4").replace("    units 3\n", "")
    arm = arm.replace("    modules H1, L3, L4\n", "").replace("    rank coverage, modules\n", "")
    c = check_text(arm, "arm.mod")
    assert c.ok, [d.message for d in c.diagnostics]
    robot = c.design.resolved_robots()[0]
    starts: dict[str, np.ndarray] = {}

    def clear(robot, checker, target, start, seed):
        starts[target.name] = np.asarray(start, float)
        return None

    monkeypatch.setattr(plan, "clear_solution", clear)
    q = [0.1, 0.2, 0.3]
    assert coverage.reached(robot, 0, known={"pair[1,0,0]": q}) == (set(), 2)
    assert np.allclose(starts["pair[1,0,0]"], q) and not np.allclose(starts["pair[0,0,0]"], q)


# the region lies across the arm's front, a wall behind it: the arms that reach `home` by the
# simplest twists serve none of its points, so the search must look for those that do
BEHIND_A_WALL = """design walled {
    payload 100 g
    box wall size (0.02, 0.6, 0.5) m at (0.45, 0, 0.25) m
    target home at (0.25, 0.0, 0.30) m
    region far box size (0.3, 0, 0) m at (0.3, 0.0, 0.2) m turned (0, 0, 90) deg grid 4 x 1 x 1
    task serve { visit home, far, home }
    base within box size (0.1, 0.1, 0) m at (0, 0, 0) m step 100 mm yaw 0 to 180 deg step 90 deg
    units 3
    modules H1, L3
    rank coverage, cycle_time
}
"""


@pytest.mark.slow
def test_coverage_with_a_base_grid_searches_for_arms_that_serve_the_region():
    """`rank coverage` with `base within` planned only the arms found for the targets alone (it
    skipped the search for arms serving the region's points): "no design", every candidate
    reaching no point. Now the grid is searched for them as one pose is."""
    from modc.design import run

    o = run.design(problem(BEHIND_A_WALL), top=1, seed=0)
    assert o.designs, o.why_none()
    d = o.designs[0]
    assert d.coverage > 0 and d.plans and d.plans[0].task == "serve"
    robot = d.verified.robot
    served = [v for v in next(t for t in robot.tasks if t.name == "serve").visits if v.startswith("far[")]
    assert len(served) == round(d.coverage * 4) and o.bases_searched > 1


# every point of the tray lies 3 m out: beyond the reach of any arm of 2 to 3 units
FAR = """design far {
    target a at (0.30, 0.10, 0.25) m
    region tray box size (0.10, 0.10, 0) m at (3.0, 0, 0.2) m grid 2 x 2 x 1
    task serve { visit a, tray }
    units 2 to 3
    rank coverage, cycle_time
}
"""


def test_a_region_beyond_every_arm_is_told_at_once():
    """`rank coverage` when no point of any region is within reach of the longest arm: no design,
    said of the region (not of the first arm planned in vain), before any search."""
    from modc.design import run

    out = run.design(problem(FAR), top=1, seed=0)
    assert not out.designs and out.evaluated == 0 and set(out.regions_beyond) == {"tray"}
    assert 1.0 < out.regions_beyond["tray"] < 3.0
    why = out.why_none()
    assert "every point of region 'tray' lies beyond the reach of the longest arm" in why and "m at least" in why


def test_a_region_is_beyond_only_when_no_base_pose_brings_it_in_reach():
    from modc.design import run

    near = FAR.replace("at (3.0, 0, 0.2) m", "at (1.2, 0, 0.2) m")
    assert set(run.regions_beyond(problem(near), 3)) == {"tray"}
    moved = near.replace("    units 2 to 3\n", "    units 2 to 3\n"
                         "    base within box size (1.0, 0, 0) m at (0.5, 0, 0) m step 100 mm\n")
    assert run.regions_beyond(problem(moved), 3) == {}  # from x = 1.0 m the tray is 0.2 m away
    assert run.regions_beyond(problem(near.replace("rank coverage, cycle_time", "rank cycle_time")), 3) == {}
