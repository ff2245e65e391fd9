"""Whole-process compile, cold lint, and the design search's in-process fast path, each next to its
anchor in the same run.

    python benchmarks/bench_compile.py                  # examples/farm.mod, full run
    python benchmarks/bench_compile.py --quick          # fewer repetitions
    python benchmarks/bench_compile.py --json out.json

1. Processes, start-up and imports included, interleaved (one run of each command per round),
   medians and the ratio of medians, on one core (the children inherit the affinity) with a
   private bytecode cache (as installed users have it). Wall time and the child's CPU time (user +
   system) are both reported; on a loaded machine the CPU time is the steadier of the two, and
   the ratios are given for both:
     first compile    MODC_NO_CACHE=1 python -m modc FILE -o OUT   (meshes, 10,000-sample collision
                      matrix and worst-case torque search all computed)
     cached compile   python -m modc FILE -o OUT with a warm MODC_CACHE_DIR
     anchor           xacro FILE.urdf.xacro -o OUT.urdf: the xacro command expanding the same arm's
                      own .urdf.xacro (the one modc emits)
     cold lint        python -m modc lint FILE    anchor: python -c pass
   and, with --floors, what any lint in a fresh process pays whatever modc's own code does, each
   against the same `python -c pass`: the libraries it is built on (pydantic's BaseModel, lark,
   the CLI library), the CLI library plus parsing FILE into the AST (no model, no pydantic: what
   any lint does first), modc's modules imported without work, and check_file(FILE) with no CLI.
2. In-process (a 6-DoF arm, examples/example_b.mod), median over batches of the process's CPU
   time per call (wall time alongside):
     describe + model        the arm's Description and its pinocchio Model
     candidate evaluation    modc.physical.evaluate.evaluate: Description, Model, FK of tool0, g(q)
                             and a collision check (self and environment) at one pose
Goals (issue 11): first compile <= 5x xacro, cached <= 3x, cold lint <= 6x python -c pass,
describe + model <= 0.3 ms, candidate evaluation <= 1 ms.
"""
from __future__ import annotations

import argparse
import datetime as _dt
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _common import child_env, pin_one_core, report  # benchmarks/_common.py

ROOT = Path(__file__).resolve().parent.parent
if (ROOT / "modc" / "__init__.py").is_file() and str(ROOT) not in sys.path[:1]:
    sys.path.insert(0, str(ROOT))

DEFAULT_FILE = ROOT / "examples" / "farm.mod"
ARM_6DOF = ROOT / "examples" / "example_b.mod"
GOALS = {"first": 5.0, "cached": 3.0, "lint": 6.0, "describe_model_ms": 0.3, "evaluate_ms": 1.0}


def _stats(xs: list[float]) -> dict:
    s = sorted(xs)
    return {"n": len(s), "median": statistics.median(s), "min": s[0], "max": s[-1]}


def prepare(src: Path, tmp: Path) -> Path:
    """Compile src once; its .urdf.xacro is the anchor's input."""
    from modc.compiler import build, check_file, write_tree

    c = check_file(src)
    assert c.ok, [d.message for d in c.diagnostics if d.is_error]
    (robot,) = c.design.robots
    write_tree(build(c), tmp / "prepared")
    return tmp / "prepared" / "urdf" / f"{robot.file_stem}.urdf.xacro"


def floor_cases(src: Path, env: dict) -> dict:
    """Start-up costs that a cold lint cannot avoid with modc's present libraries."""
    py = sys.executable
    return {
        "floor: import pydantic.BaseModel": (env, [py, "-c", "from pydantic import BaseModel"]),
        "floor: import lark": (env, [py, "-c", "import lark"]),
        "floor: import click (the CLI library)": (env, [py, "-c", "import click"]),
        "floor: import click + parse(FILE), no model": (env, [py, "-c", "import click; from modc.syntax import parse; "
                                                                 f"parse(open({str(src)!r}).read())"]),
        "floor: import modc.compiler (no work)": (env, [py, "-c", "import modc.compiler"]),
        "floor: check_file(FILE), no CLI": (env, [py, "-c", f"from modc.compiler import check_file; "
                                                          f"check_file({str(src)!r})"]),
    }


def bench_processes(src: Path, xacro_file: Path, runs: int, tmp: Path, floors: bool = False) -> dict:
    env = child_env(pycache=tmp / "pycache")
    env.pop("MODC_NO_CACHE", None)
    env["MODC_CACHE_DIR"] = str(tmp / "cache")
    cold_env = dict(env, MODC_NO_CACHE="1")
    exe = Path(sys.executable).parent / "xacro"
    xacro_cmd = [str(exe)] if exe.is_file() else [sys.executable, "-m", "xacro"]
    modc = [sys.executable, "-m", "modc"]
    cases = {
        "modc FILE -o OUT, first (MODC_NO_CACHE=1)": (cold_env, [*modc, str(src), "-o", str(tmp / "first"), "--force"]),
        "modc FILE -o OUT, cached": (env, [*modc, str(src), "-o", str(tmp / "cached"), "--force"]),
        "xacro FILE.urdf.xacro -o OUT.urdf": (env, [*xacro_cmd, str(xacro_file), "-o", str(tmp / "x.urdf")]),
        "modc lint FILE": (env, [*modc, "lint", str(src)]),
        "python -c pass": (env, [sys.executable, "-c", "pass"]),
    }
    if floors:
        cases.update(floor_cases(src, env))
    codes = {}
    for name, (e, cmd) in cases.items():  # warm-up: bytecode, the cache for "cached", the OS's file cache
        codes[name] = subprocess.run(cmd, env=e, capture_output=True, cwd=tmp).returncode
    wall: dict[str, list[float]] = {k: [] for k in cases}
    cpu: dict[str, list[float]] = {k: [] for k in cases}
    for _ in range(runs):
        for name, (e, cmd) in cases.items():  # interleaved: load changes hit every command alike
            before = resource.getrusage(resource.RUSAGE_CHILDREN)
            t0 = time.perf_counter()
            subprocess.run(cmd, env=e, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=tmp)
            wall[name].append(time.perf_counter() - t0)
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpu[name].append(after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
    return {k: {**_stats(wall[k]), "cpu": _stats(cpu[k]), "exit_code": codes[k]} for k in cases}


def bench_in_process(batches: int, per_batch: int) -> dict:
    import numpy as np

    from modc.compiler import check_file
    from modc.physical import multibody
    from modc.physical.assembly import describe
    from modc.physical.evaluate import evaluate

    (robot,) = check_file(ARM_6DOF).design.robots
    lo, hi = np.array([robot.joint_range(i) for i in range(1, robot.dof + 1)]).T
    poses = np.random.default_rng(0).uniform(lo, hi, size=(per_batch, robot.dof))
    cases = {
        "describe + pinocchio model (6 DoF)": lambda q: multibody.model(describe(robot)),
        "candidate evaluation (6 DoF)": lambda q: evaluate(robot, q),
    }
    for fn in cases.values():  # warm-up: imports, the per-part caches (BVH models, local inertials)
        for q in poses[:5]:
            fn(q)
    cpu: dict[str, list[float]] = {k: [] for k in cases}
    wall: dict[str, list[float]] = {k: [] for k in cases}
    collisions = sum(evaluate(robot, q).collision for q in poses)
    for _ in range(batches):
        for name, fn in cases.items():
            c0, t0 = time.process_time(), time.perf_counter()
            for q in poses:
                fn(q)
            cpu[name].append((time.process_time() - c0) / per_batch * 1e3)
            wall[name].append((time.perf_counter() - t0) / per_batch * 1e3)
    out = {k: {**_stats(cpu[k]), "wall": _stats(wall[k])} for k in cases}
    out["candidate evaluation (6 DoF)"]["poses_in_collision"] = f"{collisions}/{per_batch}"
    return out


def render(doc: dict) -> str:
    p, ip, r = doc["processes"], doc["in_process"], doc["ratios"]
    m = doc["machine"]
    lines = [f"modc cold start and compile vs anchors  {m['date']}  Python {m['python']}, one core (cpu {m['cpu']}), "
             f"load average {m['load']}", f"file: {doc['file']}; anchor input: {doc['xacro_file']}", "",
             f"1. processes, median of {doc['runs']} interleaved runs (s): wall, and CPU (user + system)"]
    w = max(len(k) for k in p) + 2
    for k, s in p.items():
        lines.append(f"   {k:<{w}} wall {s['median']:6.3f} (min {s['min']:6.3f})   cpu {s['cpu']['median']:6.3f} "
                     f"(min {s['cpu']['min']:6.3f})   rc={s['exit_code']}")

    def verdict(key: str) -> str:
        x, c, goal = r[key], r[f"{key}_cpu"], GOALS[key]
        return f"wall {x:5.2f}x, cpu {c:5.2f}x (goal <= {goal:g}x: {'ok' if c <= goal else 'MISS'})"

    anchor = p["python -c pass"]["cpu"]["median"]
    for k, s in p.items():
        if k.startswith("floor:"):
            lines.append(f"   {k:<{w}} = {s['cpu']['median'] / anchor:5.2f}x python -c pass (cpu)")
    lines += [f"   first compile / xacro:      {verdict('first')}",
              f"   cached compile / xacro:     {verdict('cached')}",
              f"   cold lint / python -c pass: {verdict('lint')}", "",
              f"2. in-process, median over {doc['batches']} batches of {doc['per_batch']} calls (ms of CPU per call)"]
    if not ip:
        return "\n".join(lines[:-2])
    w = max(len(k) for k in ip) + 2
    goals = [GOALS["describe_model_ms"], GOALS["evaluate_ms"]]
    for (k, s), goal in zip(ip.items(), goals, strict=True):
        extra = f"   poses in collision {s['poses_in_collision']}" if "poses_in_collision" in s else ""
        lines.append(f"   {k:<{w}} {s['median']:7.3f}   min {s['min']:6.3f}   wall {s['wall']['median']:7.3f}"
                     f"   (goal <= {goal:g} ms: "
                     f"{'ok' if s['median'] <= goal else 'MISS'}){extra}")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--file", type=Path, default=DEFAULT_FILE, help="a .mod file with one robot (default: farm)")
    ap.add_argument("--quick", action="store_true", help="fewer repetitions")
    ap.add_argument("--runs", type=int, help="process runs per command (default 11, quick 5)")
    ap.add_argument("--json", nargs="?", const="-", metavar="PATH", help="JSON to stdout (table to stderr) or to PATH")
    ap.add_argument("--processes-only", action="store_true",
                    help="only part 1 (e.g. to measure an older checkout, which has no fast path)")
    ap.add_argument("--floors", action="store_true",
                    help="also time the imports a cold lint cannot avoid (pydantic, lark, the CLI library, "
                    "modc's modules) and check_file without the CLI")
    args = ap.parse_args(argv)
    runs = args.runs or (5 if args.quick else 11)
    batches, per_batch = (5, 50) if args.quick else (15, 100)
    core = pin_one_core()
    src = args.file.resolve()
    with tempfile.TemporaryDirectory(prefix="modc-bench-compile-") as t:
        tmp = Path(t)
        xacro_file = prepare(src, tmp)
        processes = bench_processes(src, xacro_file, runs, tmp, args.floors)
    ip = {} if args.processes_only else bench_in_process(batches, per_batch)
    med = {k: v["median"] for k, v in processes.items()}
    cpu = {k: v["cpu"]["median"] for k, v in processes.items()}
    names = list(med)
    doc = {
        "machine": {"date": _dt.datetime.now().isoformat(timespec="seconds"), "python": platform.python_version(),
                    "platform": platform.platform(), "cpu": core, "load": round(os.getloadavg()[0], 2)},
        "file": str(src.relative_to(ROOT) if src.is_relative_to(ROOT) else src), "xacro_file": xacro_file.name,
        "runs": runs, "batches": batches, "per_batch": per_batch, "processes": processes, "in_process": ip,
        "ratios": {"first": med[names[0]] / med[names[2]], "cached": med[names[1]] / med[names[2]],
                   "lint": med[names[3]] / med[names[4]], "first_cpu": cpu[names[0]] / cpu[names[2]],
                   "cached_cpu": cpu[names[1]] / cpu[names[2]], "lint_cpu": cpu[names[3]] / cpu[names[4]]},
        "goals": GOALS,
    }
    report(doc, render(doc), args.json)
    return 0


if __name__ == "__main__":
    sys.exit(main())
