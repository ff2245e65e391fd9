"""`modc design` with tasks: the cell's tasks planned and timed for the designs the static search
returns, `rank … cycle_time` / `energy`, the trajectory and task keys written."""
from __future__ import annotations

import json
import subprocess
from pathlib import Path

import pytest
from conftest import SMALL_CELL, modc_design

from modc.compiler import check_file, check_text

ROOT = Path(__file__).resolve().parent.parent

# two targets on either side of a post: the motion between them is planned around it
TASKED = SMALL_CELL.replace("    modules H1, L3\n", "    modules H1, L3\n    task serve { visit a, b }\n"
                            "    rank modules, cycle_time\n")


def problem(text: str = TASKED):
    checked = check_text(text, "cell.mod")
    assert checked.ok, [d.message for d in checked.diagnostics]
    return checked.design.problems[0]


def _design(tmp_path, text: str, *args: str) -> subprocess.CompletedProcess:
    return modc_design(tmp_path, text, *args)


@pytest.mark.slow
def test_rank_cycle_time_plans_every_design_and_ranks_by_it():
    """Was a KeyError in rank.key: the designs are now planned and ordered by modules, then cycle time."""
    from modc.design import run

    p = problem()
    o = run.design(p, top=2, seed=0)
    assert len(o.designs) == 2
    for d in o.designs:
        assert [pl.task for pl in d.plans] == ["serve"]
        assert d.cycle_time == pytest.approx(sum(s.duration for s in d.plans[0].counted)) and d.cycle_time > 0
        assert d.energy >= 0
    keys = [(d.modules, d.cycle_time) for d in o.designs]
    assert keys == sorted(keys)


@pytest.mark.slow
def test_a_design_whose_task_cannot_be_planned_is_rejected(monkeypatch):
    from modc.design import run
    from modc.plan import task
    from modc.plan.errors import PlanError

    real = task.plan_task_robot
    refused: list[str] = []

    def fails_for_the_first(robot, name, **kw):
        chain = "-".join(u.name for u in robot.units)
        if not refused or refused[0] == chain:  # the first design planned cannot do its task
            refused.append(chain)
            raise PlanError([], {})
        return real(robot, name, **kw)

    monkeypatch.setattr(task, "plan_task_robot", fails_for_the_first)
    o = run.design(problem(), top=1, seed=0)
    assert refused and all("-".join(u.name for u in d.verified.robot.units) != refused[0] for d in o.designs)
    assert any(r.startswith(refused[0] + ": task 'serve' cannot be planned") for r in o.rejections)


@pytest.mark.slow
def test_when_every_first_candidate_fails_its_task_the_search_goes_on(monkeypatch):
    """The static search stops once `top` designs rank first and returns a few candidates to plan;
    when every one of them fails its task, modc design searches on (asking for more designs)
    instead of answering "no design", and plans each arm once."""
    from modc.design import run
    from modc.plan import task
    from modc.plan.errors import PlanError

    cell = problem(TASKED.replace("    modules H1, L3\n", "    modules H1, L3, L4\n"))
    real_search, real_plan = run._search, task.plan_task_robot
    asked: list[int | None] = []

    def search(*a, **kw):  # the first round stops early with three candidates, as a larger cell's would
        asked.append(kw.get("enough"))
        out = real_search(*a, **kw)
        if len(asked) == 1:
            out.designs = out.designs[:3]
        return out

    planned: list[tuple] = []

    def plan(robot, name, **kw):  # the first round's arms cannot do their task
        arm = tuple((u.name, round(u.pivot, 6), round(u.port, 6), u.link) for u in robot.units)
        planned.append(arm)
        if len(set(planned)) <= 3:
            raise PlanError([], {})
        return real_plan(robot, name, **kw)

    monkeypatch.setattr(run, "_search", search)
    monkeypatch.setattr(task, "plan_task_robot", plan)
    o = run.design(cell, top=1, seed=0)
    assert asked[0] == 1 and len(asked) == 2 and asked[1] > 1  # searched on, for more designs
    assert len(o.designs) == 1 and len(set(planned)) > 3  # arms beyond the first round planned
    assert len(planned) == len(set(planned))  # none planned twice
    assert sum("cannot be planned" in r for r in o.rejections) == 3


@pytest.mark.slow
def test_modc_design_writes_the_timed_task(tmp_path):
    from modc import trajectory

    r = _design(tmp_path, TASKED, "--top", "1")
    assert r.returncode == 0, r.stderr
    assert "cycle time" in r.stderr
    out = tmp_path / "out"
    ranking = json.loads((out / "ranking.json").read_text())
    d = ranking["designs"][0]
    assert d["traj"] == "small_1.traj.json" and d["traj_task"] == "serve" and d["coverage"] == 1.0
    assert d["cycle_time_s"] > 0 and d["energy_j"] >= 0
    assert d["base"] == {"xyz_m": [0.0, 0.0, 0.0], "rpy_deg": [0.0, 0.0, 0.0]}
    assert d["cycle_time_s"] == pytest.approx(sum(t["cycle_time_s"] for t in d["tasks"]), abs=1e-5)
    traj, errors = trajectory.load(out / d["traj"])
    assert traj is not None and not errors
    robot_file = check_file(out / d["file"])
    assert robot_file.ok
    robot = robot_file.design.robots[0]
    assert [t.name for t in robot.tasks] == ["serve"]  # the written robot keeps the cell's task
    assert trajectory.validate_for(traj, robot) == []
    for row in traj.q:  # within the joint limits, checked here directly too
        for i, v in enumerate(row, start=1):
            lo, hi = robot.joint_range(i)
            assert lo - 1e-9 <= v <= hi + 1e-9
    assert "<th>cycle time (s)</th>" in (out / "report.html").read_text()
    # the segments after the approach add up to the cycle time
    plan = json.loads((out / d["traj"]).read_text())
    assert plan["task"] == "serve"
    assert sum(s["duration_s"] for s in plan["segments"] if s["kind"] != "approach") == \
        pytest.approx(d["cycle_time_s"], abs=1e-5)


def test_a_reference_arm_that_passes_is_planned_timed_and_written(tmp_path):
    """`compare with chain …` on a cell with a task: the reference is planned and timed by the
    designs' own code, and written beside them so that `modc view` and `modc plan` can show it."""
    from modc import trajectory
    from modc.view.ranking import Ranking

    text = TASKED.replace("    rank modules, cycle_time\n", "    rank modules, cycle_time\n"
                          "    compare with chain H1 - H1(pivot=-45deg) - L3(pivot=-15deg)\n")
    r = _design(tmp_path, text, "--top", "1")
    assert r.returncode == 0, r.stderr
    out = tmp_path / "out"
    ranking = json.loads((out / "ranking.json").read_text())
    ref = ranking["reference"]["small"]
    assert ref["feasible"] and ref["fails"] == []
    assert ref["file"] == "small_reference.mod" and ref["traj"] == "small_reference.traj.json"
    assert ref["cycle_time_s"] > 0 and ref["cycle_time_s"] == pytest.approx(
        sum(s["duration_s"] for s in ref["tasks"][0]["segments"] if s["kind"] != "approach"), abs=1e-5)
    checked = check_file(out / ref["file"])
    assert checked.ok
    robot = checked.design.robots[0]
    assert [u.name for u in robot.units] == ["H1", "H1", "L3"] and [t.name for t in robot.tasks] == ["serve"]
    traj, errors = trajectory.load(out / ref["traj"])
    assert traj is not None and not errors and trajectory.validate_for(traj, robot) == []
    html = (out / "report.html").read_text()
    row = html[html.index('<td>reference</td>'):]
    assert f"{ref['cycle_time_s']:.3f} s" in row[:row.index("</tr>")]
    assert "by cycle time" in html  # rank 1 against the reference, told on the ranked objectives
    view = Ranking(out / "ranking.json")  # the viewer lists it after the designs
    assert view.designs[-1]["rank"] is None and view.file(len(view.designs) - 1) == out / "small_reference.mod"
    assert "reference" in view.choice(len(view.designs) - 1)


# two targets on either side of the base: every arm that stands at both swings around between
# them, none keeps tool0 on the straight segment through the base's column
UNFOLLOWABLE = """design badpath {
    payload 50 g
    target a at (0.30, 0.0, 0.20) m
    target b at (-0.30, 0.0, 0.20) m
    path seam from a to b straight
    units 2 to 3
    modules H1, L3
    rank cycle_time
}
"""


@pytest.mark.slow
def test_no_design_for_a_path_no_arm_can_follow_points_at_the_path(tmp_path):
    """Every chain reaching both targets fails the straight path: the diagnostic points at the
    `path` line, not at the design's name, and says so."""
    r = _design(tmp_path, UNFOLLOWABLE)
    assert r.returncode == 1, r.stderr
    assert "cell.mod:5:5: error[no-design]" in r.stderr, r.stderr
    assert "none can be planned on path 'seam'" in r.stderr
    assert "path 'seam' cannot be planned" in r.stderr


@pytest.mark.slow
def test_coverage_measurement_stops_at_the_budget():
    """A design's coverage is an IK run per region point (10,000 in a large region): the time
    budget and Ctrl-C are honoured between points, and the planning step stops with them."""
    from dataclasses import replace

    from modc.design import coverage, run, tasks
    from modc.design.run import Outcome

    covering = problem(TASKED.replace("    task serve { visit a, b }\n",
                                      "    region tray box size (0.1, 0.1, 0) m at (0.3, 0, 0.2) m grid 10 x 10 x 1\n"
                                      "    task serve { visit a, tray }\n").replace("rank modules, cycle_time",
                                                                                "rank coverage"))
    found = run.design(problem(), top=1, seed=0)
    assert found.designs, found.why_none()
    d = found.designs[0]
    robot = d.verified.robot.model_copy(update={"regions": covering.cell.regions})
    asked: list[int] = []

    def stopping(after: int):
        def stop(*_deadline):
            asked.append(1)
            return "time budget" if len(asked) > after else None
        return stop

    assert coverage.reached(robot, 0, stopping(3)) is None and len(asked) == 4  # stopped at the 4th point
    got = coverage.reached(robot, 0, lambda: None)
    assert got is not None and got[1] == 100
    asked.clear()
    o = Outcome(covering, [replace(d, verified=replace(d.verified, robot=robot))])
    tasks.plan_all(o, 1, 0, None, stopping(5))
    assert o.stopped == "time budget" and o.designs == [] and not o.rejections
    assert len(asked) == 7  # once before the design, five times measuring it (4 points tried), once for why
    assert o.not_planned == [d.chain()] and o.complete is False  # said: found, not planned, maybe not the best
    assert "before planning and timing the 1 design" in o.why_none() and "touching" not in o.why_none()


# both ends are reached by every 3-unit arm's simplest twists, folded so that no motion keeps
# tool0 on the line between them; the arms that follow it have other twists
SEAM = """design seam {
    payload 50 g
    box ground size (0.8, 0.8, 0.02) m at (0, 0, -0.02) m
    target p at (0.18, 0.22, 0.12) m
    target q at (0.18, -0.22, 0.12) m
    path weld from p to q straight
    task go { visit p, q }
    units 3
    modules H1, L3, L4
    rank cycle_time
}
"""


def test_a_straight_path_is_screened_along_its_way():
    """Points inside a straight path are screened as targets (an arm on the segment reaches each),
    with the tighter tolerance of its ends, position only; the designs' robots keep the cell's
    own targets and the figures name the points after the path."""
    from modc.design import tasks

    p = problem(SEAM)
    screen, names = tasks.with_points(p)
    inside = [t for t in screen.cell.targets if t.name in names]
    assert [names[t.name] for t in inside] == ["weld at 1/4", "weld at 2/4", "weld at 3/4"]
    assert [round(t.xyz[1], 9) for t in inside] == [0.11, 0.0, -0.11]
    assert all(t.rpy is None and t.pointing is None and t.position_tolerance == 0.005 for t in inside)


@pytest.mark.slow
def test_a_path_the_simplest_twists_cannot_follow_gets_a_design(tmp_path):
    """It was "no design" (every shape's representative stood at both ends folded the wrong way):
    the designs returned follow the path, planned and timed."""
    r = _design(tmp_path, SEAM, "--top", "1")
    assert r.returncode == 0, r.stderr
    d = json.loads((tmp_path / "out" / "ranking.json").read_text())["designs"][0]
    assert d["cycle_time_s"] > 0 and [t["task"] for t in d["tasks"]] == ["go", "weld"]
    robot = check_file(tmp_path / "out" / d["file"]).design.robots[0]
    assert [t.name for t in robot.targets] == ["p", "q"]


@pytest.mark.slow
def test_no_design_for_region_points_out_of_reach_points_at_the_region(tmp_path):
    """Only points of one region are out of every arm's reach: the diagnostic points at that
    region's line, names the points and says by how much."""
    text = """design far {
    target a at (0.3, 0, 0.2) m
    region r box size (1.6, 0, 0) m at (0.9, 0, 0.2) m grid 3 x 1 x 1
    task t { visit a, r }
    units 3
    modules H1, L3
}
"""
    r = _design(tmp_path, text)
    assert r.returncode == 1, r.stderr
    assert "cell.mod:3:5: error[no-design]" in r.stderr and "target 'r[2,0,0]': no design gets closer than" in r.stderr


@pytest.mark.slow
def test_a_static_search_cut_short_by_the_budget_still_hands_over_planned_designs(monkeypatch):
    """Was: the static search spent the whole --time-budget, planned nothing and said "no design"
    though it had found 15. It now stops PLAN_RESERVE s per candidate (at most half the budget)
    before the budget's end. Here the search says it ran out of its time (no clock is raced: the
    budget is far away), and what it found is planned."""
    import time

    from modc.design import run, tasks

    real = run._search
    given = []

    def cut(p, units, k, seed, executor, progress, deadline, **kw):
        given.append(deadline)
        out = real(p, units, k, seed, executor, progress, None, **kw)
        out.stopped, out.complete = "time budget", False
        return out

    monkeypatch.setattr(run, "_search", cut)
    end = time.time() + 3600.0
    n = tasks.candidates(problem(), 2)
    o = run.design(problem(), top=2, seed=0, deadline=end)
    assert given and given[0] <= end - min(run.PLAN_RESERVE * n, 1000.0)  # time kept for planning
    assert o.designs and all(d.plans and d.cycle_time > 0 for d in o.designs)
    assert o.stopped == "time budget" and not o.complete
