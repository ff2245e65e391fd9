"""modc benchmark: task-based design (`modc design`, modc/design). Not a test.

    python benchmarks/bench_design.py                 # all three measurements, Timor if installed
    python benchmarks/bench_design.py --quick         # fewer candidates and designs
    python benchmarks/bench_design.py --timor ROOT    # Timor's venv from shared/tools/timor-offline.sh
    python benchmarks/bench_design.py --json [OUT]

On one core (the process is pinned to one CPU, BLAS/OpenMP pools set to one thread), CPU time
(time.process_time), so that other load on the machine does not count:

1. candidate   modc's screen of candidate chains with three targets (the work the search does per
               twist setting): batched IK from 4 seeds per target within the joint limits, then the
               obstacle screen, over 512 candidates of one 3-unit shape; CPU ms per candidate. Two
               mixes: random twist settings (most leave at the first target they miss, as in the
               search) and the worst case, where every candidate solves all three targets.
               Also the exact check of one design (modc.design.evaluate.verify: compile checks,
               torque analysis, coal collision model), which the search runs only on the few
               chains it ranks.
2. solve       `modc design`'s search (run.design, top 1) on a cell with three position targets
               and at most 3 modules, from the start: wall and CPU seconds.
3. anchor      Timor-python 1.1.1 (TUM) in its own venv, raced side by side: per design, assemble
               a 3-DoF serial chain from its geometric_primitive_modules set, build its pinocchio
               robot and solve IK for three targets (each the FK of a random pose, so reachable),
               CPU ms per design over random module chains.

The ratio is Timor's ms per design over modc's ms per candidate.
"""
from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMEXPR_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse  # noqa: E402
import json  # noqa: E402
import platform  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402

from _common import pin_one_core  # noqa: E402  (benchmarks/_common.py)

ROOT = Path(__file__).resolve().parent.parent
if (ROOT / "modc" / "__init__.py").is_file() and str(ROOT) not in sys.path[:1]:
    sys.path.insert(0, str(ROOT))

# Three position targets in a cell with a shelf and a post: a 3-module problem.
CELL = """design bench {
    payload 100 g
    box shelf size (0.6, 0.4, 0.02) m at (0.3, 0, 0.05) m
    box post size (0.05, 0.05, 0.6) m at (0.15, 0.3, 0.3) m
    target a at (0.30, 0.10, 0.25) m
    target b at (0.25, -0.15, 0.30) m
    target c at (0.10, 0.30, 0.45) m
    units 2 to 3
}
"""

TIMOR = r"""
import sys, time, json
sys.path.insert(0, sys.argv[1])
import timor_offline  # noqa: F401  (stubs the module-database lookup timor makes at import)
import numpy as np
from timor import ModulesDB, ModuleAssembly
from timor.task import Tolerance
from timor.utilities.tolerated_pose import ToleratedPose

designs = int(sys.argv[2])
db = ModulesDB.from_name('geometric_primitive_modules')
links = ['i_15', 'i_30', 'i_45', 'l_15', 'l_30', 'l_45']
rng = np.random.default_rng(0)
tol = Tolerance.CartesianXYZ(*[[-0.005, 0.005]] * 3)
phases = {'assembly': 0.0, 'robot': 0.0, 'ik': 0.0}
solved = 0
for k in range(designs + 1):
    chain = ['base', 'J2', links[rng.integers(6)], 'J2', links[rng.integers(6)], 'J2', 'eef']
    t0 = time.process_time()
    A = ModuleAssembly.from_serial_modules(db, chain)
    t1 = time.process_time()
    robot = A.to_pin_robot()
    t2 = time.process_time()
    goals = [robot.fk(rng.uniform(-np.pi, np.pi, robot.dof)) for _ in range(3)]
    t3 = time.process_time()
    for T in goals:
        q, ok = robot.ik(ToleratedPose(T, tolerance=tol), q_init=np.zeros(robot.dof))
        solved += bool(ok)
    t4 = time.process_time()
    if k:  # the first design warms caches up
        phases['assembly'] += t1 - t0
        phases['robot'] += t2 - t1
        phases['ik'] += t4 - t3
total = sum(phases.values())
print(json.dumps({'designs': designs, 'ms_per_design': 1e3 * total / designs,
                  'phases_ms': {k: 1e3 * v / designs for k, v in phases.items()}, 'ik_solved': solved}))
"""


def problem():
    from modc.compiler import check_text

    c = check_text(CELL, "bench.mod")
    assert c.ok, c.diagnostics
    return c.design.problems[0]


def bench_candidates(count: int) -> dict:
    """Two mixes: random twist settings of one shape (most leave at the first, hardest target,
    as in the search), and the worst case, every candidate solving all three targets (the farm
    arm's twists, with targets it reaches)."""
    import numpy as np

    from modc import api
    from modc.compiler import check_text
    from modc.design.evaluate import Candidate, Spec, screen_batch, verify
    from modc.design.space import Shape, twist_values
    from modc.kinematics import Chain

    p = problem()
    spec = Spec.of(p)
    lib = p.cell.library
    rng = np.random.default_rng(1)
    piv, port = twist_values(lib.twists.pivot), twist_values(lib.twists.port)
    shape = Shape((1, 4, 3), (None, None, None))
    pivots = piv[rng.integers(len(piv), size=(count, 3))]
    ports = port[rng.integers(len(port), size=(count, 3))]
    ports[:, 0] = ports[:, 2] = 0.0
    screen_batch(spec, shape, pivots[:8], ports[:8], 0)  # warm up (imports, caches)
    t = time.process_time()
    s = screen_batch(spec, shape, pivots, ports, 0)
    cpu = time.process_time() - t
    out = {"candidates": count, "targets": 3, "ms_per_candidate": 1e3 * cpu / count, "feasible": int(s.feasible.sum())}

    farm = api.load(ROOT / "examples" / "farm.mod")
    chain = Chain(farm)
    goals = [chain.T_base_tool(q)[:3, 3] for q in np.radians([[30, -40, 70], [-60, 20, -90], [100, -70, 40]])]
    text = "design reach {\n    tool at (0.06, 0, 0) m\n    payload 50 g at (0.01, 0, 0) m\n" + "".join(
        f"    target g{k} at ({x:.9f}, {y:.9f}, {z:.9f}) m\n" for k, (x, y, z) in enumerate(goals)) + "    units 3\n}\n"
    c = check_text(text, "reach.mod")
    assert c.ok, c.diagnostics
    reach_problem = c.design.problems[0]
    rspec = Spec.of(reach_problem)
    fshape = Shape((1, 4, 3), (None, None, 0.18))
    fp = np.tile([[u.pivot for u in farm.units]], (count, 1))
    fo = np.tile([[u.port for u in farm.units]], (count, 1))
    screen_batch(rspec, fshape, fp[:8], fo[:8], 0)
    t = time.process_time()
    s2 = screen_batch(rspec, fshape, fp, fo, 0)
    out["ms_per_candidate_all_targets"] = 1e3 * (time.process_time() - t) / count
    out["feasible_all_targets"] = int(s2.feasible.sum())
    if s2.feasible.any():
        sols = tuple(tuple(tuple(float(x) for x in q) for q in per) for per in s2.solutions[0])
        cand = Candidate(fshape, ("H", "L", "L"), tuple(fp[0]), tuple(fo[0]), sols)
        verify(reach_problem, cand)  # warm up: imports, the collision matrix cache
        t = time.process_time()
        v = verify(reach_problem, cand)
        out["verify_ms"] = 1e3 * (time.process_time() - t)
        out["verify_result"] = "accepted" if not isinstance(v, str) else v
    return out


def bench_solve() -> dict:
    from modc.design import run

    p = problem()
    t, c = time.perf_counter(), time.process_time()
    o = run.design(p, top=1, seed=0)
    wall, cpu = time.perf_counter() - t, time.process_time() - c
    best = o.designs[0].chain() if o.designs else None
    return {"seconds_wall": wall, "seconds_cpu": cpu, "evaluated": o.evaluated, "shapes": o.shapes, "best": best,
            "modules": o.designs[0].modules if o.designs else None}


def bench_timor(root: Path, designs: int) -> dict | None:
    py = root / "venv" / "bin" / "python"
    if not py.is_file():
        return None
    env = dict(os.environ, HOME=str(root / "home"))
    p = subprocess.run([str(py), "-c", TIMOR, str(root), str(designs)], capture_output=True, text=True, env=env,
                       timeout=1800)
    if p.returncode != 0:
        return {"error": p.stderr.strip().splitlines()[-1] if p.stderr.strip() else f"exit {p.returncode}"}
    return json.loads(p.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--timor", default=os.environ.get("TIMOR_ROOT", "/tmp/timor-offline"),
                    help="the ROOT given to shared/tools/timor-offline.sh")
    ap.add_argument("--json", nargs="?", const="-", default=None)
    args = ap.parse_args()
    core = pin_one_core()
    warnings.simplefilter("ignore")
    result = {"machine": platform.processor() or platform.machine(), "python": platform.python_version(), "core": core}
    result["candidate"] = bench_candidates(128 if args.quick else 512)
    result["solve"] = bench_solve()
    result["anchor"] = bench_timor(Path(args.timor), 10 if args.quick else 40)
    c, s, a = result["candidate"], result["solve"], result["anchor"]
    lines = [f"candidate  {c['ms_per_candidate']:.3f} ms CPU per candidate ({c['targets']} targets, {c['candidates']} "
             f"random twist settings, {c['feasible']} feasible); {c['ms_per_candidate_all_targets']:.3f} ms when "
             f"every candidate solves all 3 ({c['feasible_all_targets']} feasible); exact check of one design "
             f"{c.get('verify_ms', float('nan')):.0f} ms ({c.get('verify_result')})",
             f"solve      {s['seconds_wall']:.1f} s wall, {s['seconds_cpu']:.1f} s CPU, "
             f"{s['evaluated']:,} evaluated over "
             f"{s['shapes']} shapes; best {s['best']}"]
    if a and "ms_per_design" in a:
        ratio = a["ms_per_design"] / c["ms_per_candidate"]
        worst = a["ms_per_design"] / c["ms_per_candidate_all_targets"]
        result["ratio"], result["ratio_all_targets"] = ratio, worst
        phases = ", ".join(f"{k} {v:.1f} ms" for k, v in a["phases_ms"].items())
        lines.append(f"anchor     Timor {a['ms_per_design']:.1f} ms CPU per 3-DoF design with 3 targets ({phases}; "
                     f"{a['ik_solved']}/{3 * a['designs']} IK solved)")
        lines.append(f"ratio      {ratio:.0f}x (Timor per design / modc per candidate); {worst:.0f}x against modc's "
                     "worst case")
    else:
        lines.append(f"anchor     Timor not measured: {a or 'not installed (run shared/tools/timor-offline.sh)'}")
    print("\n".join(lines), file=sys.stderr)
    if args.json is not None:
        text = json.dumps(result, indent=2)
        if args.json == "-":
            print(text)
        else:
            Path(args.json).write_text(text + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
