"""The farm's real task (examples/farm_cell.mod): a plant in the cell, a row of tray cells served
with the gripper pointing down, a shelf post and a table; the paper's arm on the same cell."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from modc.compiler import check_file, check_text

ROOT = Path(__file__).resolve().parent.parent
PAPER = "H1 - L4(pivot=-90deg, port=45deg) - L3(link=180mm)"


def farm():
    checked = check_file(ROOT / "examples" / "farm_cell.mod")
    assert checked.ok, [d.message for d in checked.diagnostics]
    return checked.design.problems[0]


def robot_on_the_cell(chain: str):
    """A robot file with the farm cell around the chain (as `modc design` writes one)."""
    from modc.model.write import robot_file_text

    units = check_text(f"robot x {{\n    chain {chain}\n}}\n", "x.mod").design.robots[0].units
    text = robot_file_text(farm().cell.model_copy(update={"name": "farm_paper", "units": units}))
    checked = check_text(text, "farm_paper.mod")
    assert checked.ok, [d.message for d in checked.diagnostics]
    return checked.design.robots[0], text


def test_the_farm_cell_states_the_task():
    p = farm()
    assert [t.name for t in p.cell.tasks] == ["serve"] and p.rank[0] == "cycle_time"
    tray = p.cell.regions[0]
    assert tray.pointing == (0.0, 0.0, -1.0) and len(tray.points()) == 3
    assert p.cell.tasks[0].visits == ("plant", "tray[0,0,0]", "tray[1,0,0]", "tray[2,0,0]", "plant")
    assert {"post", "table"} <= {o.name for o in p.cell.obstacles}


@pytest.mark.slow
def test_the_papers_arm_cannot_point_down_at_the_tray(tmp_path):
    """Its tool points straight down only on a ring about joint 1 that misses the tray row: the
    planner says which target it cannot serve, and an IK of the tray point independent of the
    planner (position and axis, many seeds) agrees."""
    from modc.kinematics import Chain
    from modc.plan.errors import PlanError
    from modc.plan.task import plan_task_robot

    robot, _ = robot_on_the_cell(PAPER)
    with pytest.raises(PlanError) as e:
        plan_task_robot(robot, "serve", seed=0)
    assert e.value.code == "task-segment-failed" and "tray[" in e.value.message
    chain = Chain(robot)
    lo = np.array([robot.joint_range(i)[0] for i in range(1, 4)])
    hi = np.array([robot.joint_range(i)[1] for i in range(1, 4)])
    rng = np.random.default_rng(0)
    t = robot.task_target("tray[0,0,0]")
    best = np.inf
    for q in lo + (hi - lo) * rng.random((20000, 3)):
        T = chain.T_base_tool(q)
        if -T[2, 0] >= np.cos(t.orientation_tolerance):  # pointing down within the tolerance
            best = min(best, float(np.linalg.norm(T[:3, 3] - t.xyz)))
    assert best > 4 * t.position_tolerance
