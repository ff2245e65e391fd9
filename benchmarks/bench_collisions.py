"""modc benchmark: the SRDF self-collision matrix (modc/physical/collisions.py). Not a test.

    python benchmarks/bench_collisions.py              # examples A and B (6-DoF), 10,000 samples
    python benchmarks/bench_collisions.py --quick      # fewer repetitions
    python benchmarks/bench_collisions.py --all        # every example robot
    python benchmarks/bench_collisions.py --json [OUT] # JSON document on stdout (table on stderr) or to OUT

Measured side by side, per robot, on one core (the process is pinned to one CPU and BLAS/OpenMP
pools are set to one thread before numpy loads):

  fast    collisions.compute: vectorised broad phase, exact mesh tests of link pairs only where
          bounding spheres touch, pairs leave the loop once their reason is certain
  naive   collisions.compute_naive, the anchor: every mesh pair of every non-adjacent link pair
          in every sample (pinocchio.computeCollisions), every result read back
  ratio   naive / fast. Both must produce the same matrix; the script checks that.

Target: fast <= 0.5 s for 10,000 samples of a 6-DoF arm. Both wall time (median of the runs)
and the process's CPU time are reported: on a loaded machine the CPU time is the steadier
figure. Loading the URDF and meshes into pinocchio (done once per compile) is timed separately.
"""
from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMEXPR_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import platform  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

from _common import pin_one_core, report  # noqa: E402  (benchmarks/_common.py)

ROOT = Path(__file__).resolve().parent.parent
if (ROOT / "modc" / "__init__.py").is_file() and str(ROOT) not in sys.path[:1]:
    sys.path.insert(0, str(ROOT))

TARGET_S = 0.5
SIX_DOF_EXAMPLES = ("example_a", "example_b")




def _time(fn, runs: int) -> tuple[dict, object]:
    fn()  # warm-up (imports, caches)
    walls, cpus, result = [], [], None
    for _ in range(runs):
        w, c = time.perf_counter(), time.process_time()
        result = fn()
        walls.append(time.perf_counter() - w)
        cpus.append(time.process_time() - c)
    return {"runs": runs, "wall_median": statistics.median(walls), "wall_min": min(walls),
            "cpu_median": statistics.median(cpus), "cpu_min": min(cpus)}, result


def _robots(all_examples: bool):
    from modc.backends import Build
    from modc.compiler import check_file

    paths = sorted((ROOT / "examples").glob("*.mod")) if all_examples else \
        [ROOT / "examples" / f"{s}.mod" for s in SIX_DOF_EXAMPLES]
    for path in paths:
        c = check_file(path)
        if not c.ok:
            continue
        b = Build(c.design)
        for r in c.design.robots:
            yield path.stem, b, r


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer repetitions")
    ap.add_argument("--all", action="store_true", help="every example robot, not only the 6-DoF ones")
    ap.add_argument("--samples", type=int, default=10_000)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--json", nargs="?", const="-", default=None, metavar="OUT")
    args = ap.parse_args(argv)

    cpu = pin_one_core()
    from modc.physical import collisions

    fast_runs, naive_runs = (3, 1) if args.quick else (9, 3)
    out = sys.stderr if args.json == "-" else sys.stdout
    rows = []
    print(f"self-collision matrix, {args.samples} samples, seed {args.seed}, one core (cpu {cpu}); "
          f"times in s: median wall / median CPU", file=out)
    print(
        f"{'example/robot':<26}{'dof':>4}{'load':>8}{'fast wall':>11}{'fast cpu':>10}"
        f"{'naive wall':>12}{'naive cpu':>11}"
        f"{'ratio':>8}{'exact':>8}{'same':>6}",
        file=out,
    )
    for stem, b, r in _robots(args.all):
        load, geo = _time(lambda b=b, r=r: collisions.geometry(b.description(r)), fast_runs)
        fast, mf = _time(lambda geo=geo: collisions.compute(geo, args.samples, args.seed), fast_runs)
        naive, mn = _time(lambda geo=geo: collisions.compute_naive(geo, args.samples, args.seed), naive_runs)
        same = mf.disabled == mn.disabled and mf.enabled == mn.enabled
        ratio = naive["cpu_median"] / fast["cpu_median"]
        rows.append({"example": stem, "robot": r.name, "dof": r.dof, "samples": args.samples, "seed": args.seed,
                     "load": load, "fast": fast, "naive": naive, "ratio_cpu": ratio,
                     "ratio_wall": naive["wall_median"] / fast["wall_median"], "same_matrix": same,
                     "stats": mf.stats, "naive_mesh_pairs": mn.stats.get("mesh_pairs"),
                     "reasons": {k: sum(p.reason == k for p in mf.disabled) for k in collisions.REASONS},
                     "enabled": len(mf.enabled)})
        print(
            f"{stem + '/' + r.name:<26}{r.dof:>4}{load['wall_median']:>8.3f}"
            f"{fast['wall_median']:>11.3f}{fast['cpu_median']:>10.3f}"
            f"{naive['wall_median']:>12.3f}{naive['cpu_median']:>11.3f}{ratio:>7.1f}x{mf.stats['exact_tests']:>8}"
            f"{'yes' if same else 'NO':>6}",
            file=out,
        )
    six = [x for x in rows if x["dof"] == 6]
    if six:
        worst = max(x["fast"]["cpu_median"] for x in six)
        verdict = "meets" if worst <= TARGET_S else "MISSES"
        ratios = ", ".join(f"{x['robot']} {x['ratio_cpu']:.1f}x" for x in six)
        print(f"6-DoF, {args.samples} samples: worst fast CPU {worst:.3f} s -> {verdict} the {TARGET_S} s target "
              f"(naive anchor / fast: {ratios})", file=out)
    doc = {"benchmark": "collisions", "target_s": TARGET_S, "cpu": cpu, "python": platform.python_version(),
           "platform": platform.platform(), "rows": rows}
    report(doc, None, args.json)
    return 0 if all(x["same_matrix"] for x in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
