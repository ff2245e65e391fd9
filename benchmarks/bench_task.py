"""modc benchmark: designing for a whole task (issue 23's goals, one core). Not a test.

    python benchmarks/bench_task.py                 # both goals
    python benchmarks/bench_task.py --only visit    # one of them (visit, region)
    python benchmarks/bench_task.py --json [OUT]    # the figures as JSON (stdout without OUT)
    python benchmarks/bench_task.py --profile DIR   # also a cProfile of each run: DIR/<goal>.prof

Each goal is run.design (top 1, seed 0) on a cell with at most 3 modules whose design block has
a task, so the static search, the exact check and the planning and timing of every surviving
design (modc.design.tasks) all count. CPU figures are time.process_time() of this process pinned
to one core (BLAS/OpenMP pools at one thread), so other load on the machine does not count; wall
figures are time.perf_counter() and do. The first run of a process pays imports and caches: a
warm-up design (one target, no task) runs first and counts in nothing.

   visit   a 4-goal `visit` task around a post, units 2 to 3, every module type: goal <= 60 s CPU
   region  a 12-point region (grid 4 x 3 x 1) visited in one task, units 2 to 3: goal <= 30 s CPU
   points  the same 12 points written as targets: the region costs what its points as targets cost
"""
from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMEXPR_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import platform  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402

from _common import pin_one_core, report  # noqa: E402  (benchmarks/_common.py)

ROOT = Path(__file__).resolve().parent.parent
if (ROOT / "modc" / "__init__.py").is_file() and str(ROOT) not in sys.path[:1]:
    sys.path.insert(0, str(ROOT))

WARM_UP = """design warm {
    target a at (0.30, 0.10, 0.25) m
    units 2
}
"""

# Four goals on either side of a post: the motions between them go around it.
VISIT = """design visit4 {
    payload 100 g
    box post size (0.05, 0.05, 0.6) m at (0.2, 0.25, 0.3) m
    target a at (0.30, 0.10, 0.25) m
    target b at (0.25, -0.15, 0.30) m
    target c at (0.35, -0.05, 0.15) m
    target d at (0.10, 0.30, 0.30) m
    units 2 to 3
    task serve { visit a, b, c, d }
    rank modules, cycle_time
}
"""

# A tray of 4 x 3 cells, 5 cm apart, served in one task by position (each within 5 mm), from a
# point above its centre. Every point is required: the static search screens the 12 points as
# targets (modc.design.tasks.with_points), each from the candidate's own solution at the nearest
# point it already reached (evaluate.screen_batch).
REGION = """design tray12 {
    payload 50 g
    target above at (0.30, 0, 0.25) m
    region tray box size (0.15, 0.10, 0) m at (0.30, 0, 0.20) m grid 4 x 3 x 1 within 5 mm
    units 2 to 3
    task serve { visit above, tray }
    rank modules, cycle_time
}
"""



def _points_as_targets() -> str:
    """The same 12 points as plain targets, visited in the region's order: what the search does
    once it screens region points as it screens targets."""
    xs, ys = [0.225 + 0.05 * i for i in range(4)], [-0.05 + 0.05 * j for j in range(3)]
    names = [f"p{i}{j}" for i in range(4) for j in range(3)]
    lines = [f"    target p{i}{j} at ({x:.3f}, {y:.3f}, 0.20) m within 5 mm" for i, x in enumerate(xs)
             for j, y in enumerate(ys)]
    return ("design points12 {\n    payload 50 g\n    target above at (0.30, 0, 0.25) m\n" + "\n".join(lines)
            + f"\n    units 2 to 3\n    task serve {{ visit above, {', '.join(names)} }}\n"
            "    rank modules, cycle_time\n}\n")


POINTS = _points_as_targets()
GOALS = {"visit": (VISIT, 60.0), "region": (REGION, 30.0), "points": (POINTS, 30.0)}


def _problem(text: str):
    from modc.compiler import check_text

    checked = check_text(text, "bench.mod")
    assert checked.ok, [d.message for d in checked.diagnostics]
    return checked.design.problems[0]


def bench_goal(text: str, goal_s: float, profile: Path | None = None) -> dict:
    """run.design (top 1) on the cell: CPU and wall seconds, what it found."""
    from modc.design import run

    problem = _problem(text)
    prof = None
    if profile is not None:
        import cProfile

        prof = cProfile.Profile()
        prof.enable()
    from modc.design import tasks

    planning = [0.0]
    plan_all = tasks.plan_all

    def timed(*args, **kw):  # the planning and timing of the static search's designs, apart
        c = time.process_time()
        try:
            return plan_all(*args, **kw)
        finally:
            planning[0] += time.process_time() - c

    c0, w0 = time.process_time(), time.perf_counter()
    tasks.plan_all = timed
    try:
        out = run.design(problem, top=1, seed=0)
    finally:
        tasks.plan_all = plan_all
    cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    if prof is not None and profile is not None:
        prof.disable()
        profile.parent.mkdir(parents=True, exist_ok=True)
        prof.dump_stats(str(profile))
    best = out.designs[0] if out.designs else None
    return {"seconds_cpu": round(cpu, 2), "seconds_wall": round(wall, 2), "goal_cpu_s": goal_s,
            "planning_cpu_s": round(planning[0], 2), "static_search_cpu_s": round(cpu - planning[0], 2),
            "met": cpu <= goal_s and best is not None, "evaluated": out.evaluated, "complete": out.complete,
            "best": best.chain() if best is not None else None,
            "cycle_time_s": round(best.cycle_time, 4) if best is not None and best.plans else None,
            "segments": sum(len(p.counted) for p in best.plans) if best is not None else 0,
            "rejected": len(out.rejections), "why_none": None if best is not None else out.why_none()}


def bench_visit(profile: Path | None = None) -> dict:
    """(a) the 4-goal visit task, <= 3 modules."""
    return bench_goal(VISIT, GOALS["visit"][1], profile)


def bench_region(profile: Path | None = None) -> dict:
    """(b) the 12-point region, <= 3 modules."""
    return bench_goal(REGION, GOALS["region"][1], profile)


def bench_points(profile: Path | None = None) -> dict:
    """(b') the region's 12 points written as targets, so that the static search screens them."""
    return bench_goal(POINTS, GOALS["points"][1], profile)


def _load() -> float:
    try:
        return os.getloadavg()[0]
    except OSError:
        return float("nan")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", choices=sorted(GOALS), action="append", help="run only this goal (repeatable)")
    ap.add_argument("--json", nargs="?", const="-", default=None, help="write the figures as JSON (no OUT: stdout)")
    ap.add_argument("--profile", type=Path, help="directory for a cProfile of each goal (<goal>.prof)")
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    result: dict = {"machine": platform.processor() or platform.machine(), "python": platform.python_version(),
                    "core": pin_one_core(), "load_1min_before": round(_load(), 2)}
    from modc.design import run

    run.design(_problem(WARM_UP), top=1, seed=0)
    runs = {"visit": bench_visit, "region": bench_region, "points": bench_points}
    for name in args.only or list(runs):
        result[name] = runs[name](args.profile / f"{name}.prof" if args.profile else None)
    result["load_1min_after"] = round(_load(), 2)
    lines = [f"{'goal':<8} {'CPU s':>7} {'search':>7} {'plan':>7} {'wall s':>7} {'goal s':>7}  met    best"]
    for name in runs:
        r = result.get(name)
        if r is None:
            continue
        found = f"{r['best']} ({r['cycle_time_s']} s, {r['segments']} segments)" if r["best"] else \
            f"none: {r['why_none']}"
        lines.append(f"{name:<8} {r['seconds_cpu']:>7.1f} {r['static_search_cpu_s']:>7.1f} {r['planning_cpu_s']:>7.1f} "
                     f"{r['seconds_wall']:>7.1f} {r['goal_cpu_s']:>7.0f}  "
                     f"{'yes' if r['met'] else 'NO ':<5}  {found}")
    lines.append(f"one core ({result['core']}), load average {result['load_1min_before']} before, "
                 f"{result['load_1min_after']} after")
    report(result, "\n".join(lines), args.json)


if __name__ == "__main__":
    main()
