"""modc benchmark: task-based design (`modc design`, modc/design). Not a test.

    python benchmarks/bench_design.py                 # everything, Timor if installed
    python benchmarks/bench_design.py --quick         # smaller samples, no whole-library run
    python benchmarks/bench_design.py --solve         # only measurements 1-2 and the JIT's cost (with --quick too)
    python benchmarks/bench_design.py --timor ROOT    # ROOT: a venv with timor-python installed (ROOT/bin/python)
    python benchmarks/bench_design.py --json [OUT]
    python benchmarks/bench_design.py --beyond 4 [5 6]   # only measurement 7, units 1-4 [1-5, 1-6]

CPU figures are time.process_time() of this process pinned to one core (BLAS/OpenMP pools at one
thread), so other load on the machine does not count; wall figures are time.perf_counter().

1. candidate   per twist setting, what the search does (search.search_shape over every setting
               of one 3-unit shape, three position targets, a shelf and a post): its family
               bounds (plan), the sound reach bounds on every setting, batched IK (4 seeds, within
               the limits) and the obstacle screen on those the bounds keep. CPU ms = the shape's
               CPU time / its settings (a first call on another range warms imports up and is not
               counted). Per screened setting = the same CPU time (bounds included) / the
               settings that reached the IK: the goal's figure (<= 0.1 ms). The hardest range
               (4-4-3: most settings pass the bounds, many solve all targets) likewise, and the
               case where every candidate solves all three (the farm arm's twists, repeated).
               The IK runs compiled (numba, modc/design/reach_jit.py, when installed); the whole
               shape again with the numpy path (MODC_JIT=0) gives "with the numpy IK".
   reference   the same screen written plainly: one candidate at a time, numpy on small arrays
               (docs/conventions.md FK, DLS from the same 4 seeds, 40 iterations, the first target
               missed ends it), no bounds, no batching: CPU ms per candidate.
2. solve       run.design on the three-target cell with at most 3 modules, --top 5 (the command
               line's default, the goal's figure) and --top 1: CPU s. --top 5 runs with the compiled
               IK and with the numpy path (MODC_JIT=0), alternating, twice each (once with --quick):
               the smaller CPU time of each; the process has loaded numba already (a fresh
               `modc design` loads it once it has solved 50,000 IK runs: the "jit" line's cost).
   jit         numba's import and the kernel's first call in a fresh process: with an empty cache
               (the compile, once per install) and with the cache (every process that switches).
3. complete    run.design on a cell where nothing is feasible, units 1 to 3, every unit type:
               every setting of every shape screened or excluded (CPU s, settings, excluded).
4. library     `modc design --workers 2` on two cells nothing can serve, units 1 to 6, every unit
               type: targets below a floor, and targets about 2 m out (inside every offset laid
               end to end, beyond every setting's reach): wall s (a subprocess on two cores). And the per-shape CPU of
               six-unit shapes on a cell the bounds cannot close (sampled), extrapolated to the
               whole space on 2 workers.
5. dask        units of work (five-unit shapes of the three-target cell) on a Dask LocalCluster of 1 and 2
               single-thread worker processes: wall s, and the extrapolation to 64 workers.
6. task        benchmarks/bench_task.py's goals (a 4-goal visit task <= 60 s, a 12-point region
               <= 30 s CPU) and benchmarks/bench_task_base.py's base placement (1 pose vs 25).
7. anchor      Timor-python 1.1.1 (TUM) in its own venv: per design, assemble a 3-DoF chain
               from geometric_primitive_modules, build its pinocchio robot, IK for three targets
               (each the FK of a random pose); the first (warm-up) design counts in nothing.
7. beyond      two targets 0.86 m out, beyond every 3-unit setting (a sound bound), within reach
               of 4-unit arms (77 shapes of 256 keep live families): run.design (top 3) with
               units 1-4 in this process (CPU and wall s), and with --beyond 5 / 6 units 1-5 / 1-6
               through `modc design --workers 2` (wall s); complete or not, shapes on the coarse
               grid, settings through the IK, excluded by bounds, of those dominated (shapes
               searched by level, modc.design.dominance). Date and load average recorded.
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
        solved += bool(ok) and k > 0  # the warm-up design counts in nothing
    t4 = time.process_time()
    if k:  # the first design warms caches up
        phases['assembly'] += t1 - t0
        phases['robot'] += t2 - t1
        phases['ik'] += t4 - t3
total = sum(phases.values())
print(json.dumps({'designs': designs, 'ms_per_design': 1e3 * total / designs,
                  'phases_ms': {k: 1e3 * v / designs for k, v in phases.items()}, 'ik_solved': solved}))
"""


NOTHING = """design nothing {
    box shelf size (0.6, 0.4, 0.02) m at (0.3, 0, 0.05) m
    target a at (0.95, 0.25, 0.35) m
    target b at (-0.30, 0.25, 0.10) m
    units 1 to 3
}
"""

# Two targets about 2 m out: within every offset laid end to end of the longest six-unit chains
# (2.24 m), beyond what any of their twist settings reaches (at most 1.83 m).
FAR = """design far {
    target a at (1.90, 0.35, 0.40) m
    target b at (-1.20, 1.50, 0.30) m
    units 1 to 6
}
"""

WALLED = """design walled {
    box floor size (6, 6, 0.03) m at (0, 0, -0.02) m
    target a at (0.30, 0.10, -0.25) m
    target b at (0.25, -0.15, -0.30) m
    units 1 to 6
}
"""


def _problem(text: str):
    from modc.compiler import check_text

    c = check_text(text, "bench.mod")
    assert c.ok, c.diagnostics
    return c.design.problems[0]


def problem():
    return _problem(CELL)


def bench_candidates(count: int) -> dict:
    import numpy as np

    from modc import api
    from modc.design import search
    from modc.design.evaluate import Candidate, Spec, screen_batch, verify
    from modc.design.space import Shape
    from modc.kinematics import Chain

    spec = Spec.of(problem())
    whole = Shape((1, 4, 3), (None, None, None))
    _path(True)
    search.search_part(spec, whole, ((0, 256),), 0)  # warm up (imports, caches, numba's kernel)
    t = time.process_time()
    res = search.search_shape(spec, whole, 0)
    cpu = time.process_time() - t
    out = {"shape": whole.label(), "settings": res.evaluated, "targets": 3,
           "ms_per_candidate": 1e3 * cpu / res.evaluated, "screened": res.screened, "excluded": res.excluded,
           "ms_per_screened": 1e3 * cpu / max(res.screened, 1)}
    _path(False)  # the numpy path on the same shape (MODC_JIT=0)
    t = time.process_time()
    search.search_shape(spec, whole, 0)
    out["numpy_ms_per_screened"] = 1e3 * (time.process_time() - t) / max(res.screened, 1)
    _path(True)
    # the hardest range met: most settings of 4-4-3 there pass the bounds and many solve all targets
    shape = Shape((4, 4, 3), (None, None, None))
    lo = search.size(spec, shape) // 3
    t = time.process_time()
    part = search.search_part(spec, shape, ((lo, lo + count),), 0)
    cpu = time.process_time() - t
    out["hard"] = {"shape": shape.label(), "settings": count, "ms_per_candidate": 1e3 * cpu / count,
                   "screened": part.screened, "excluded": part.excluded,
                   "ms_per_screened": 1e3 * cpu / max(part.screened, 1)}
    out["load_average"] = os.getloadavg()  # CPU time is this process's, but a busy machine still slows it

    farm = api.load(ROOT / "examples" / "farm.mod")
    chain = Chain(farm)
    goals = [chain.T_base_tool(q)[:3, 3] for q in np.radians([[30, -40, 70], [-60, 20, -90], [100, -70, 40]])]
    text = "design reach {\n    tool at (0.06, 0, 0) m\n    payload 50 g at (0.01, 0, 0) m\n" + "".join(
        f"    target g{k} at ({x:.9f}, {y:.9f}, {z:.9f}) m\n" for k, (x, y, z) in enumerate(goals)) + "    units 3\n}\n"
    reach_problem = _problem(text)
    rspec = Spec.of(reach_problem)
    fshape = Shape((1, 4, 3), (None, None, 0.18))
    n_all = min(count, 1024)
    fp = np.tile([[u.pivot for u in farm.units]], (n_all, 1))
    fo = np.tile([[u.port for u in farm.units]], (n_all, 1))
    screen_batch(rspec, fshape, fp[:8], fo[:8], 0)
    t = time.process_time()
    s2 = screen_batch(rspec, fshape, fp, fo, 0)
    out["ms_per_candidate_all_targets"] = 1e3 * (time.process_time() - t) / n_all
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


def bench_reference(count: int) -> dict:
    """The plain per-candidate screen (see the module's docstring), on the same shape and range."""
    import numpy as np

    from modc.design import search, settings
    from modc.design.evaluate import Spec
    from modc.design.reach import seeds
    from modc.design.space import Shape
    from modc.kinematics import A_t1, A_t2, homogeneous

    spec = Spec.of(problem())
    lib = spec.problem.cell.library
    shape = Shape((4, 4, 3), (None, None, None))
    ax = settings.axes(spec, shape)
    lo = search.size(spec, shape) // 3
    piv, por = settings.range_settings(ax, 3, lo, lo + count)
    units = [lib.units[k] for k in shape.kinds]
    limit = np.full(3, spec.upper)
    q0 = seeds(3, 4, -limit, limit, 0)
    order = np.argsort(-np.linalg.norm(spec.targets.xyz, axis=1), kind="stable")

    def fk(fixed, q):
        T = np.eye(4)
        points = []
        for (pre, post), th in zip(fixed, q, strict=True):
            T = T @ pre
            c, s = np.cos(th), np.sin(th)
            T = T @ homogeneous(np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]), (0.0, 0.0, 0.0))
            points.append((T[:3, 3].copy(), T[:3, 2].copy()))
            T = T @ post
        return T[:3, 3], points

    feasible = 0
    t = time.process_time()
    for c in range(count):
        fixed = [(A_t1(piv[c, i], u.x01, u.z01) @ homogeneous(np.eye(3), (0.0, 0.0, u.z12)),
                  A_t2(por[c, i], u.x23) if u.link else np.eye(4)) for i, u in enumerate(units)]
        ok = True
        for ti in order:
            x, tol = spec.targets.xyz[ti], spec.targets.tol_p[ti]
            reached = False
            for q in q0:
                q, lam = q.copy(), 1e-2
                p, pts = fk(fixed, q)
                err = np.linalg.norm(x - p)
                for _ in range(40):
                    if err < 1e-7:
                        break
                    J = np.stack([np.cross(z, p - o) for o, z in pts], -1)
                    dq = np.linalg.solve(J.T @ J + lam * np.eye(3), J.T @ (x - p))
                    qn = np.clip(q + dq, -limit, limit)
                    pn, ptsn = fk(fixed, qn)
                    errn = np.linalg.norm(x - pn)
                    if errn < err:
                        q, p, pts, err, lam = qn, pn, ptsn, errn, max(lam / 3, 1e-9)
                    else:
                        lam *= 4
                reached |= err <= tol
                if reached:
                    break
            if not reached:
                ok = False
                break
        feasible += ok
    cpu = time.process_time() - t
    return {"settings": count, "ms_per_candidate": 1e3 * cpu / count, "feasible_before_obstacles": feasible}


def _design(text: str, **kw) -> dict:
    from modc.design import run

    p = _problem(text)
    t, c = time.perf_counter(), time.process_time()
    o = run.design(p, **kw)
    wall, cpu = time.perf_counter() - t, time.process_time() - c
    return {"seconds_wall": wall, "seconds_cpu": cpu, "evaluated": o.evaluated, "excluded": o.excluded,
            "shapes": o.shapes, "complete": o.complete, "best": o.designs[0].chain() if o.designs else None,
            "why_none": None if o.designs else o.why_none()}


def _path(jit: bool):
    """Run the screen's IK compiled (numba: modc.design.reach_jit) or in numpy from now on."""
    os.environ["MODC_JIT"] = "1" if jit else "0"


def bench_solve(reps: int) -> dict:
    """The three-target cell with --top 5 (the command line's default: the goal's figure) and --top 1,
    with the compiled IK and with the numpy path (MODC_JIT=0), alternating, reps times each: the
    smallest CPU time of each (the same ranking: the two paths return the same bits)."""
    runs: dict[str, list[dict]] = {"jit": [], "numpy": []}
    for _ in range(reps):
        for name in runs:
            _path(name == "jit")
            runs[name].append(_design(CELL, top=5, seed=0))
    _path(True)
    best = {k: min(v, key=lambda r: r["seconds_cpu"]) for k, v in runs.items()}
    assert best["jit"]["best"] == best["numpy"]["best"]
    return {**best["jit"], "numpy": best["numpy"], "all_cpu_s": {k: [r["seconds_cpu"] for r in v] for k, v in
                                                                  runs.items()},
            "top_1": _design(CELL, top=1, seed=0), "load_average": os.getloadavg()}


JIT_COST = r"""
import sys, time
t = time.process_time()
import numpy as np
from modc.design import reach_jit
t1 = time.process_time()
C, n = 4, 3
reach_jit.solve_position(np.tile(np.eye(4), (C, n + 1, 1, 1)), np.arange(C), np.zeros(C, int), np.ones((1, 3)),
                         np.full(C, 0.01), np.zeros((n, C)), -np.ones(n), np.ones(n), 40, 5, 0.5, 1e-2)
print(t1 - t, time.process_time() - t1)
"""


def bench_jit_cost() -> dict | None:
    """What the compiled path costs a process: numba's import and the kernel's first call, with an
    empty cache (the compile, once per install) and then with the cache (every process that
    switches to it: modc.design.reach.jit)."""
    import tempfile

    from _common import child_env

    try:
        import numba  # noqa: F401
    except ImportError:
        return None
    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name in ("cold", "cached"):
            p = subprocess.run([sys.executable, "-c", JIT_COST], capture_output=True, text=True,
                               env=dict(child_env(), NUMBA_CACHE_DIR=tmp), check=True)
            imp, first = (float(x) for x in p.stdout.split())
            out[name] = {"import_s": imp, "first_call_s": first}
    return out


def bench_complete() -> dict:
    return _design(NOTHING, top=1, seed=0)


def bench_library(sample: int, whole: bool) -> dict:
    """The walled cell through the command line on two cores; six-unit shapes of a cell the
    bounds cannot close, sampled on this core."""
    import tempfile

    import numpy as np
    from _common import child_env

    from modc.design import search, space
    from modc.design.evaluate import Spec

    out: dict = {}
    if whole:
        all_cpus = os.sched_getaffinity(0) | set(range(os.cpu_count() or 1))
        for name, text in (("walled", WALLED), ("far", FAR)):
            with tempfile.TemporaryDirectory() as tmp:
                src = Path(tmp) / f"{name}.mod"
                src.write_text(text, encoding="utf-8")
                t = time.perf_counter()
                p = subprocess.run([sys.executable, "-m", "modc", "design", str(src), "-o", str(Path(tmp) / "out"),
                                    "--workers", "2", "-q", "--no-render"], capture_output=True, text=True,
                                   env=child_env(), preexec_fn=lambda: os.sched_setaffinity(0, all_cpus),
                                   timeout=3600)
                out[f"{name}_workers2_wall_s"] = time.perf_counter() - t
                out[f"{name}_exit"] = p.returncode
                out[f"{name}_message"] = next((ln for ln in p.stderr.splitlines() if "no-design" in ln),
                                              p.stderr[-300:])
    prob = _problem(NOTHING.replace("units 1 to 3", "units 6"))
    spec = Spec.of(prob)
    shapes = space.shapes(prob, 6)
    rng = np.random.default_rng(0)
    pick = [shapes[i] for i in sorted(rng.choice(len(shapes), size=sample, replace=False))]
    search.search_shape(spec, pick[0], 0)
    t = time.process_time()
    settings = 0
    for s in pick:
        settings += search.search_shape(spec, s, 0).evaluated
    per_shape = (time.process_time() - t) / sample
    n_all = sum(len(space.shapes(_problem(NOTHING.replace("units 1 to 3", f"units {n}")), n)) for n in range(2, 7))
    out.update({"six_unit_sample": sample, "six_unit_cpu_s_per_shape": per_shape,
                "six_unit_settings_per_shape": settings / sample, "shapes_in_library": n_all,
                "extrapolated_library_wall_s_2_workers": per_shape * n_all / 2})
    return out


def bench_dask(shapes: int) -> dict | None:
    try:
        import distributed
    except ImportError:
        return None
    from modc.design import search, space
    from modc.design.evaluate import Spec

    # five-unit shapes of the three-target cell: targets in reach, so each unit is real work (a cell
    # the family bounds close would time only the scheduling)
    prob = _problem(CELL.replace("units 2 to 3", "units 5"))
    spec = Spec.of(prob)
    # shapes whose plan leaves settings to screen (searched by level or in full: most 5-unit
    # shapes of this cell are complete by dominance now, none on the coarse grid), `shapes` of them
    work: list = []
    picked = 0
    for s in space.shapes(prob, 5)[::-1]:
        units = [w for w in search.parts_of(spec, s) if any(b > a for a, b in w[1])]
        if units:
            work += units
            picked += 1
        if picked == shapes:
            break
    out: dict = {"tasks": len(work)}
    for n in (1, 2):
        with distributed.LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                      dashboard_address=None) as cluster, distributed.Client(cluster) as client:
            ex = client.get_executor()
            list(ex.map(search.search_chunk, [spec], [[work[0]]], [0]))  # warm up the workers
            t = time.perf_counter()
            list(ex.map(search.search_chunk, [spec] * len(work), [[w] for w in work], [0] * len(work)))
            out[f"wall_s_{n}_workers"] = time.perf_counter() - t
    per_task = out["wall_s_1_workers"] / len(work)
    out["per_task_s"] = per_task
    out["speedup_2"] = out["wall_s_1_workers"] / out["wall_s_2_workers"]
    # a 4,096-shape tier: one range per coarse shape, rounds of 512 -> 8 tasks per worker per round
    out["extrapolated_4096_shapes_64_workers_s"] = 4096 * per_task / 64
    return out


# Two targets 0.86 m out: every 3-unit twist setting falls short (the family bounds exclude them
# all), 4-unit arms with links reach them (dominance.py: their shapes are searched by level).
BEYOND = """design beyond3 {
    payload 100 g
    target a at (0.714, 0.294, 0.378) m
    target b at (-0.255, 0.765, 0.298) m
    units 1 to 4
}
"""


def bench_beyond(highest: list[int]) -> dict:
    import tempfile

    from _common import child_env

    out: dict = {"date_utc": time.strftime("%Y-%m-%d %H:%M", time.gmtime()), "load_average": os.getloadavg()}
    all_cpus = os.sched_getaffinity(0) | set(range(os.cpu_count() or 1))
    for hi in highest:
        text = BEYOND.replace("units 1 to 4", f"units 1 to {hi}")
        if hi <= 4:
            from modc.design import run

            t, c = time.perf_counter(), time.process_time()
            o = run.design(_problem(text), top=3, seed=0)
            out[f"units_1_{hi}"] = {
                "seconds_wall": time.perf_counter() - t, "seconds_cpu": time.process_time() - c, "workers": 1,
                "complete": o.complete, "coarse_shapes": len(o.coarse), "shapes": o.shapes,
                "through_ik": o.evaluated - o.excluded, "excluded": o.excluded, "dominated": o.dominated,
                "best": o.designs[0].chain() if o.designs else None}
            continue
        with tempfile.TemporaryDirectory() as tmp:
            src = Path(tmp) / "beyond.mod"
            src.write_text(text, encoding="utf-8")
            t = time.perf_counter()
            p = subprocess.run([sys.executable, "-m", "modc", "design", str(src), "-o", str(Path(tmp) / "out"),
                                "--workers", "2", "-q", "--no-render", "--top", "3"], capture_output=True, text=True,
                               env=child_env(), preexec_fn=lambda: os.sched_setaffinity(0, all_cpus), timeout=7200)
            wall = time.perf_counter() - t
            js = Path(tmp) / "out" / "ranking.json"
            r = json.loads(js.read_text(encoding="utf-8")) if js.is_file() else {}
        out[f"units_1_{hi}"] = {
            "seconds_wall": wall, "workers": 2, "exit": p.returncode, "complete": r.get("complete"),
            "coarse_shapes": len(r.get("coarse_shapes", [])), "through_ik": r.get("evaluated", 0)
            - r.get("excluded_by_bounds", 0), "excluded": r.get("excluded_by_bounds"), "dominated": r.get("dominated"),
            "best": r["designs"][0]["chain"] if r.get("designs") else None}
    return out


def _beyond_lines(b: dict) -> list[str]:
    lines = [f"beyond     run of {b['date_utc']} UTC, load average {', '.join(f'{x:.1f}' for x in b['load_average'])}"]
    for k, v in b.items():
        if not k.startswith("units_"):
            continue
        cpu = f", {v['seconds_cpu']:.1f} s CPU" if "seconds_cpu" in v else ""
        lines.append(f"beyond     {k[6:].replace('_', '-')}: {v['seconds_wall']:.1f} s wall{cpu} ({v['workers']} "
                     f"worker(s)), complete={v['complete']}, {v['coarse_shapes']} coarse shapes; settings "
                     f"through the IK {v['through_ik']:,}, excluded {v['excluded']:,} (dominated "
                     f"{v['dominated']:,}); best {v['best']}")
    return lines


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


def _screen_lines(result: dict) -> list[str]:
    """The lines of measurements 1-2 and the JIT's cost."""
    c, r, s = (result[x] for x in ("candidate", "reference", "solve"))
    h = c["hard"]
    lines = [f"candidate  {c['ms_per_candidate']:.4f} ms CPU per twist setting ({c['targets']} targets, all "
             f"{c['settings']:,} settings of {c['shape']}: {c['excluded']:,} excluded by the bounds, {c['screened']:,} "
             f"screened = {c['ms_per_screened']:.3f} ms each, {c['numpy_ms_per_screened']:.3f} ms with the numpy "
             f"IK); hardest range ({h['settings']:,} of {h['shape']}, "
             f"{h['screened']:,} screened): {h['ms_per_screened']:.3f} ms each; "
             f"{c['ms_per_candidate_all_targets']:.3f} ms when every candidate solves all 3; exact check of one "
             f"design {c.get('verify_ms', float('nan')):.0f} ms; "
             f"load average {', '.join(f'{x:.1f}' for x in c['load_average'])}",
             f"reference  {r['ms_per_candidate']:.2f} ms CPU per candidate, plain numpy one at a time "
             f"({r['settings']} settings): {r['ms_per_candidate'] / c['ms_per_candidate']:.0f}x modc",
             f"solve      3 targets, <= 3 modules, --top 5: {s['seconds_cpu']:.1f} s CPU "
             f"({s['seconds_wall']:.1f} s wall; goal 10 s; numpy IK {s['numpy']['seconds_cpu']:.1f} s), "
             f"{s['evaluated']:,} settings over {s['shapes']} shapes, complete={s['complete']}; best {s['best']}; "
             f"--top 1: {s['top_1']['seconds_cpu']:.2f} s CPU; load average "
             f"{', '.join(f'{x:.1f}' for x in s['load_average'])}"]
    j = result["jit_cost"]
    if j:
        lines.append(f"jit        numba import {j['cached']['import_s']:.2f} s + cached kernel "
                     f"{j['cached']['first_call_s']:.2f} s CPU per process that switches to it; first compile "
                     f"{j['cold']['first_call_s']:.1f} s CPU (once, then cached)")
    return lines


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--timor", default=os.environ.get("TIMOR_ROOT", "/tmp/timor-offline"),
                    help="a venv with timor-python installed (ROOT/bin/python)")
    ap.add_argument("--json", nargs="?", const="-", default=None)
    ap.add_argument("--solve", action="store_true", help="only measurements 1-2 and the JIT's cost")
    ap.add_argument("--beyond", nargs="+", type=int, metavar="UNITS",
                    help="only measurement 7: units 1 to each UNITS (4 in this process, 5-6 on --workers 2)")
    args = ap.parse_args()
    warnings.simplefilter("ignore")
    if args.beyond:
        b = bench_beyond(args.beyond)
        print("\n".join(_beyond_lines(b)), file=sys.stderr)
        if args.json is not None:
            print(json.dumps(b, indent=2))
        return
    result: dict = {"machine": platform.processor() or platform.machine(), "python": platform.python_version()}
    if args.solve:
        result["core"] = pin_one_core()
        result["candidate"] = bench_candidates(2048 if args.quick else 8192)
        result["reference"] = bench_reference(48 if args.quick else 192)
        result["solve"] = bench_solve(1 if args.quick else 2)
        result["jit_cost"] = bench_jit_cost()
        print("\n".join(_screen_lines(result)), file=sys.stderr)
        if args.json == "-":
            print(json.dumps(result, indent=2))
        elif args.json is not None:
            Path(args.json).write_text(json.dumps(result, indent=2) + "\n", encoding="utf-8")
        return
    # before pinning (the worker processes would inherit one core)
    result["library"] = bench_library(4 if args.quick else 16, whole=not args.quick)
    result["dask"] = bench_dask(8 if args.quick else 24)
    result["core"] = pin_one_core()
    result["candidate"] = bench_candidates(2048 if args.quick else 8192)
    result["reference"] = bench_reference(48 if args.quick else 192)
    result["solve"] = bench_solve(1 if args.quick else 2)
    result["jit_cost"] = bench_jit_cost()
    result["complete"] = bench_complete()
    from bench_task import bench_region, bench_visit  # the task goals and base placement, side by side
    from bench_task_base import bench_base, bench_task_cells

    result["task"] = {"visit": bench_visit(), "region": bench_region()}
    result["base_placement"] = bench_base()
    result["base_placement_tasks"] = bench_task_cells()
    result["anchor"] = bench_timor(Path(args.timor), 10 if args.quick else 40)
    c, k, lib = (result[x] for x in ("candidate", "complete", "library"))
    a = result["anchor"]
    lines = _screen_lines(result)
    lines.append(f"complete   nothing feasible, units 1-3: {k['seconds_cpu']:.1f} s CPU, {k['evaluated']:,} settings "
                 f"({k['excluded']:,} excluded by bounds), complete={k['complete']}: {k['why_none']}")
    for name, t in result["task"].items():
        lines.append(f"task       {name}: {t['seconds_cpu']:.1f} s CPU (goal {t['goal_cpu_s']:.0f} s; search "
                     f"{t['static_search_cpu_s']:.1f} s, planning {t['planning_cpu_s']:.1f} s); best {t['best']} "
                     f"({t['cycle_time_s']} s)")
    b = result["base_placement"]["top1"]
    one, many = b["one_pose"], b["poses_25"]
    lines.append(f"base       1 pose {one['seconds_cpu']:.1f} s, 25 poses {many['seconds_cpu']:.1f} s CPU "
                 f"({many['bases_searched']} searched): {b['ratio_cpu']:.1f}x (goal <= 5)")
    for name, t in result["base_placement_tasks"].items():
        lines.append(f"base       task {name}: 1 pose {t['one_pose']['seconds_cpu']:.1f} s, 25 poses "
                     f"{t['poses_25']['seconds_cpu']:.1f} s CPU: {t['ratio_cpu']:.1f}x (goal <= 5; static search alone "
                     f"{t['ratio_static_search_cpu']:.1f}x)")
    if "walled_workers2_wall_s" in lib:
        lines.append(f"library    walled cell, units 1-6, --workers 2: {lib['walled_workers2_wall_s']:.1f} s wall "
                     f"(exit {lib['walled_exit']})")
        lines.append(f"library    far cell (targets ~2 m out), units 1-6, every unit type, --workers 2: "
                     f"{lib['far_workers2_wall_s']:.1f} s wall (exit {lib['far_exit']}): {lib['far_message'][-160:]}")
    lines.append(f"library    6-unit shapes on a cell the bounds cannot close: {lib['six_unit_cpu_s_per_shape']:.2f} s "
                 f"CPU per shape ({lib['six_unit_settings_per_shape']:.0f} settings, coarse grid); "
                 f"{lib['shapes_in_library']} shapes on 2 workers ~ "
                 f"{lib['extrapolated_library_wall_s_2_workers'] / 60:.1f} min")
    d = result["dask"]
    if d:
        lines.append(f"dask       {d['tasks']} tasks: 1 worker {d['wall_s_1_workers']:.1f} s, 2 workers "
                     f"{d['wall_s_2_workers']:.1f} s ({d['speedup_2']:.2f}x); 4,096 shapes on 64 workers ~ "
                     f"{d['extrapolated_4096_shapes_64_workers_s']:.0f} s")
    if a and "ms_per_design" in a:
        result["ratio"] = a["ms_per_design"] / c["ms_per_candidate"]
        phases = ", ".join(f"{k_} {v:.1f} ms" for k_, v in a["phases_ms"].items())
        lines.append(f"anchor     Timor {a['ms_per_design']:.1f} ms CPU per 3-DoF design with 3 targets ({phases}; "
                     f"{a['ik_solved']}/{3 * a['designs']} IK solved, warm-up excluded)")
        lines.append(f"ratio      {result['ratio']:.0f}x (Timor per design / modc per twist setting)")
    else:
        lines.append(f"anchor     Timor not measured: {a or 'not installed (--timor ROOT: a venv with timor-python)'}")
    print("\n".join(lines), file=sys.stderr)
    if args.json is not None:
        text = json.dumps(result, indent=2)
        if args.json == "-":
            print(text)
        else:
            Path(args.json).write_text(text + "\n", encoding="utf-8")


if __name__ == "__main__":
    main()
