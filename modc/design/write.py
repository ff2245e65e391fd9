"""What `modc design FILE -o DIR` writes: DIR/ranking.json (docs/conventions.md), one complete robot
file per design (DIR/<name>_<rank>.mod: the chain, the cell, the targets and a pose per target,
compilable as it is) and DIR/report.html."""
from __future__ import annotations

import json
import math

from .evaluate import pose_name
from .rank import Design
from .run import Outcome


def file_name(problem: str, rank: int) -> str:
    return f"{problem}_{rank}.mod"


def robot_file(outcome: Outcome, rank: int, d: Design) -> str:
    from ..model.write import robot_file_text

    name = f"{outcome.problem.name}_{rank}"
    robot = d.verified.robot.model_copy(update={"name": name})
    targets = ", ".join(f"{pose_name(t)} reaches {t}" for t in d.verified.targets)
    comments = [f"Design {rank} of `modc design` for '{outcome.problem.name}': {d.modules} modules, "
                f"{d.mass:.3f} kg, torque margin {d.margin * 100:.0f} %.", f"Poses: {targets}."]
    return robot_file_text(robot, comments)


def ranking(outcomes: list[Outcome]) -> dict:
    designs = []
    for o in outcomes:
        for rank, d in enumerate(o.designs, start=1):
            designs.append({
                "rank": rank, "file": file_name(o.problem.name, rank), "design": o.problem.name, "chain": d.chain(),
                "modules": d.modules, "mass_kg": round(d.mass, 6), "torque_margin": round(d.margin, 6),
                "targets": d.verified.targets,
                "alternatives": [{"chain": a.chain(), "mass_kg": round(a.mass, 6), "torque_margin": round(a.margin, 6)}
                                 for a in d.alternatives],
            })
    prefix = len(outcomes) > 1

    def shapes(o: Outcome, labels: list[str]) -> list[str]:
        return [f"{o.problem.name}/{s}" if prefix else s for s in labels]

    return {"designs": designs, "evaluated": sum(o.evaluated for o in outcomes),
            "excluded_by_bounds": sum(o.excluded for o in outcomes),
            "seconds": round(sum(o.seconds for o in outcomes), 3),
            "complete": all(o.complete for o in outcomes),
            "stopped": next((o.stopped for o in outcomes if o.stopped), None),
            "unfinished_shapes": [s for o in outcomes for s in shapes(o, o.unfinished)],
            "coarse_shapes": [s for o in outcomes for s in shapes(o, o.coarse)]}


def files(outcomes: list[Outcome], renders: dict[str, bytes] | None = None) -> dict[str, str | bytes]:
    from .. import __version__
    from ..files import REPORT
    from .report import report_html

    out: dict[str, str | bytes] = {"ranking.json": json.dumps(ranking(outcomes), indent=2, allow_nan=False) + "\n"}
    for o in outcomes:
        for rank, d in enumerate(o.designs, start=1):
            out[file_name(o.problem.name, rank)] = robot_file(o, rank, d)
    out["report.html"] = report_html(outcomes, renders or {})
    # what wrote this directory (write_tree's manifest is what lets a later run replace it)
    marker = {"generator": f"modc {__version__}", "command": "design",
              "designs": [o.problem.name for o in outcomes], "outputs": sorted([*out, REPORT])}
    out[REPORT] = json.dumps(marker, indent=2) + "\n"
    return dict(sorted(out.items()))


def summary_line(o: Outcome) -> str:
    best = o.designs[0]
    return (f"{o.problem.name}: {len(o.designs)} designs from {o.evaluated:,} evaluated in {o.seconds:.1f} s; "
            f"best {best.chain()} ({best.modules} modules, {best.mass:.3f} kg, "
            f"margin {math.floor(best.margin * 100)} %)")
