"""modc benchmark: the design search's IK (modc.design.reach.solve) on batches of oriented targets. Not a test.

    python benchmarks/bench_ik_oriented.py              # the table
    python benchmarks/bench_ik_oriented.py --quick      # one repetition
    python benchmarks/bench_ik_oriented.py --json [OUT]

The bare solve, as the screen calls it: 200 candidates of one chain (3, 4 and 6 units of the
mark2 library, settings spread over the chain's grid) x the targets x 4 seeds in one batch, towards
full poses (`rpy`: 6 residual rows), directions (`pointing`: position and tool0's x axis) and both
mixed with a position-only target; numpy (MODC_JIT=0) and compiled (modc.design.reach_jit_pose,
numba; its kernel loaded and compiled before timing), alternating, the smallest CPU time of
`--reps` each, this process pinned to one core. The two paths must return the same bits (checked:
a mismatch stops the run). "us/run" is CPU per IK run (one candidate, target and seed).

Figures (27 Nov 2026 12:29 UTC, load 2.0-2.2 on a 2-core machine shared with other jobs, one
core, best of 3; the numpy column is the path every oriented batch took before reach_jit_pose):

    chain          targets     runs  numpy s   jit s      x us/run np us/run jit
    1-4-3          rpy         1600    0.021   0.007    3.1      12.8        4.2
    1-4-3          pointing    2400    0.045   0.011    4.2      18.5        4.4
    1-4-3          mixed       4800    0.076   0.022    3.5      15.8        4.5
    4-3-4-3        rpy         1600    0.035   0.009    4.1      21.8        5.4
    4-3-4-3        pointing    2400    0.061   0.014    4.2      25.6        6.0
    4-3-4-3        mixed       4800    0.117   0.029    4.1      24.5        6.0
    4-3-4-3-4-3    rpy         1600    0.048   0.014    3.5      30.2        8.6
    4-3-4-3-4-3    pointing    2400    0.090   0.022    4.1      37.6        9.2
    4-3-4-3-4-3    mixed       4800    0.176   0.046    3.8      36.6        9.6
    total CPU s: numpy 0.67, compiled 0.17 (3.9x)

The kernel's first compile costs ~14 s CPU once per install (cached with reach_jit's, where
reach_jit._cache_dir says), loading it ~0.5 s per process. The compiled runs cost mostly the C
library's cos, sin, acos and atan2 and scalar arithmetic; views and calls are free there.
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _common import ROOT, pin_one_core, report  # noqa: E402

sys.path.insert(0, str(ROOT))

CELL = """design posed {
    target a at (0.30, 0.10, 0.25) m rpy (0, 90, 0) deg
    target b at (0.25, -0.15, 0.30) m pointing (0, 0, -1) within 0.5 mm, 1 deg
    target c at (0.10, 0.30, 0.45) m
    target d at (0.20, 0.0, 0.35) m pointing (1, 0, 0)
    target e at (0.35, 0.05, 0.15) m rpy (180, 0, 45) deg within 2 mm, 3 deg
    target f at (0.40, 0, 0.20) m pointing (0, 0, -1) within 5 mm, 5 deg
    units 1 to 6
}
"""
SETS = {"rpy": [0, 4], "pointing": [1, 3, 5], "mixed": [0, 1, 2, 3, 4, 5]}
CHAINS = [(1, 4, 3), (4, 3, 4, 3), (4, 3, 4, 3, 4, 3)]


def _spec():
    from modc.compiler import check_text
    from modc.design.evaluate import Spec

    c = check_text(CELL, "bench.mod")
    assert c.ok, c.diagnostics
    return Spec.of(c.design.problems[0])


def _batch(spec, kinds, count=200):
    from modc.design import settings
    from modc.design.batch import geometry
    from modc.design.space import Shape

    lib = spec.problem.cell.library
    n = len(kinds)
    ax = settings.axes(spec, Shape(kinds, (None,) * n))
    idx = np.linspace(0, ax.count - 1, min(count, ax.count)).astype(np.int64)
    piv, por = settings.settings_at(ax, n, idx)
    types = [lib.units[k] for k in kinds]
    tool = spec.problem.cell.tool
    return geometry(types, piv, por, [t.x23 for t in types], tool.xyz, tool.rpy)


def _timed(jit: bool, *args):
    from modc.design import reach

    os.environ["MODC_JIT"] = "1" if jit else "0"
    t = time.process_time()
    out = reach.solve(*args)
    return time.process_time() - t, out


def bench(reps: int) -> dict:
    from modc.design import reach

    spec = _spec()
    rows = []
    for kinds in CHAINS:
        n = len(kinds)
        g = _batch(spec, kinds)
        lo, hi = np.full(n, spec.lower), np.full(n, spec.upper)
        q0 = reach.seeds(n, 4, lo, hi, 0)
        for name, which in SETS.items():
            tg = spec.targets.take(np.array(which))
            args = (g, tg, q0, lo, hi)
            _timed(True, *args)  # numba's import, the kernel's compile or cache load
            cpu: dict[str, list[float]] = {"numpy": [], "jit": []}
            outs = {}
            for _ in range(reps):
                for path in cpu:
                    s, outs[path] = _timed(path == "jit", *args)
                    cpu[path].append(s)
            if not all(np.array_equal(a, b) for a, b in zip(outs["numpy"], outs["jit"], strict=True)):
                raise SystemExit(f"the compiled IK differs from numpy's on {kinds} {name}")
            runs = outs["numpy"][1].size
            hit = (outs["numpy"][1] <= tg.tol_p[None, :, None]) & (outs["numpy"][2] <= tg.tol_r[None, :, None])
            rows.append({"chain": "-".join(map(str, kinds)), "targets": name, "runs": runs,
                         "numpy_cpu_s": min(cpu["numpy"]), "jit_cpu_s": min(cpu["jit"]),
                         "all_cpu_s": cpu, "hits": int(hit.sum())})
    return {"rows": rows, "reps": reps, "load_average": os.getloadavg()}


def _table(doc: dict) -> str:
    lines = [f"{'chain':14} {'targets':9} {'runs':>6} {'numpy s':>8} {'jit s':>7} {'x':>6} "
             f"{'us/run np':>9} {'us/run jit':>10} {'hits':>5}"]
    for r in doc["rows"]:
        lines.append(f"{r['chain']:14} {r['targets']:9} {r['runs']:6d} {r['numpy_cpu_s']:8.3f} {r['jit_cpu_s']:7.3f} "
                     f"{r['numpy_cpu_s'] / max(r['jit_cpu_s'], 1e-9):6.1f} {1e6 * r['numpy_cpu_s'] / r['runs']:9.1f} "
                     f"{1e6 * r['jit_cpu_s'] / r['runs']:10.1f} {r['hits']:5d}")
    total = [sum(r[k] for r in doc["rows"]) for k in ("numpy_cpu_s", "jit_cpu_s")]
    lines.append(f"total CPU s: numpy {total[0]:.2f}, compiled {total[1]:.2f} ({total[0] / total[1]:.1f}x); "
                 f"best of {doc['reps']}; load {doc['load_average'][0]:.2f}; core {doc.get('core')}")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="one repetition")
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--json", nargs="?", const="-", default=None, metavar="OUT")
    args = ap.parse_args()
    core = pin_one_core()
    doc = bench(1 if args.quick else args.reps)
    doc["core"] = core
    report(doc, _table(doc), args.json)


if __name__ == "__main__":
    main()
