"""modc benchmark: base placement in `modc design` (`base within … step …`). Not a test.

    python benchmarks/bench_task_base.py            # the figure, as a table
    python benchmarks/bench_task_base.py --json [OUT]
    python benchmarks/bench_task_base.py --static-only   # only the static cell (seconds; else ~1.5 min)

The same cell (bench_design.CELL: three position targets, a shelf and a post, at most 3 modules)
searched with its base as written (one pose) and with `base within box size (0.2, 0.2, 0) m at
(0, 0, 0) m step 50 mm` (5 x 5 = 25 poses): run.design (--top 1 by default, seed 0), CPU seconds of
this process pinned to one core (BLAS pools at one thread; one pose: the median of three runs),
and their ratio (goal: at most 5). The warm-up runs both sides once (counted in nothing: imports,
caches, numba's kernel), so both run in the same state: the grid crosses reach.JIT_AFTER, so by
default both sides then run the compiled IK; with MODC_JIT=0 both run numpy ("compiled IK" in the
output says which). Before 443ef04 only the one-pose side warmed up, and by default the 25-pose
run paid numba's import and cache load (~0.8 s) inside the measured run.
bench_base() is the function bench_design.py calls.

The issue's task goals (bench_task.py's visit and region cells, the whole design: static search,
exact check, planning and timing) with their base as written and on the same 25-pose grid
(bench_task_cells(); one run each side). 27 Nov 2026 ~13:55 UTC on 968fdcd, load ~1-2, one
pinned core:

                      1 pose (search)      25 poses (search)     ratio (search alone)
    visit             4.0 s (0.1 s)        5.9 s (2.5 s)          1.49 (16.8)
    region           10.6 s (1.2 s)       27.7 s (17.9 s)         2.61 (15.4)

The same on the final tree of that session (27 Nov 2026 ~15:10 UTC, load 2-3, a test run
beside it: the exact reach and pose tests, the family bounds per pose):

    visit             3.8 s (0.1 s)        3.8 s (0.9 s)          1.00 (12.6)
    region           10.2 s (0.7 s)       15.4 s (7.3 s)          1.50 (10.0)
    static cell       0.15-0.2 s           1.3-1.6 s              8-10 (--static-only, four runs)

Planning and timing the candidates dominates a task cell and does not grow with the grid (the
same number of candidates is planned), so the design as a whole meets the goal; the static
search alone grows about as the static cell below does.

Figures (CPU s, --top 1, one core of a 2-core machine shared with three other jobs, load 2.5-3.5;
an empty MODC_CACHE_DIR per run; before (12d2c95) and after (this file's commit) alternating,
three runs each, 27 Nov 2026 10:02-10:05, the same benchmark for both):

                      1 pose (three runs)   25 poses (three runs)   ratio
    default (compiled IK on both sides after the warm-up)
      before 12d2c95  0.23 0.23 0.25        2.98 3.44 3.42          12.7 15.0 13.7
      after           0.19 0.20 0.21        2.91 2.64 2.25          15.4 13.5 10.5
    MODC_JIT=0 (numpy IK)
      before 12d2c95  0.27 0.35 0.30        5.87 5.71 5.91          22.1 16.4 20.0
      after           0.37 0.38 0.28        5.75 5.77 5.44          15.7 15.2 19.8

    best (25 poses): H2 - L2(pivot=-45deg) - L4(pivot=15deg) at (0, 0.05, 0) m, margin 0.959537,
    before and after (ranking.json identical but for "seconds").

What changed (none of it changes what is listed, screened or counted): a shape's family bounds
at every pose in one pass (prefix.refine_many) testing D_1 first and the other bounds only on the
families some pose still passes (bounds.possible_all: half the rows), the bounds' norms without
reductions over an axis of 3; base_link's contact test with one checker per (variant, type)
moved over the poses (8 checkers instead of 109). Measured apart (same process, best of four,
compiled IK): the family bounds of the run's 40 shapes at 15 poses 0.92-1.08 s -> 0.58-0.73 s;
the pose filter (placement.poses) about 0.34 -> 0.1 s.

The screen's retry inside a target's tolerance (evaluate.clear_within, 347c018 and after): a
run that reaches a target's centre only in collision is re-solved once towards a point 0.9 of
the tolerance away from the obstacle. Measured the same way (27 Nov 2026 12:33-12:35, load
1.3-2.4, before = 304d8ba, alternating, three runs each):

                      1 pose (three runs)   25 poses (three runs)   ratio
    default   before  0.17 0.15 0.16        2.19 2.25 2.05          13.1 15.0 12.5
              after   0.30 0.25 0.16        2.68 2.52 2.31           9.0 10.0 14.4
    MODC_JIT=0 before 0.28 0.30 0.44        4.22 4.89 5.52          15.1 16.1 12.5
              after   0.36 0.28 0.28        5.19 4.84 5.54          14.4 17.4 19.5

Same best design, same margin. In this cell it adds no design and costs ~10-20 % of the
25-pose run: of the ~13,800 runs that reach a target only in collision, ~4,700 are shallow
enough to try and ~2,300 come out clear (mostly target c of the X-{3,4}-{1,2} shapes below,
tool0 4.5 mm from the centre, away from the post), and those settings then fail targets a or b
(their IK, at every pose). Where it matters: a chain whose last actuator grazes an obstacle at
the target's centre (tests/test_design_clearance.py: the lightest design needs it).

Goal (<= 5) not met. The floor is the IK: half the 3-unit shapes of this cell (X-{3,4}-{1,2},
X = 1 or 2) work at no pose: at most poses their IK does not reach target c at all (four seeds),
at the others only in collision with the post or, with the retry, clear but then not a or b. They are screened at every
one of the 15 poses in reach, each setting the family and per-setting bounds leave (about 45,000
settings x 4 seeds: ~0.55 s compiled, most of the 25-pose run with numpy, against 0.16-0.2 s for
the whole one-pose run); their mass equals the designs', so the ranking (margin next) needs them
searched. What is left besides: the screen's per-call work around the IK (collision sampling,
forward kinematics, ~0.3 s over 170 calls) and the family bounds (~0.5 s, array work per
(family, pose): sharing them over the poses saves only the per-call overhead).

The exact reach test of 2- and 3-joint chains (modc.design.bounds_exact, after bounds.possible:
branch and bound over (theta_2, theta_3) with first- and second-order bounds and a Gauss-Newton
witness; a numba kernel once reach.jit loads numba, a numpy walk with the same answers before).
Measured as above (27 Nov 2026 14:37-14:40, load 1.1-1.8, before = main at 968fdcd, after =
this file's commit, alternating, default compiled IK):

                      1 pose             25 poses           ratio
    before            0.188 0.176 0.16   2.52 2.58 2.26     13.4 14.7 14.1
    after             0.145 0.141 0.21   1.71 1.88 1.63     11.8 13.3  7.8

IK runs (reach.solve wrapped, one process): 25 poses 218,379 -> 12,914, one pose 10,329 ->
2,337; the same best design, base and margin. Of the settings bounds.possible keeps, ~97 % cannot
reach some target at all (mostly target c): the kernel excludes them at ~3.5-4 µs per setting
(a pair far out of reach: ~60 boxes) against ~15 µs of IK each. What is left of the 25-pose run:
the family bounds (prefix.refine_many, ~0.5 s), the screen around the IK (~0.3 s), the test
(~0.2 s). examples/farm_cell.mod (--top 5) gains nothing: its targets lie just out of reach of
many settings, where a pair's tree is wide (~20 µs, more than the IK it saves), so
bounds_exact.prune tests one setting in 16 first and the rest of the block only where 60 % of
that sample is out of reach. In one process, pinned, warm, search.EXACT off / on alternating:
12.88 / 13.15 s, 13.03 / 13.17 s CPU; the same ranking, excluded_by_bounds 115,141 -> 124,918.
"""
from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMEXPR_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
if (ROOT / "modc" / "__init__.py").is_file() and str(ROOT) not in sys.path[:1]:
    sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(Path(__file__).resolve().parent))

GRID = "    base within box size (0.2, 0.2, 0) m at (0, 0, 0) m step 50 mm\n"


def _run(text: str, top: int) -> dict:
    from bench_design import _problem

    from modc.design import run

    p = _problem(text)
    c, w = time.process_time(), time.perf_counter()
    o = run.design(p, top=top, seed=0)
    cpu, wall = time.process_time() - c, time.perf_counter() - w
    best = o.designs[0] if o.designs else None
    return {"seconds_cpu": round(cpu, 3), "seconds_wall": round(wall, 3), "designs": len(o.designs),
            "best": best.chain() if best else None,
            "best_base_m": list(best.verified.robot.base.xyz) if best else None,
            "best_mass_kg": round(best.mass, 6) if best else None,
            "best_margin": round(best.margin, 6) if best else None,
            "bases_searched": o.bases_searched, "bases_pruned": o.bases_pruned, "bases_total": o.bases_total}


def bench_base(tops: tuple[int, ...] = (1,)) -> dict:
    """One base pose against 25 on the same cell: CPU s each and the ratio, per --top."""
    from bench_design import CELL

    grid = CELL.replace("    units 2 to 3\n", "    units 2 to 3\n" + GRID)
    assert grid != CELL
    out = {}
    # warm-up (counted in nothing): imports, caches, and both sides once, so that both run in the
    # same state - in particular the compiled IK (modc.design.reach.jit), which a process loads
    # only once it has solved JIT_AFTER runs: the grid crosses that, one pose does not, and
    # without this the 25-pose run would pay numba's import and cache load for both
    _run(CELL, 1)
    _run(grid, 1)
    for top in tops:
        # one pose: the median of three runs (about a second each, so a burst of load on the
        # machine would move the ratio by itself)
        one = sorted((_run(CELL, top) for _ in range(3)), key=lambda r: r["seconds_cpu"])[1]
        many = _run(grid, top)
        out[f"top{top}"] = {"one_pose": one, "poses_25": many,
                            "ratio_cpu": round(many["seconds_cpu"] / max(one["seconds_cpu"], 1e-9), 2)}
    from modc.design import reach

    out["compiled_ik"] = bool(reach._JIT and reach._JIT[0])  # both sides: the warm-up set it
    out["load_average"] = [round(x, 2) for x in os.getloadavg()]
    return out


def bench_task_cells() -> dict:
    """The issue's task goals (bench_task's visit and region cells: the static search, the exact
    check, the planning and timing of every surviving design) with their base as written and on
    the same 25-pose grid: CPU s each (and the static search's share apart), and the ratios. One
    run each side (seconds each, so load moves the ratio less than the static cell's)."""
    from bench_task import GOALS, bench_goal

    out = {}
    for name in ("visit", "region"):
        text, goal = GOALS[name]
        grid = text.replace("    units 2 to 3\n", "    units 2 to 3\n" + GRID)
        assert grid != text
        one, many = bench_goal(text, goal), bench_goal(grid, goal)
        out[name] = {"one_pose": one, "poses_25": many,
                     "ratio_cpu": round(many["seconds_cpu"] / max(one["seconds_cpu"], 1e-9), 2),
                     "ratio_static_search_cpu": round(many["static_search_cpu_s"]
                                                      / max(one["static_search_cpu_s"], 1e-9), 2)}
    return out


def _lines(res: dict, tasks: dict) -> list[str]:
    lines = [f"  compiled IK: {res.pop('compiled_ik')}; load average {res.pop('load_average')}"]
    for k, v in res.items():
        a, b = v["one_pose"], v["poses_25"]
        lines.append(f"  static cell {k}: 1 pose {a['seconds_cpu']:.1f} s ({a['best']}); 25 poses "
                     f"{b['seconds_cpu']:.1f} s ({b['bases_searched']} searched, {b['bases_pruned']} pruned; best "
                     f"{b['best']} at {b['best_base_m']}); ratio {v['ratio_cpu']:.2f}")
    for k, v in tasks.items():
        a, b = v["one_pose"], v["poses_25"]
        lines.append(f"  task cell {k}: 1 pose {a['seconds_cpu']:.1f} s (search {a['static_search_cpu_s']:.1f} s, "
                     f"{a['best']}, {a['cycle_time_s']} s); 25 poses {b['seconds_cpu']:.1f} s (search "
                     f"{b['static_search_cpu_s']:.1f} s, {b['best']}, {b['cycle_time_s']} s); ratio "
                     f"{v['ratio_cpu']:.2f} (search alone {v['ratio_static_search_cpu']:.2f})")
    return lines


def main() -> None:
    from _common import pin_one_core

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--json", nargs="?", const="-", default=None)
    ap.add_argument("--top", type=int, nargs="+", default=[1], help="--top values to measure (5: minutes)")
    ap.add_argument("--static-only", action="store_true", help="only the static three-target cell (seconds)")
    args = ap.parse_args()
    core = pin_one_core()
    res = bench_base(tuple(args.top))
    tasks = {} if args.static_only else bench_task_cells()
    if args.json is not None:
        import json

        text = json.dumps({"core": core, "base_placement": res, "task_cells": tasks}, indent=2)
        if args.json == "-":
            print(text)
        else:
            Path(args.json).write_text(text + "\n", encoding="utf-8")
        return
    print(f"base placement, one core ({core}): CPU s, 1 pose vs 25 poses (goal: ratio <= 5)")
    print("\n".join(_lines(res, tasks)))


if __name__ == "__main__":
    main()
