"""modc benchmark: base placement in `modc design` (`base within … step …`). Not a test.

    python benchmarks/bench_task_base.py            # the figure, as a table
    python benchmarks/bench_task_base.py --json [OUT]

The same cell (bench_design.CELL: three position targets, a shelf and a post, at most 3 modules)
searched with its base as written (one pose) and with `base within box size (0.2, 0.2, 0) m at
(0, 0, 0) m step 50 mm` (5 x 5 = 25 poses): run.design (--top 1 by default, seed 0), CPU seconds of
this process pinned to one core (BLAS pools at one thread; one pose: the median of three runs),
and their ratio (goal: at most 5).
bench_base() is the function bench_design.py calls.

Figures (CPU s, one core of a 2-core machine shared with other jobs; an empty MODC_CACHE_DIR
per run; before (12e0a43, per-pose search) and after (modc/design/grid.py) alternating):

    27 Nov 2026, load 2.3-4.5       --top  1 pose            25 poses        ratio
    before 12e0a43 (07:51-07:54)      1    0.31-0.42 (median  7.2-11.6 (8.0-   20.5 / 23.7
                                           of six, two runs)  8.1 median)
    after          (same window)      1    0.30-0.45          5.3-7.8 (5.4-   14.9 / 17.5
                                                              5.9 median)
    before 12e0a43 (07:49-07:51)      3    11.0               9.0             0.82
    after          (07:47-07:49)      3    13.0               4.3             0.33
    with the compiled IK (reach_jit, numba; 08:44-08:46, load 1.8-2.1):
                                      1    0.3                3.6-3.8         12.1 / 13.7
                                      3    6.6                2.9             0.44
    (screening every pose of a level in one shared IK batch was tried on top: 115 IK calls
    instead of 327, the same time once the IK is compiled: 3.2-3.6 s, 11.7 / 14.2; left out)

    best (25 poses, --top 1): before H2(pivot=30deg) - L2(pivot=-15deg) - L4(pivot=15deg) at
    (-0.05, 0.1, 0) m (margin 0.95965); after H2 - L2(pivot=-45deg) - L4(pivot=15deg) at
    (0, 0.05, 0) m (margin 0.95954): one design per shape over the grid, its simplest setting
    at its nearest pose, where before every pose gave its own (see modc/design/grid.py).

Goal (<= 5) not met. The grid search closes a shape that works somewhere at every pose once six
of its settings are dead on (usually after two nonzero twists), but half the 3-unit shapes of
this cell (unit 3 of type 1 or 2) work nowhere and are screened at every one of the 15 poses in
reach, each setting the family and per-setting bounds leave (about 45,000 IK screens, most of
the time); their mass equals the designs', so the ranking (margin next) needs them searched.
What is left: the IK of those settings (about 200 batched calls of a few hundred settings each:
screening a level of a shape at every pose in one batch would need per-candidate targets in
modc.design.evaluate.screen_batch), the family bounds per (shape, pose) (about 15 %), and the
base_link contact test per pose (about 0.3 s).
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


def main() -> None:
    from _common import pin_one_core

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--json", nargs="?", const="-", default=None)
    ap.add_argument("--top", type=int, nargs="+", default=[1], help="--top values to measure (5: minutes)")
    args = ap.parse_args()
    core = pin_one_core()
    res = bench_base(tuple(args.top))
    if args.json is not None:
        import json

        text = json.dumps({"core": core, "base_placement": res}, indent=2)
        if args.json == "-":
            print(text)
        else:
            Path(args.json).write_text(text + "\n", encoding="utf-8")
        return
    print(f"base placement, one core ({core}): CPU s, 1 pose vs 25 poses (goal: ratio <= 5)")
    print(f"  compiled IK: {res.pop('compiled_ik')}; load average {res.pop('load_average')}")
    for k, v in res.items():
        a, b = v["one_pose"], v["poses_25"]
        print(f"  {k}: 1 pose {a['seconds_cpu']:.1f} s ({a['best']}); 25 poses {b['seconds_cpu']:.1f} s "
              f"({b['bases_searched']} searched, {b['bases_pruned']} pruned; best {b['best']} at {b['best_base_m']}); "
              f"ratio {v['ratio_cpu']:.2f}")


if __name__ == "__main__":
    main()
