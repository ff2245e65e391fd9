"""The cell's tasks and paths for the designs the static search returns: each design's robot
(the cell's tasks, regions and paths included) planned and timed with modc.plan.task, the one
planner of `modc plan --task`. A design whose task cannot be planned or timed is rejected, the
reason recorded with the other rejections. Planning costs seconds per design, so it runs only
for the designs that passed the cheap screens and the exact check."""
from __future__ import annotations

import time
from dataclasses import replace

from .rank import TASK, Design, order

PLAN_FACTOR = 3  # designs the static search returns per design asked for when a task objective ranks


def has_tasks(problem) -> bool:
    return bool(problem.cell.tasks or problem.cell.paths)


def candidates(problem, top: int) -> int:
    """How many designs the static search should return: more than `top` when a task objective
    ranks (the static order does not know which arm is fastest)."""
    return top * PLAN_FACTOR if any(o in TASK for o in problem.rank) else top


def task_names(robot) -> list[str]:
    return [t.name for t in (*robot.tasks, *robot.paths)]


def plan_design(d: Design, seed: int, deadline: float | None) -> Design | str:
    """d with its plans, or why one of its tasks cannot be planned."""
    from ..plan.errors import PlanError
    from ..plan.task import plan_task_robot

    robot = d.verified.robot
    plans = []
    for name in task_names(robot):
        left = None if deadline is None else max(deadline - time.time(), 1.0)
        try:
            plans.append(plan_task_robot(robot, name, seed=seed, timeout=left))
        except PlanError as e:
            return f"task '{name}' cannot be planned ({e.code}: {e.message})"
    return replace(d, plans=tuple(plans))


def plan_all(out, top: int, seed: int, deadline: float | None, stopping) -> None:
    """Plan every design of the outcome, drop those that fail, rank by the problem's objectives
    (the task objectives now known) and keep `top`."""
    kept = []
    for d in out.designs:
        why = stopping(deadline)
        if why:
            out.stopped = out.stopped or why
            break
        p = plan_design(d, seed, deadline)
        if isinstance(p, str):
            out.rejections.append(f"{'-'.join(u.name for u in d.verified.robot.units)}: {p}")
            continue
        kept.append(p)
    out.designs = order(kept, out.problem.rank)[:top]
