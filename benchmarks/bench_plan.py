"""modc benchmark: `modc plan` (modc/plan). Not a test.

    python benchmarks/bench_plan.py              # farm (3-DoF) and a 6-DoF cell, 5 seeds each
    python benchmarks/bench_plan.py --quick      # 3 seeds, anchor on the first case only
    python benchmarks/bench_plan.py --json [OUT] # JSON document on stdout (table on stderr) or to OUT

Per case and seed, plan(FILE, TARGET, seed=s) end to end (read and check the file, build the
collision model, IK, path search, shortcuts, timing, clearance), on one core (the process is
pinned to one CPU and BLAS/OpenMP pools are set to one thread before numpy loads):

  fast    modc.plan as shipped: RRT-Connect searches with motion checks 4x coarser than
          certified, then every edge of its path is certified (and re-planned if it fails)
  anchor  the straightforward way: RRT-Connect checks every motion at the certified
          resolution from the start (planner.SEARCH_COARSENESS = 1)
  ratio   anchor / fast, of the median wall times over the seeds.

Both must produce valid plans; the median over seeds is the figure (RRT-Connect's effort
varies from seed to seed, so the spread is reported too). The second table breaks the fast
run down by phase (validity checks counted, not timed, are deterministic).
"""
from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMEXPR_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import platform  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

from _common import pin_one_core, report  # noqa: E402  (benchmarks/_common.py)

ROOT = Path(__file__).resolve().parent.parent
if (ROOT / "modc" / "__init__.py").is_file() and str(ROOT) not in sys.path[:1]:
    sys.path.insert(0, str(ROOT))

# A 6-DoF arm (the paper's Example A chain) on a table, with a wall between home and the target.
SIX_DOF = """robot a6 {
    chain H1 - H4(pivot=-90deg, port=15deg) - H4 - L1 - L4(pivot=15deg, port=90deg) - L2
    box table size (1.2, 1.2, 0.02) m at (0, 0, -0.011) m
    box wall size (0.04, 0.8, 0.5) m at (0.45, 0, 0.25) m
    target behind at (0.6, 0.1, 0.3) m
}
"""




def _cases(tmp: Path) -> list[tuple[str, Path, str]]:
    six = tmp / "a6.mod"
    six.write_text(SIX_DOF, encoding="utf-8")
    return [("farm/plant", ROOT / "examples" / "farm.mod", "plant"),
            ("farm/tray", ROOT / "examples" / "farm.mod", "tray"),
            ("a6/behind (6-DoF)", six, "behind")]


def _run(path: Path, target: str, seeds: list[int], coarseness: float) -> dict:
    from modc.plan import plan, planner

    saved = planner.SEARCH_COARSENESS
    planner.SEARCH_COARSENESS = coarseness
    try:
        walls, cpus, checks, durations = [], [], [], []
        for s in seeds:
            w, c = time.perf_counter(), time.process_time()
            p = plan(path, target, seed=s)
            walls.append(time.perf_counter() - w)
            cpus.append(time.process_time() - c)
            checks.append(p.stats["checks"])
            durations.append(p.duration)
    finally:
        planner.SEARCH_COARSENESS = saved
    return {"seeds": seeds, "wall": walls, "cpu": cpus, "checks": checks, "motion_s": durations,
            "wall_median": statistics.median(walls), "wall_min": min(walls), "wall_max": max(walls),
            "cpu_median": statistics.median(cpus), "checks_median": statistics.median(checks)}


def _phases(path: Path, target: str, seed: int) -> dict:
    """One fast run, timed by phase (wrappers around the package's functions, which plan_robot
    looks up on their modules at call time)."""
    import modc.plan as mp
    from modc.plan import collision, ik, planner

    times: dict[str, float] = {}

    def wrap(mod, name, label):
        f = getattr(mod, name)

        def g(*a, **k):
            t = time.perf_counter()
            try:
                return f(*a, **k)
            finally:
                times[label] = times.get(label, 0.0) + time.perf_counter() - t
        setattr(mod, name, g)
        return f

    originals = [wrap(collision, "CollisionChecker", "collision model"), wrap(ik, "solve", "IK"),
                 wrap(planner, "find_path", "path search + shortcuts")]
    t = time.perf_counter()
    try:
        mp.plan(path, target, seed=seed)
    finally:
        collision.CollisionChecker, ik.solve, planner.find_path = originals
    times["total"] = time.perf_counter() - t
    times["rest (file, timing, clearance)"] = times["total"] - sum(v for k, v in times.items() if k != "total")
    return times


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="3 seeds; the anchor on the first case only")
    ap.add_argument("--json", nargs="?", const="-", default=None, metavar="OUT")
    args = ap.parse_args(argv)

    cpu = pin_one_core()
    from modc.plan import plan  # noqa: F401  (imports outside the timings)

    seeds = list(range(3 if args.quick else 5))
    out = sys.stderr if args.json == "-" else sys.stdout
    rows = []
    with tempfile.TemporaryDirectory(prefix="modc-bench-plan-") as tmp:
        cases = _cases(Path(tmp))
        plan(cases[0][1], cases[0][2], seed=0)  # warm-up: imports, mesh cache
        print(f"modc plan, seeds {seeds[0]}..{seeds[-1]}, one core (cpu {cpu}); wall times in s "
              f"(median [min-max] over seeds)", file=out)
        print(f"{'case':<20}{'fast':>8}{'[min-max]':>16}{'checks':>9}{'motion s':>10}{'anchor':>9}{'checks':>9}"
              f"{'ratio':>8}", file=out)
        for k, (name, path, target) in enumerate(cases):
            fast = _run(path, target, seeds, 4.0)
            anchor = _run(path, target, seeds, 1.0) if (not args.quick or k == 0) else None
            ratio = anchor["wall_median"] / fast["wall_median"] if anchor else None
            rows.append({"case": name, "fast": fast, "anchor": anchor, "ratio_wall": ratio,
                         "phases": _phases(path, target, 0)})
            print(
                f"{name:<20}{fast['wall_median']:>8.3f}"
                f"{'[' + format(fast['wall_min'], '.2f') + '-' + format(fast['wall_max'], '.2f') + ']':>16}"
                f"{fast['checks_median']:>9.0f}{statistics.median(fast['motion_s']):>10.2f}"
                + (f"{anchor['wall_median']:>9.3f}{anchor['checks_median']:>9.0f}{ratio:>7.1f}x" if anchor else ""),
                file=out,
            )
        print("phases of the seed-0 fast run (s):", file=out)
        for r in rows:
            ph = ", ".join(f"{k} {v:.3f}" for k, v in r["phases"].items())
            print(f"  {r['case']:<20}{ph}", file=out)
    doc = {"benchmark": "plan", "cpu": cpu, "python": platform.python_version(), "platform": platform.platform(),
           "rows": rows}
    report(doc, None, args.json)
    return 0


if __name__ == "__main__":
    sys.exit(main())
