"""modc's whole compile of a 6-DoF file vs the `xacro` tool expanding that file's own .urdf.xacro.

    python benchmarks/bench_xacro.py                    # examples/example_b.mod (6 DoF), full run
    python benchmarks/bench_xacro.py --quick            # fewer repetitions
    python benchmarks/bench_xacro.py --file F.mod --json out.json

Side by side in one run, interleaved, median of N runs after a warm-up (target: ratio <= 1):

1. in-process (the headline): modc = check_file (as `modc FILE -o OUT` runs it: parse, passes and
   the torque analysis; also shown without the torque analysis) + build() with every registered
   backend (load_all(), plus the xacro backend if load_all does not import it yet), files kept in
   memory; xacro = xacro.process_file(FILE.urdf.xacro) + toxml() (toxml, not the CLI's
   toprettyxml: the cheaper of the two, so the ratio is conservative). Neither writes to disk.
   Then a breakdown of the whole compile: check_file and each backend's emit, timed apart.
2. subprocesses (start-up and imports included): `python -m modc FILE -o OUT` vs the `xacro`
   console script next to python, `xacro FILE.urdf.xacro -o OUT.urdf`. Both write their output.

The .urdf.xacro is the one modc emits for FILE, compiled once into a temporary directory.
"""
from __future__ import annotations

import argparse
import datetime as _dt
import gc
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _common import child_env, report  # benchmarks/_common.py

ROOT = Path(__file__).resolve().parent.parent
if (ROOT / "modc" / "__init__.py").is_file() and str(ROOT) not in sys.path[:1]:
    sys.path.insert(0, str(ROOT))

DEFAULT_FILE = ROOT / "examples" / "example_b.mod"  # the paper's Example B, H1-H4-H4-L2-L2-L2
TARGET_RATIO = 1.0


def _stats(samples: list[float]) -> dict:
    s = sorted(samples)
    n = len(s)
    return {"n": n, "median": statistics.median(s), "min": s[0], "max": s[-1],
            "p90": s[min(n - 1, int(round(0.9 * (n - 1))))]}


def _backends() -> list[str]:
    from modc.backends import load_all

    names = list(load_all())
    if "xacro" not in names:
        from modc.backends import xacro  # noqa: F401  (registers itself)
    from modc.backends import BACKENDS

    return list(BACKENDS)




def prepare(src: Path, tmp: Path) -> tuple[Path, dict]:
    """Compile src once with every backend; return its .urdf.xacro and facts about the robot."""
    from modc.compiler import COMPILE_ANALYSES, build, check_file, write_tree

    c = check_file(src, analyses=COMPILE_ANALYSES)
    assert c.ok, [d.message for d in c.diagnostics if d.is_error]
    robots = c.design.robots
    if len(robots) != 1:
        raise SystemExit(f"{src}: expected one robot, found {len(robots)}")
    files = build(c)
    out = tmp / "out"
    write_tree(files, out)
    r = robots[0]
    return out / "urdf" / f"{r.file_stem}.urdf.xacro", {
        "robot": r.name, "sequence": r.sequence, "dof": r.dof, "outputs": len(files),
        "xacro_files": sorted(k for k in files if k.endswith(".xacro"))}


def bench_in_process(src: Path, xacro_file: Path, runs: int) -> dict:
    import xacro

    from modc.compiler import COMPILE_ANALYSES, build, check_file

    def cold():  # the first compile of this arm on a machine: collision matrix and meshes not cached
        os.environ["MODC_NO_CACHE"] = "1"
        try:
            return build(check_file(src, analyses=COMPILE_ANALYSES))
        finally:
            del os.environ["MODC_NO_CACHE"]

    cases = {
        "modc: check_file(torque) + build(all)": lambda: build(check_file(src, analyses=COMPILE_ANALYSES)),
        "modc: the same, cold (MODC_NO_CACHE=1)": cold,
        "modc: check_file + build(all), no torque": lambda: build(check_file(src)),
        "xacro: process_file + toxml": lambda: xacro.process_file(str(xacro_file)).toxml(),
    }
    for fn in cases.values():  # warm-up: imports, Lark, library, Jinja, mesh cache
        fn()
    samples: dict[str, list[float]] = {k: [] for k in cases}
    gc.collect()
    for _ in range(runs):
        for name, fn in cases.items():  # interleaved
            t0 = time.perf_counter()
            fn()
            samples[name].append((time.perf_counter() - t0) * 1e3)
    return {k: _stats(v) for k, v in samples.items()}


def bench_breakdown(src: Path, runs: int) -> dict:
    """Where the whole compile's time goes: check_file(torque), then each backend's emit, in
    build()'s order (the same work as build(check_file(...)))."""
    from modc.backends import BACKENDS, Build
    from modc.compiler import COMPILE_ANALYSES, check_file

    samples: dict[str, list[float]] = {}

    def once(record: bool) -> None:
        t0 = time.perf_counter()
        c = check_file(src, analyses=COMPILE_ANALYSES)
        times = {"check_file (parse, passes, torque)": time.perf_counter() - t0}
        b = Build(c.design, diagnostics=list(c.diagnostics))
        for name, backend in BACKENDS.items():
            t0 = time.perf_counter()
            b.files.update(backend.emit(b))
            times[f"backend {name}"] = time.perf_counter() - t0
        if record:
            for k, v in times.items():
                samples.setdefault(k, []).append(v * 1e3)

    once(False)
    for _ in range(runs):
        once(True)
    return {k: _stats(v) for k, v in samples.items()}


def bench_subprocess(src: Path, xacro_file: Path, runs: int, tmp: Path) -> dict:
    env = child_env()
    exe = Path(sys.executable).parent / "xacro"
    xacro_cmd = [str(exe)] if exe.is_file() else [sys.executable, "-m", "xacro"]
    cmds = {
        "python -m modc FILE -o OUT": [sys.executable, "-m", "modc", str(src), "-o", str(tmp / "sub_out"), "-q"],
        "xacro FILE.urdf.xacro -o OUT.urdf": [*xacro_cmd, str(xacro_file), "-o", str(tmp / "sub.urdf")],
    }
    rcs = {}
    for name, cmd in cmds.items():
        rcs[name] = subprocess.run(cmd, env=env, capture_output=True, cwd=tmp).returncode
    samples: dict[str, list[float]] = {k: [] for k in cmds}
    for _ in range(runs):
        for name, cmd in cmds.items():
            t0 = time.perf_counter()
            subprocess.run(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=tmp)
            samples[name].append(time.perf_counter() - t0)
    res = {k: _stats(v) for k, v in samples.items()}
    for k in res:
        res[k]["exit_code"] = rcs[k]
    return res


def render(doc: dict) -> str:
    m = doc["machine"]
    ip, sp = doc["in_process"], doc["subprocess"]
    r = doc["ratios"]
    lines = [
        f"modc compile vs xacro expansion  {m['date']}  Python {m['python']} on {m['platform']}",
        f"file: {doc['file']} ({doc['info']['sequence']}, {doc['info']['dof']} DoF); "
        f"backends: {', '.join(doc['backends'])} -> {doc['info']['outputs']} files",
        f"xacro {m['xacro']}; expanded: {doc['xacro_file']}",
        "",
        f"1. in-process, median of {doc['runs_in_process']} interleaved runs (ms)",
    ]
    w = max(len(k) for k in ip) + 2
    for k, s in ip.items():
        lines.append(f"   {k:<{w}} {s['median']:8.2f}   min {s['min']:7.2f}   p90 {s['p90']:7.2f}")
    lines.append(
        f"   ratio modc whole compile / xacro expansion: {r['in_process']:.3f}  (target <= {TARGET_RATIO:g}: "
        f"{'ok' if r['in_process'] <= TARGET_RATIO else 'MISS'}); "
        f"without torque analysis: {r['in_process_no_torque']:.3f}; "
        f"cold (first compile of this arm, nothing cached): {r['in_process_cold']:.3f}"
    )
    bd = doc["breakdown"]
    lines.append(f"   breakdown of the whole compile, median of {doc['runs_breakdown']} runs (ms; the first build of a"
                 " process also renders the library data once):")
    w = max(len(k) for k in bd) + 2
    for k, s in bd.items():
        lines.append(f"     {k:<{w}} {s['median']:8.2f}")
    lines.append("")
    lines.append(f"2. subprocesses, start-up included, median of {doc['runs_subprocess']} interleaved runs (s)")
    w = max(len(k) for k in sp) + 2
    for k, s in sp.items():
        lines.append(
            f"   {k:<{w}} {s['median']:8.3f}   min {s['min']:7.3f}   p90 {s['p90']:7.3f}   rc={s['exit_code']}"
        )
    lines.append(f"   ratio modc / xacro: {r['subprocess']:.3f}")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--file", type=Path, default=DEFAULT_FILE, help="a .mod file with one robot (default: Example B)")
    ap.add_argument("--quick", action="store_true", help="fewer repetitions")
    ap.add_argument("--runs", type=int, help="in-process runs per case (default 40, quick 10)")
    ap.add_argument("--sub-runs", type=int, help="subprocess runs per command (default 10, quick 3)")
    ap.add_argument("--json", nargs="?", const="-", metavar="PATH", help="JSON to stdout (table to stderr) or to PATH")
    args = ap.parse_args(argv)
    runs = args.runs or (10 if args.quick else 40)
    sub_runs = args.sub_runs or (3 if args.quick else 10)
    src = args.file.resolve()

    from importlib import metadata

    backends = _backends()
    with tempfile.TemporaryDirectory(prefix="modc-bench-xacro-") as t:
        tmp = Path(t)
        xacro_file, info = prepare(src, tmp)
        ip = bench_in_process(src, xacro_file, runs)
        bd = bench_breakdown(src, max(5, runs // 4))
        sp = bench_subprocess(src, xacro_file, sub_runs, tmp)
    x = ip["xacro: process_file + toxml"]["median"]
    subs = list(sp.values())
    doc = {
        "machine": {"date": _dt.datetime.now().isoformat(timespec="seconds"), "python": platform.python_version(),
                    "platform": platform.platform(), "xacro": metadata.version("xacro")},
        "file": str(src.relative_to(ROOT) if src.is_relative_to(ROOT) else src),
        "xacro_file": xacro_file.name, "backends": backends, "info": info,
        "runs_in_process": runs, "runs_subprocess": sub_runs,
        "runs_breakdown": max(5, runs // 4),
        "in_process": ip, "breakdown": bd, "subprocess": sp,
        "ratios": {
            "in_process": ip["modc: check_file(torque) + build(all)"]["median"] / x,
            "in_process_cold": ip["modc: the same, cold (MODC_NO_CACHE=1)"]["median"] / x,
            "in_process_no_torque": ip["modc: check_file + build(all), no torque"]["median"] / x,
            "subprocess": subs[0]["median"] / subs[1]["median"],
        },
        "target_ratio": TARGET_RATIO,
    }
    report(doc, render(doc), args.json)
    return 0


if __name__ == "__main__":
    sys.exit(main())
