"""Start-up of the command line: this checkout next to another one (say, the commit before a
start-up change), interleaved, on one core.

    python benchmarks/bench_startup.py --against ../main        # 21 rounds
    python benchmarks/bench_startup.py --against ../main --runs 51 --json out.json
    python benchmarks/bench_startup.py                          # this checkout alone

Commands: `modc --version` and `modc --help` (the command line alone: its imports and the
building of its commands), `modc lint examples/farm.mod` (what a CI check pays), and the anchor
`python -c pass`. Each checkout's modc is imported from its own tree (PYTHONPATH) with a private
bytecode cache, as installed users have it. Reported: medians of the child's CPU time (user +
system; the steadier figure on a shared machine) and of wall time, and per command the
difference between the two checkouts.
"""
from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _common import ROOT, pin_one_core, report  # benchmarks/_common.py

COMMANDS = {
    "modc --version": ["--version"],
    "modc --help": ["--help"],
    "modc lint examples/farm.mod": ["lint", "examples/farm.mod"],
}


def _env(tree: Path, tmp: Path) -> dict[str, str]:
    env = dict(os.environ, PYTHONPATH=str(tree), MODC_CACHE_DIR=str(tmp / "cache"))
    env["PYTHONPYCACHEPREFIX"] = str(tmp / f"pycache-{abs(hash(str(tree)))}")
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    return env


def measure(trees: dict[str, Path], runs: int, tmp: Path) -> dict:
    cases = {("python -c pass", "-"): ([sys.executable, "-c", "pass"], _env(ROOT, tmp), ROOT)}
    for command, args in COMMANDS.items():
        for label, tree in trees.items():
            cases[(command, label)] = ([sys.executable, "-m", "modc", *args], _env(tree, tmp), tree)
    codes = {k: subprocess.run(cmd, env=e, cwd=cwd, capture_output=True).returncode
             for k, (cmd, e, cwd) in cases.items()}  # warm-up: bytecode, Lark's grammar cache
    cpu: dict[tuple[str, str], list[float]] = {k: [] for k in cases}
    wall: dict[tuple[str, str], list[float]] = {k: [] for k in cases}
    for _ in range(runs):
        for key, (cmd, e, cwd) in cases.items():  # interleaved: load changes hit both checkouts alike
            before = resource.getrusage(resource.RUSAGE_CHILDREN)
            t0 = time.perf_counter()
            subprocess.run(cmd, env=e, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            wall[key].append(time.perf_counter() - t0)
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpu[key].append(after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime)
    return {f"{c} [{t}]": {"cpu_s": statistics.median(cpu[(c, t)]), "wall_s": statistics.median(wall[(c, t)]),
                           "exit_code": codes[(c, t)]} for c, t in cases}


def table(rows: dict, trees: dict[str, Path], runs: int, core: int | None) -> str:
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    lines = [f"modc start-up, medians of {runs} interleaved runs, one core (cpu {core}), load average {load:.2f}",
             *(f"  [{label}] {tree}" for label, tree in trees.items()), "",
             f"  {'command':<44}{'cpu ms':>8}{'wall ms':>9}  rc"]
    for name, r in rows.items():
        lines.append(f"  {name:<44}{1000 * r['cpu_s']:>8.0f}{1000 * r['wall_s']:>9.0f}  {r['exit_code']}")
    if len(trees) == 2:
        a, b = trees
        lines.append("")
        for command in COMMANDS:
            x, y = rows[f"{command} [{a}]"]["cpu_s"], rows[f"{command} [{b}]"]["cpu_s"]
            lines.append(f"  {command:<44} {a} - {b}: {1000 * (x - y):+.0f} ms CPU ({(x - y) / y:+.0%})")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--against", type=Path, help="another modc checkout to measure next to this one")
    ap.add_argument("--runs", type=int, default=21, help="rounds (default 21)")
    ap.add_argument("--json", metavar="FILE", help="also write the figures as JSON ('-': stdout)")
    args = ap.parse_args(argv)
    trees = {"this": ROOT}
    if args.against is not None:
        if not (args.against / "modc" / "__init__.py").is_file():
            ap.error(f"{args.against}: not a modc checkout")
        trees["other"] = args.against.resolve()
    core = pin_one_core()
    with tempfile.TemporaryDirectory() as tmp:
        rows = measure(trees, args.runs, Path(tmp))
    doc = {"runs": args.runs, "trees": {k: str(v) for k, v in trees.items()}, "results": rows}
    report(doc, table(rows, trees, args.runs, core), args.json)
    return 0


if __name__ == "__main__":
    sys.exit(main())
