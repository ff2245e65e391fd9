"""What `modc design FILE -o DIR` writes: DIR/ranking.json (docs/conventions.md), one complete robot
file per design (DIR/<name>_<rank>.mod: the chain, the cell, the targets and a pose per target,
compilable as it is), for a cell with tasks DIR/<name>_<rank>.traj.json (the first task, planned
and timed) and DIR/report.html."""
from __future__ import annotations

import json
import math

from ..formatting import counted
from ..objectives import REGISTRY
from .evaluate import pose_name
from .outcome import Outcome
from .rank import Design, why, worst_share


def file_name(problem: str, rank: int) -> str:
    return f"{problem}_{rank}.mod"


def traj_name(problem: str, rank: int) -> str:
    return f"{problem}_{rank}.traj.json"


def task_figures(o: Outcome, rank: int, d: Design) -> dict:
    """ranking.json's task keys of a planned design: cycle time and energy summed over the
    cell's tasks and paths, the figures per task, and which task the .traj.json holds."""
    if not d.plans:
        return {**base_figures(o, d), **({"coverage": round(d.coverage, 6)} if "coverage" in o.problem.rank else {})}
    return {**base_figures(o, d, always=True),
            "cycle_time_s": round(d.cycle_time, 6), "energy_j": round(d.energy, 6),
            "peak_torque_share": round(max(p.peak_share for p in d.plans), 6),
            "coverage": round(d.coverage, 6),  # share of the region points reached (1 unless `rank coverage`)
            "tasks": [{"task": p.task, "kind": p.kind, "cycle_time_s": round(p.cycle_time, 6),
                       "energy_j": round(p.energy, 6), "peak_torque_share": round(p.peak_share, 6),
                       "segments": [s.to_json() for s in p.segments]} for p in d.plans],
            "traj": traj_name(o.problem.name, rank), "traj_task": d.plans[0].task}


def base_figures(o: Outcome, d: Design, always: bool = False) -> dict:
    """ranking.json's "base" (`base within`, or a cell with tasks): where the design's base_link
    stands in the cell frame, m and deg (the `base at` of its robot file)."""
    if not always and o.problem.base_grid is None:
        return {}
    base = d.verified.robot.base
    return {"base": {"xyz_m": [round(v, 9) + 0.0 for v in base.xyz],
                     "rpy_deg": [round(math.degrees(v), 6) + 0.0 for v in base.rpy]}}


def robot_file(outcome: Outcome, rank: int, d: Design) -> str:
    from ..model.write import robot_file_text

    name = f"{outcome.problem.name}_{rank}"
    robot = d.verified.robot.model_copy(update={"name": name})
    # (region points are screened with poses of their own, which the robot file does not keep)
    targets = ", ".join(f"{pose_name(t)} reaches {t}" for t in d.verified.targets if robot.pose(pose_name(t)))
    comments = [f"Design {rank} of `modc design` for '{outcome.problem.name}': {counted(d.modules, 'module')}, "
                f"{d.mass:.3f} kg, torque margin {d.margin * 100:.0f} %.", f"Poses: {targets}."]
    if outcome.problem.base_grid is not None:  # the cell was given in the frame of the base's box
        comments.append("The base pose was searched (`base within`): the cell below is in base_link, "
                        "the frame of `base at`.")
    return robot_file_text(robot, comments, state_base=outcome.problem.base_grid is not None)


def reference_file(o: Outcome) -> str | None:
    """DIR/<name>_reference.mod: the block's `compare with` arm in its cell, with a pose per target
    when it reaches them all (so that `modc view` and `modc plan` show what it does); None when
    its chain does not compile."""
    from ..model.write import robot_file_text
    from .reference import file_name as ref_name

    r = o.reference
    if r is None or r.mass is None or (r.verified is None and o.problem.reference is None):
        return None
    robot = r.verified.robot if r.verified is not None else o.problem.reference
    assert robot is not None
    robot = robot.model_copy(update={"name": ref_name(o.problem.name)[:-len(".mod")]})
    verdict = "it passes every check the designs passed" if r.feasible else "it fails: " + "; ".join(r.fails)
    comments = [f"The reference arm of `modc design` for '{o.problem.name}' (`compare with chain {r.chain}`): "
                f"{counted(r.modules, 'module')}, {r.mass:.3f} kg; {verdict}."]
    return robot_file_text(robot, comments, state_base=o.problem.base_grid is not None)


def _entry(o: Outcome, rank: int, d: Design, said: str) -> dict:
    return {
        "rank": rank, "file": file_name(o.problem.name, rank), "design": o.problem.name, "chain": d.chain(),
        "modules": d.modules, "mass_kg": round(d.mass, 6), "torque_margin": round(d.margin, 6),
        "targets": d.verified.targets, **task_figures(o, rank, d),
        "worst_error_share": round(worst_share(d.verified.targets, o.problem.cell), 6),
        "why": said,  # in words: what decided this rank against the next (the last: the one before)
        # every ranked objective's value (SI: kg, s, J; shares 0 to 1), in ranking order
        "objectives": {k: round(float(REGISTRY[k].value(d) or 0.0), 9) for k in o.problem.rank},
        "alternatives": [{"chain": a.chain(), "mass_kg": round(a.mass, 6), "torque_margin": round(a.margin, 6)}
                         for a in d.alternatives],
    }


def ranking(outcomes: list[Outcome]) -> dict:
    designs = [_entry(o, rank, d, said) for o in outcomes
               for rank, (d, said) in enumerate(zip(o.designs, why(o.designs, o.problem.rank), strict=True), start=1)]
    prefix = len(outcomes) > 1

    def shapes(o: Outcome, labels: list[str]) -> list[str]:
        return [f"{o.problem.name}/{s}" if prefix else s for s in labels]

    bases = {o.problem.name: {"poses": o.bases_total, "searched": o.bases_searched, "pruned_by_reach": o.bases_pruned,
                              "pruned_by_contact": o.bases_touching}
             for o in outcomes if o.bases_searched is not None}
    return {"designs": designs, **({"bases": bases} if bases else {}), "evaluated": sum(o.evaluated for o in outcomes),
            "excluded_by_bounds": sum(o.excluded for o in outcomes),
            "dominated": sum(o.dominated for o in outcomes),  # of those excluded: out of every shape's top
            "seconds": round(sum(o.seconds for o in outcomes), 3),
            "complete": all(o.complete for o in outcomes),
            "stopped": next((o.stopped for o in outcomes if o.stopped), None),
            "unfinished_shapes": [s for o in outcomes for s in shapes(o, o.unfinished)],
            # designs the search found but could not plan and time before it stopped
            "not_planned": [s for o in outcomes for s in shapes(o, o.not_planned)],
            # design blocks not searched at all: an earlier one used up the time budget (or Ctrl-C)
            "not_searched": [o.problem.name for o in outcomes if not o.searched],
            "coarse_shapes": [s for o in outcomes for s in shapes(o, o.coarse)],
            # `compare with chain …`: per design block naming one, its arm evaluated on the cell
            **({"reference": refs} if (refs := {o.problem.name: o.reference.to_json(o.problem.name)
                                                for o in outcomes if o.reference is not None}) else {})}


def files(outcomes: list[Outcome], renders: dict[str, bytes] | None = None) -> dict[str, str | bytes]:
    from .. import __version__
    from ..files import REPORT
    from .report import report_html

    out: dict[str, str | bytes] = {"ranking.json": json.dumps(ranking(outcomes), indent=2, allow_nan=False) + "\n"}
    for o in outcomes:
        for rank, d in enumerate(o.designs, start=1):
            out[file_name(o.problem.name, rank)] = robot_file(o, rank, d)
            if d.plans:  # the whole of the first task (ranking.json's traj_task)
                out[traj_name(o.problem.name, rank)] = d.plans[0].dumps()
        ref = reference_file(o)
        if ref is not None:
            from . import reference

            out[reference.file_name(o.problem.name)] = ref
            if o.reference.plans:
                out[reference.traj_name(o.problem.name)] = o.reference.plans[0].dumps()
    out["report.html"] = report_html(outcomes, renders or {})
    # what wrote this directory (write_tree's manifest is what lets a later run replace it)
    marker = {"generator": f"modc {__version__}", "command": "design",
              "designs": [o.problem.name for o in outcomes], "outputs": sorted([*out, REPORT])}
    out[REPORT] = json.dumps(marker, indent=2) + "\n"
    return dict(sorted(out.items()))


def summary_line(o: Outcome) -> str:
    if not o.designs:
        return f"{o.problem.name}: no design" + ("" if o.searched else " (not searched)")
    best = o.designs[0]
    timed = f", cycle time {best.cycle_time:.3f} s, {best.energy:.2f} J" if best.plans else ""
    return (f"{o.problem.name}: {counted(len(o.designs), 'design')} from {o.evaluated:,} evaluated in "
            f"{o.seconds:.1f} s; "
            f"best {best.chain()} ({counted(best.modules, 'module')}, {best.mass:.3f} kg, "
            f"margin {math.floor(best.margin * 100)} %{timed})")
