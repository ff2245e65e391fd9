"""modc benchmarks: cold `modc lint`, in-process compile, lint throughput. Not a test.

    python benchmarks/bench.py            # full run (~1 min)
    python benchmarks/bench.py --quick    # fewer repetitions (< 60 s)
    python benchmarks/bench.py --json     # table on stderr, JSON document on stdout
    python benchmarks/bench.py --json out.json   # table on stdout, JSON written to out.json

What is measured, side by side in one run:

1. cold start: wall time of fresh subprocesses, median of N runs after one warm-up run each
   (the warm-up also creates Lark's grammar cache and the .pyc files). `python -c pass` is the
   anchor (bare interpreter start-up); lint/anchor is reported so that figures from different
   machines can be compared. The runs of all commands are interleaved so that machine drift
   hits them alike. Bytecode is cached in a private PYTHONPYCACHEPREFIX even where
   PYTHONDONTWRITEBYTECODE is set (then one extra row shows the environment as it is).
2. in-process compile of a 6-DoF arm without meshes: check_text, then build(only=["urdf"])
   (build always adds the "report" backend, so this equals ["urdf", "report"]; both are timed).
3. lint throughput: a generated corpus (fixed seed) of valid and invalid .mod files, checked
   in-process with check_file, and once by a `modc lint DIR` subprocess (start-up included).

Every row also reports CPU time (user + sys of the child, or process_time in-process): on a
busy machine wall times inflate several-fold while CPU time grows far less, so compare CPU
columns across runs made under different load. The load average is printed with a warning.

Only the standard library and modc itself are used. The working tree this file sits in is the
modc that is measured (its root is put first on sys.path, and on PYTHONPATH for subprocesses
when a fresh interpreter would otherwise import another copy).
"""
from __future__ import annotations

import argparse
import datetime as _dt
import gc
import json
import os
import platform
import random
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _common import child_env  # benchmarks/_common.py

ROOT = Path(__file__).resolve().parent.parent
if (ROOT / "modc" / "__init__.py").is_file() and str(ROOT) not in sys.path[:1]:
    sys.path.insert(0, str(ROOT))

SEED = 20240611

# Targets (see the project brief): seconds, milliseconds, files per second.
TARGET_COLD_S = 0.300
TARGET_COMPILE_MS = 5.0
TARGET_FILES_PER_S = 1000.0

# A 6-DoF arm valid under mark2's rules: H first, L last, no L -> H, at most 3 H and 3 L.
SIX_DOF = "robot six { chain H1 - H4(pivot=-90deg) - H4 - L1(pivot=90deg) - L4(pivot=-90deg, port=90deg) - L2 }\n"


# --------------------------------------------------------------------------------------------
# helpers

def _stats(samples: list[float]) -> dict:
    s = sorted(samples)
    n = len(s)
    return {
        "n": n,
        "median": statistics.median(s),
        "mean": statistics.fmean(s),
        "min": s[0],
        "max": s[-1],
        "p90": s[min(n - 1, int(round(0.9 * (n - 1))))],
        "stdev": statistics.stdev(s) if n > 1 else 0.0,
    }




def _console_script() -> Path | None:
    bindir = Path(sys.executable).parent
    for name in ("modc", "modc.exe"):
        p = bindir / name
        if p.is_file() and os.access(p, os.X_OK):
            return p
    return None


def _children_cpu() -> float:
    try:
        import resource
    except ImportError:  # Windows: no CPU time for children
        return 0.0
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def _run(cmd: list[str], env: dict, cwd: str) -> tuple[float, float, int]:
    """(wall seconds, CPU seconds of the child (user + sys), exit code). CPU time is what the
    process itself needed: it grows far less than wall time when the machine is busy."""
    c0 = _children_cpu()
    t0 = time.perf_counter()
    rc = subprocess.run(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                        env=env, cwd=cwd).returncode
    return time.perf_counter() - t0, _children_cpu() - c0, rc


def _loadavg() -> list[float] | None:
    try:
        return [round(x, 2) for x in os.getloadavg()]
    except (AttributeError, OSError):
        return None


def _machine() -> dict:
    try:
        affinity = len(os.sched_getaffinity(0))
    except AttributeError:
        affinity = os.cpu_count()
    versions = {}
    from importlib import metadata

    for dist in ("modc", "lark", "pydantic", "pydantic-core", "click", "PyYAML", "Jinja2", "numpy"):
        try:
            versions[dist] = metadata.version(dist)
        except metadata.PackageNotFoundError:
            versions[dist] = None
    commit = None
    if shutil.which("git"):
        r = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
        if r.returncode == 0:
            commit = r.stdout.strip()
            dirty = subprocess.run(["git", "-C", str(ROOT), "status", "--porcelain", "--", "modc", "grammar",
                                    "templates", "libraries"], capture_output=True, text=True).stdout.strip()
            commit += "+dirty" if dirty else ""
    return {
        "loadavg_start": _loadavg(),
        "date": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "python": platform.python_version(),
        "implementation": platform.python_implementation(),
        "executable": sys.executable,
        "platform": platform.platform(),
        "machine": platform.machine(),
        "processor": platform.processor() or None,
        "nproc": affinity,
        "cpu_count": os.cpu_count(),
        "versions": versions,
        "commit": commit,
    }


# --------------------------------------------------------------------------------------------
# the 6-DoF input

def six_dof_source() -> tuple[str, str]:
    """(text, origin): the first example with a valid 6-unit robot, else the embedded arm."""
    from modc.compiler import check_text

    for ex in sorted((ROOT / "examples").glob("*.mod")):
        text = ex.read_text(encoding="utf-8")
        c = check_text(text, str(ex))
        if c.ok and any(r.dof == 6 for r in c.design.robots):
            return text, str(ex.relative_to(ROOT))
    return SIX_DOF, "embedded"


# --------------------------------------------------------------------------------------------
# corpus generation (deterministic: fixed seed, no dependence on the clock or the file system)

_TWIST = list(range(-90, 91, 15))
_PORT = list(range(-165, 181, 15))


class Gen:
    def __init__(self, seed: int):
        self.r = random.Random(seed)

    def unit(self, variant: str) -> str:
        r = self.r
        kind = r.randint(1, 4)
        params = []
        if r.random() < 0.6:
            params.append(f"pivot={r.choice(_TWIST)}deg")
        if kind >= 3:
            if r.random() < 0.5:
                params.append(f"port={r.choice(_PORT)}deg")
            if r.random() < 0.3:
                params.append(r.choice([f"link={r.randint(5, 50) * 10}mm", f"link={r.randint(5, 50) / 100:g} m"]))
        return f"{variant}{kind}" + (f"({', '.join(params)})" if params else "")

    def chain(self) -> list[str]:
        r = self.r
        nh, nl = r.randint(1, 3), r.randint(1, 3)
        return [self.unit("H") for _ in range(nh)] + [self.unit("L") for _ in range(nl)]

    def robot(self, name: str, units: list[str] | None = None) -> str:
        r = self.r
        units = units or self.chain()
        dof = len(units)
        sep = r.choice([" - ", " -\n        "])
        body = [f"chain {sep.join(units)}"]
        if r.random() < 0.2:
            body.insert(0, "library mark2")
        if r.random() < 0.3:
            body.append(f"base at (0, 0, {r.randint(0, 50) / 100:g}) m rpy (0, 0, {r.choice(_TWIST)}) deg")
        if r.random() < 0.3:
            body.append(f"tool at (0, 0, {r.randint(1, 10)}) cm")
        if r.random() < 0.3:
            body.append(f"payload {r.randint(50, 900)} g at (0, 0, 0.03) m")
        if r.random() < 0.5:
            q = ", ".join(str(r.randint(-90, 90)) for _ in range(dof))
            body.append(f"pose home ({q}) deg")
        if r.random() < 0.3:
            body.append(f"pose zero ({', '.join(['0'] * dof)}) rad")
        if r.random() < 0.3:
            j = r.randint(1, dof)
            body.append(f"limit joint_{j} (-{r.randint(100, 170)}, {r.randint(100, 170)}) deg")
        if r.random() < 0.25:
            body.append(f"box table size (1.2, 0.8, 0.05) m at (0.4, 0, -0.03) m rpy (0, 0, {r.choice(_TWIST)}) deg")
        if r.random() < 0.15:
            body.append("sphere ball radius 0.05 m at (0.3, 0.2, 0.1) m")
        if r.random() < 0.15:
            body.append("cylinder post radius 40 mm length 0.5 m at (-0.3, 0, 0.25) m")
        if r.random() < 0.3:
            body.append(f"target t1 at ({r.randint(10, 50) / 100:g}, 0, 0.2) m")
        if r.random() < 0.1:
            body.append("allow first-variant, last-variant")
        if r.random() < 0.3:
            body.insert(r.randint(0, len(body)), "# " + r.choice(["bench cell", "wrist", "TODO: calibrate"]))
        inner = "\n    ".join(body)
        return f"robot {name} {{\n    {inner}\n}}\n"

    def valid(self, i: int) -> str:
        n = 1 if self.r.random() < 0.8 else self.r.randint(2, 3)
        head = f"# corpus file {i}: valid\n"
        return head + "\n".join(self.robot(f"arm{i}_{k}") for k in range(n))

    # Each invalid kind: a function (gen, valid robot text) -> invalid text.
    SEMANTIC = {
        "unknown-module": lambda g, t: t.replace("chain H", "chain X9 - H", 1),
        "first-variant": lambda g, t: t.replace("chain H", "chain L1 - H", 1),
        "too-many-units": lambda g, t: g.robot("big", ["H1", "H2", "H3", "H4", "L1", "L2", "L3"]),
        "twist-not-realisable": lambda g, t: g.robot("tw", ["H1(pivot=7deg)", "L4"]),
        "missing-unit": lambda g, t: g.robot("mu", ["H1(pivot=45)", "L1"]),
        "wrong-unit": lambda g, t: g.robot("wu", ["H1(pivot=45mm)", "L1"]),
        "unknown-parameter": lambda g, t: g.robot("up", ["H1(pviot=45deg)", "L1"]),
        "link-length-range": lambda g, t: g.robot("ll", ["H3(link=900mm)", "L1"]),
        "pose-arity": lambda g, t: t.replace("chain", "pose bad (1, 2, 3, 4, 5, 6, 7) deg\n    chain", 1),
        "pose-out-of-limits": lambda g, t: g.robot("po", ["H1", "L1"]).replace(
            "chain", "pose far (200, 0) deg\n    chain", 1
        ),
        "duplicate-robot": lambda g, t: t + g.robot(t.split()[1]),
        "nonpositive-size": lambda g, t: t.replace("chain", "sphere s0 radius 0 m at (0, 0, 0) m\n    chain", 1),
        "unknown-joint": lambda g, t: t.replace("chain", "limit joint_9 (-10, 10) deg\n    chain", 1),
    }
    SYNTAX = {
        "missing-dash": lambda g, t: (
            g.robot("md", ["H1", "H4", "L1"]).replace(" - H4", " H4", 1).replace("-\n        H4", " H4", 1)
        ),
        "missing-equals": lambda g, t: g.robot("me", ["H1(pivot=45deg)", "L1"]).replace("pivot=", "pivot ", 1),
        "unclosed-block": lambda g, t: t.rstrip().rstrip("}") + "\n",
        "unexpected-character": lambda g, t: t.replace("chain", "chain @", 1),
        "expected-statement": lambda g, t: t.replace("chain", "frobnicate 3\n    chain", 1),
        "syntax-error": lambda g, t: t.replace("chain", "pose p (1, 2 deg\n    chain", 1),
    }

    def invalid(self, i: int, table: dict, label: str) -> tuple[str, str]:
        kind = self.r.choice(sorted(table))
        base = self.robot(f"bad{i}")
        return kind, f"# corpus file {i}: {label} ({kind})\n" + table[kind](self, base)


def generate_corpus(directory: Path, n: int, seed: int = SEED) -> list[tuple[Path, str]]:
    """n files: ~60 % valid, ~25 % semantic errors, ~15 % syntax errors. Returns (path, category)."""
    g = Gen(seed)
    out = []
    for i in range(n):
        x = g.r.random()
        if x < 0.60:
            cat, text = "valid", g.valid(i)
        elif x < 0.85:
            cat = "semantic"
            _, text = g.invalid(i, Gen.SEMANTIC, cat)
        else:
            cat = "syntax"
            _, text = g.invalid(i, Gen.SYNTAX, cat)
        p = directory / f"f{i:04d}_{cat}.mod"
        p.write_text(text, encoding="utf-8")
        out.append((p, cat))
    return out


# --------------------------------------------------------------------------------------------
# the three benchmarks

AS_IS = "python -m modc lint FILE [env as-is, PYTHONDONTWRITEBYTECODE]"


def bench_cold(runs: int, lint_file: Path, env: dict, env_as_is: dict | None, cwd: str, log) -> dict:
    lint = [sys.executable, "-m", "modc", "lint", str(lint_file)]
    cmds = {"anchor: python -c pass": ([sys.executable, "-c", "pass"], env),
            "python -m modc lint FILE": (lint, env)}
    script = _console_script()
    if script is not None:
        cmds["modc lint FILE (console script)"] = ([str(script), "lint", str(lint_file)], env)
    # breakdown: what importing the CLI / the pipeline alone costs
    cmds["  import modc.cli"] = ([sys.executable, "-c", "import modc.cli"], env)
    cmds["  import modc.compiler"] = ([sys.executable, "-c", "import modc.compiler"], env)
    if env_as_is is not None:  # the caller's environment forbids .pyc files: show what that costs
        cmds[AS_IS] = (lint, env_as_is)
    rcs = {}
    for name, (cmd, e) in cmds.items():  # warm-up: page cache, .pyc files, Lark's grammar cache
        rcs[name] = _run(cmd, e, cwd)[2]
    bad = {k: v for k, v in rcs.items() if v != 0}
    if bad:
        log(f"warning: non-zero exit during warm-up: {bad}")
    samples: dict[str, list[float]] = {k: [] for k in cmds}
    cpu: dict[str, list[float]] = {k: [] for k in cmds}
    for _ in range(runs):
        for name, (cmd, e) in cmds.items():  # interleaved
            w, c, _ = _run(cmd, e, cwd)
            samples[name].append(w)
            cpu[name].append(c)
    res = {k: _stats(v) for k, v in samples.items()}
    for k, v in res.items():
        v["cpu"] = _stats(cpu[k])
    anchor = res["anchor: python -c pass"]["median"]
    for k, v in res.items():
        v["ratio_to_anchor"] = v["median"] / anchor if anchor > 0 else None
        v["exit_code"] = rcs[k]
    return res


def bench_compile(iterations: int, text: str) -> dict:
    from modc.compiler import build, check_text

    full_minus_meshes = ["urdf", "report"]
    path = "six.mod"
    c = check_text(text, path)  # warm-up: Lark, library, Jinja environment, numpy
    assert c.ok, [d.message for d in c.diagnostics]
    files_urdf = build(c, only=["urdf"])
    files_full = build(c, only=full_minus_meshes)
    dof = max(r.dof for r in c.design.robots)

    cases = {
        "check_text (parse, lower, passes)": lambda: check_text(text, path),
        'build(only=["urdf"])  (+report, always)': lambda: build(c, only=["urdf"]),
        'build(only=["urdf","report"])': lambda: build(c, only=full_minus_meshes),
        'check_text + build(["urdf"])': lambda: build(check_text(text, path), only=["urdf"]),
        'check_text + build(["urdf","report"])': lambda: build(check_text(text, path), only=full_minus_meshes),
    }
    samples: dict[str, list[float]] = {k: [] for k in cases}
    cpu: dict[str, list[float]] = {k: [] for k in cases}
    gc.collect()
    for _ in range(iterations):
        for name, fn in cases.items():  # interleaved
            c0, t0 = time.process_time(), time.perf_counter()
            fn()
            samples[name].append((time.perf_counter() - t0) * 1e3)
            cpu[name].append((time.process_time() - c0) * 1e3)
    res = {k: _stats(v) for k, v in samples.items()}
    for k, v in res.items():
        v["cpu"] = _stats(cpu[k])
    res["_info"] = {"dof": dof, "outputs_urdf": sorted(files_urdf), "outputs_full": sorted(files_full)}
    return res


def bench_corpus(
    files: list[tuple[Path, str]], passes: int, cli_runs: int, directory: Path, env: dict, cwd: str
) -> dict:
    from modc.compiler import check_file

    for p, _ in files[:5]:  # warm-up
        check_file(p)
    # classification check: does each file land where the generator meant it to?
    outcome = {}
    for p, _cat in files:
        c = check_file(p)
        codes = {d.code for d in c.diagnostics if d.is_error}
        syntax = codes & {"syntax-error", "unexpected-character", "unclosed-block", "missing-dash",
                          "missing-equals", "expected-statement", "expected-robot"}
        got = "syntax" if syntax else ("semantic" if codes else "valid")
        outcome[p] = got
    mismatched = sum(outcome[p] != cat for p, cat in files)
    per_cat: dict[str, list[float]] = {}
    totals, cpus = [], []
    gc.collect()
    for _ in range(passes):
        cat_time: dict[str, float] = {}
        c_all, t_all = time.process_time(), time.perf_counter()
        for p, cat in files:
            t0 = time.perf_counter()
            check_file(p)
            cat_time[cat] = cat_time.get(cat, 0.0) + time.perf_counter() - t0
        totals.append(time.perf_counter() - t_all)
        cpus.append(time.process_time() - c_all)
        for cat, t in cat_time.items():
            per_cat.setdefault(cat, []).append(t)
    n = len(files)
    counts = {}
    for _, cat in files:
        counts[cat] = counts.get(cat, 0) + 1
    total = statistics.median(totals)
    res = {
        "files": n,
        "categories": counts,
        "mismatched": mismatched,
        "in_process": {"passes": passes, "seconds": total, "files_per_s": n / total,
                       "ms_per_file": total * 1e3 / n, "seconds_all_passes": totals,
                       "cpu_seconds": statistics.median(cpus), "cpu_files_per_s": n / statistics.median(cpus)},
        "by_category": {cat: {"files": counts[cat], "seconds": statistics.median(ts),
                              "files_per_s": counts[cat] / statistics.median(ts),
                              "ms_per_file": statistics.median(ts) * 1e3 / counts[cat]}
                        for cat, ts in sorted(per_cat.items())},
    }
    cmd = [sys.executable, "-m", "modc", "lint", str(directory)]
    walls, cpus, rc = [], [], None
    for _ in range(cli_runs):
        w, c, rc = _run(cmd, env, cwd)
        walls.append(w)
        cpus.append(c)
    wall = statistics.median(walls)
    res["cli"] = {
        "runs": cli_runs,
        "seconds": wall,
        "files_per_s": n / wall,
        "exit_code": rc,
        "seconds_all_runs": walls,
        "cpu_seconds": statistics.median(cpus),
    }
    return res


# --------------------------------------------------------------------------------------------
# report

def _status(ok: bool | None, cpu_ok: bool | None = None) -> str:
    """Targets are wall times; on a busy machine a miss may still be met in CPU time."""
    if ok is None:
        return ""
    if ok:
        return "ok"
    return "MISS (cpu ok)" if cpu_ok else "MISS"


def render_table(doc: dict) -> str:
    m = doc["machine"]
    lines = [
        f"modc benchmarks  {m['date']}  mode={doc['mode']}  commit={m['commit']}",
        f"Python {m['python']} ({m['implementation']}) on {m['platform']}, {m['machine']}, nproc={m['nproc']}",
        "versions: " + ", ".join(f"{k} {v}" for k, v in m["versions"].items() if v),
    ]
    la0, la1 = m.get("loadavg_start"), m.get("loadavg_end")
    if la0 and la1:
        lines.append(f"load average (1 min) at start {la0[0]:.2f}, at end {la1[0]:.2f}")
    lint = doc["cold"]["results"]["python -m modc lint FILE"]
    stretch = lint["median"] / lint["cpu"]["median"] if lint["cpu"]["median"] > 0 else 1.0
    if stretch > 1.2 or (la0 and la0[0] > (m["nproc"] or 1)):
        lines.append(f"WARNING: the machine is busy (cold lint wall/cpu = {stretch:.2f}); wall times are inflated "
                     "and noisy: compare the cpu and min columns, or rerun")
    if m.get("PYTHONDONTWRITEBYTECODE"):
        lines.append(
            "note: PYTHONDONTWRITEBYTECODE is set here; subprocesses get a private PYTHONPYCACHEPREFIX instead"
        )
    lines.append("")
    rows = [("benchmark", "median", "min", "p90", "cpu", "n", "ratio", "target", "")]

    cold = doc["cold"]
    lines.append(
        f"1. cold start: fresh subprocess wall time, {cold['runs']} runs after 1 warm-up, .pyc cached; "
        f"file: {cold['file']}"
    )
    for name, s in cold["results"].items():
        is_lint = "lint" in name and name != AS_IS
        target = f"<= {TARGET_COLD_S:.3f} s" if is_lint else ""
        ok = s["median"] <= TARGET_COLD_S if is_lint else None
        cpu_ok = s["cpu"]["median"] <= TARGET_COLD_S
        ratio = "" if name.startswith("anchor") else f"x{s['ratio_to_anchor']:.1f}"
        rows.append(
            (
                name,
                f"{s['median']:.3f} s",
                f"{s['min']:.3f} s",
                f"{s['p90']:.3f} s",
                f"{s['cpu']['median']:.3f} s",
                str(s["n"]),
                ratio,
                target,
                _status(ok, cpu_ok),
            )
        )
    lines += _fmt(rows)
    lines.append("")

    comp = doc["compile"]
    rows = [("benchmark", "median", "min", "p90", "cpu", "n", "", "target", "")]
    lines.append(
        f"2. in-process compile, {comp['dof']}-DoF arm ({comp['source']}), no meshes; "
        f"{comp['iterations']} iterations, ms"
    )
    for name, s in comp["results"].items():
        full = name.startswith("check_text +")
        ok = s["median"] <= TARGET_COMPILE_MS if full else None
        cpu_ok = s["cpu"]["median"] <= TARGET_COMPILE_MS
        rows.append(
            (
                name,
                f"{s['median']:.2f} ms",
                f"{s['min']:.2f} ms",
                f"{s['p90']:.2f} ms",
                f"{s['cpu']['median']:.2f} ms",
                str(s["n"]),
                "",
                f"<= {TARGET_COMPILE_MS:g} ms" if full else "",
                _status(ok, cpu_ok),
            )
        )
    lines += _fmt(rows)
    lines.append(
        f"   outputs: urdf -> {', '.join(comp['outputs_urdf'])}; urdf,report -> {', '.join(comp['outputs_full'])}"
    )
    lines.append("")

    cor = doc["corpus"]
    cats = ", ".join(f"{v} {k}" for k, v in sorted(cor["categories"].items()))
    lines.append(f"3. lint throughput: {cor['files']} generated files ({cats}; seed {doc['seed']}), "
                 f"{cor['mismatched']} misclassified")
    rows = [("benchmark", "files/s", "ms/file", "total", "cpu", "n", "", "target", "")]
    ip = cor["in_process"]
    rows.append(
        (
            "check_file, in-process, all files",
            f"{ip['files_per_s']:.0f}",
            f"{ip['ms_per_file']:.3f}",
            f"{ip['seconds']:.3f} s",
            f"{ip['cpu_seconds']:.3f} s",
            str(ip["passes"]),
            "",
            f">= {TARGET_FILES_PER_S:.0f}/s",
            _status(ip["files_per_s"] >= TARGET_FILES_PER_S, ip["cpu_files_per_s"] >= TARGET_FILES_PER_S),
        )
    )
    for cat, s in cor["by_category"].items():
        rows.append(
            (
                f"  {cat} files only",
                f"{s['files_per_s']:.0f}",
                f"{s['ms_per_file']:.3f}",
                f"{s['seconds']:.3f} s",
                "",
                str(s["files"]),
                "",
                "",
                "",
            )
        )
    cli = cor["cli"]
    rows.append(
        (
            "python -m modc lint DIR (with start-up)",
            f"{cli['files_per_s']:.0f}",
            f"{cli['seconds'] * 1e3 / cor['files']:.3f}",
            f"{cli['seconds']:.3f} s",
            f"{cli['cpu_seconds']:.3f} s",
            str(cli["runs"]),
            f"rc={cli['exit_code']}",
            "",
            "",
        )
    )
    lines += _fmt(rows)
    lines.append("")
    lines.append(f"total benchmark time: {doc['elapsed_s']:.1f} s")
    return "\n".join(lines)


def _fmt(rows: list[tuple]) -> list[str]:
    widths = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    out = []
    for j, r in enumerate(rows):
        cells = [r[0].ljust(widths[0])] + [c.rjust(w) for c, w in zip(r[1:], widths[1:], strict=True)]
        out.append("   " + "  ".join(cells).rstrip())
        if j == 0:
            out.append("   " + "  ".join("-" * w for w in widths))
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="fewer repetitions (< 60 s)")
    ap.add_argument("--json", nargs="?", const="-", metavar="PATH",
                    help="also emit JSON: to stdout (table goes to stderr) or to PATH")
    ap.add_argument("--runs", type=int, help="cold-start runs per command (default 15, quick 5)")
    ap.add_argument("--iterations", type=int, help="in-process compile iterations (default 200, quick 50)")
    ap.add_argument("--files", type=int, help="corpus size (default 500)")
    args = ap.parse_args(argv)

    runs = args.runs or (5 if args.quick else 15)
    iterations = args.iterations or (50 if args.quick else 200)
    n_files = args.files or 500
    passes, cli_runs = (1, 1) if args.quick else (3, 3)
    to_stdout_json = args.json == "-"
    table_out = sys.stderr if to_stdout_json else sys.stdout

    def log(msg: str) -> None:
        print(msg, file=sys.stderr, flush=True)

    t_start = time.perf_counter()
    machine = _machine()
    with tempfile.TemporaryDirectory(prefix="modc-bench-") as tmp:
        tmpdir = Path(tmp)
        env = child_env(tmpdir / "pycache")
        no_pyc = bool(os.environ.get("PYTHONDONTWRITEBYTECODE"))
        env_as_is = child_env() if no_pyc else None
        machine["PYTHONDONTWRITEBYTECODE"] = os.environ.get("PYTHONDONTWRITEBYTECODE")
        text, origin = six_dof_source()
        lint_file = tmpdir / "six.mod"
        lint_file.write_text(text, encoding="utf-8")

        log(f"[1/3] cold start: {runs} runs x commands ...")
        cold = bench_cold(runs, lint_file, env, env_as_is, tmp, log)
        log(f"[2/3] in-process compile: {iterations} iterations ...")
        comp = bench_compile(iterations, text)
        log(f"[3/3] lint throughput: {n_files} files ...")
        corpus_dir = tmpdir / "corpus"
        corpus_dir.mkdir()
        files = generate_corpus(corpus_dir, n_files)
        cor = bench_corpus(files, passes, cli_runs, corpus_dir, env, tmp)

    info = comp.pop("_info")
    doc = {
        "mode": "quick" if args.quick else "full",
        "seed": SEED,
        "machine": machine,
        "targets": {
            "cold_lint_s": TARGET_COLD_S,
            "compile_ms": TARGET_COMPILE_MS,
            "lint_files_per_s": TARGET_FILES_PER_S,
        },
        "cold": {"runs": runs, "file": f"{origin} (copied to a temp dir)", "results": cold},
        "compile": {
            "iterations": iterations,
            "source": origin,
            "dof": info["dof"],
            "outputs_urdf": info["outputs_urdf"],
            "outputs_full": info["outputs_full"],
            "results": comp,
        },
        "corpus": cor,
    }
    lint = cold["python -m modc lint FILE"]["median"]
    full = comp['check_text + build(["urdf"])']["median"]
    doc["summary"] = {
        "cold_lint_s": lint,
        "cold_lint_ratio_to_anchor": cold["python -m modc lint FILE"]["ratio_to_anchor"],
        "compile_6dof_ms": full,
        "lint_files_per_s": cor["in_process"]["files_per_s"],
        "lint_dir_cli_files_per_s": cor["cli"]["files_per_s"],
        "targets_met": {
            "cold_lint": lint <= TARGET_COLD_S,
            "compile": full <= TARGET_COMPILE_MS,
            "throughput": cor["in_process"]["files_per_s"] >= TARGET_FILES_PER_S,
        },
        "targets_met_in_cpu_time": {
            "cold_lint": cold["python -m modc lint FILE"]["cpu"]["median"] <= TARGET_COLD_S,
            "compile": comp['check_text + build(["urdf"])']["cpu"]["median"] <= TARGET_COMPILE_MS,
            "throughput": cor["in_process"]["cpu_files_per_s"] >= TARGET_FILES_PER_S,
        },
    }
    machine["loadavg_end"] = _loadavg()
    doc["elapsed_s"] = time.perf_counter() - t_start
    print(render_table(doc), file=table_out, flush=True)
    if args.json:
        payload = json.dumps(doc, indent=2)
        if to_stdout_json:
            print(payload)
        else:
            Path(args.json).write_text(payload + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main())
