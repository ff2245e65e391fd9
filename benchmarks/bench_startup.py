"""Start-up of the command line, next to its peers (yamllint, xacro) and, if asked, next to another
checkout (say, the commit before a start-up change): interleaved, on one core.

    python benchmarks/bench_startup.py                          # 21 rounds
    python benchmarks/bench_startup.py --against ../main        # both checkouts, same rounds
    python benchmarks/bench_startup.py --runs 51 --json out.json

Commands, each round in turn: the anchor `python -c pass`; `modc --version` and `modc --help`
(the command line alone); `modc lint examples/farm.mod` (what a pre-commit hook or CI check pays),
with modc's cache warm and empty (a fresh install, a CI runner without a cache: the validated
library is made again; the parse's tables are exported from Lark once more);
`modc examples/farm.mod -o OUT` as the first compile of a new arm (the install has run modc
before: the caches keyed by modc's install alone, INSTALL_CACHES (grammar tables, the records'
compiled __init__s, validated built-in library, compiled templates), are warm; every cache keyed
by an arm is empty: builds, meshes, collision matrix, worst-case torques: issue 25's "first compile"), as the first run
after install (every cache empty: shown with its ratio, no goal) and cached (the same compile
again);
and the peers: `yamllint` on the farm's YAML form (benchmarks/data/farm.yaml, about the .mod
file's size; default rules, it passes them) and `xacro` expanding the farm's own .urdf.xacro
(the one modc writes) into a URDF. A peer that is not installed is left out, and so are its
ratios. Each checkout's modc is imported from its own tree (PYTHONPATH) with a private bytecode
cache, as installed users have it. Reported: medians of the child's CPU time (user + system; the
steadier figure on a shared machine) and of wall time, and the goals of issue 25 as ratios of CPU
medians (modc over its peer), met or missed.
"""
from __future__ import annotations

import argparse
import glob
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _common import ROOT, pin_one_core, report  # benchmarks/_common.py

FARM = "examples/farm.mod"
FARM_YAML = ROOT / "benchmarks" / "data" / "farm.yaml"
COMMANDS = {
    "modc --version": ["--version"],
    "modc --help": ["--help"],
    "modc lint examples/farm.mod": ["lint", FARM],
    "modc lint examples/farm.mod (empty cache)": ["lint", FARM],
    "modc farm.mod -o OUT (first compile of a new arm)": [FARM, "-o", "{out}"],
    "modc farm.mod -o OUT (first run after install)": [FARM, "-o", "{out}"],
    "modc farm.mod -o OUT (cached)": [FARM, "-o", "{out}"],
}
NEW_ARM = "modc farm.mod -o OUT (first compile of a new arm)"
AFTER_INSTALL = "modc farm.mod -o OUT (first run after install)"
# run with an empty modc cache every time (what a fresh install or a CI runner without a cache has)
EMPTY_CACHE = (AFTER_INSTALL, "modc lint examples/farm.mod (empty cache)")
# modc's cache kinds keyed by modc's own files alone (grammar tables, validated built-in library,
# compiled templates): warm on an install that has run modc once, whatever arm it compiled
INSTALL_CACHES = ("grammar", "library", "jinja", "records")
# (modc command, peer, at most this many times the peer's CPU time): issue 25's start-up goals
GOALS = [
    ("modc lint examples/farm.mod", "yamllint farm.yaml", 2.0),
    ("modc lint examples/farm.mod", "xacro farm.urdf.xacro", 1.5),
    ("modc farm.mod -o OUT (cached)", "xacro farm.urdf.xacro", 3.0),
    (NEW_ARM, "xacro farm.urdf.xacro", 5.0),
]
# shown next to the goals with their ratio, no goal of their own
INFORMATIONAL = [(AFTER_INSTALL, "xacro farm.urdf.xacro")]


def _env(tree: Path, tmp: Path, cache: Path | None = None) -> dict[str, str]:
    env = dict(os.environ, PYTHONPATH=str(tree), MODC_CACHE_DIR=str(cache or tmp / f"cache-{abs(hash(str(tree)))}"))
    env["PYTHONPYCACHEPREFIX"] = str(tmp / f"pycache-{abs(hash(str(tree)))}")
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    env.pop("MODC_NO_CACHE", None)
    return env


def _tool(name: str) -> str | None:
    """A peer's command: ROS's own (/opt/ros/*/bin), else on PATH, else next to this Python."""
    ros = sorted(glob.glob(f"/opt/ros/*/bin/{name}"))
    if ros:
        return ros[-1]
    here = Path(sys.executable).with_name(name)
    return shutil.which(name) or (str(here) if here.is_file() else None)


def _farm_xacro(tmp: Path) -> Path | None:
    """The farm's .urdf.xacro, as this checkout writes it."""
    out = tmp / "xacro-src"
    subprocess.run([sys.executable, "-m", "modc", FARM, "-o", str(out)], env=_env(ROOT, tmp), cwd=ROOT,
                   capture_output=True)
    found = sorted(out.rglob("*.urdf.xacro"))
    return found[0] if found else None


def _cases(trees: dict[str, Path], tmp: Path) -> dict[tuple[str, str], tuple[list[str], dict, Path]]:
    cases = {("python -c pass", "-"): ([sys.executable, "-c", "pass"], _env(ROOT, tmp), ROOT)}
    for command, args in COMMANDS.items():
        for label, tree in trees.items():
            out = str(tmp / f"out-{label}")
            cases[(command, label)] = ([sys.executable, "-m", "modc", *(a.format(out=out) for a in args)],
                                       _env(tree, tmp), tree)
    yamllint, xacro = _tool("yamllint"), _tool("xacro")
    if yamllint is not None:
        cases[("yamllint farm.yaml", "-")] = ([yamllint, str(FARM_YAML)], _env(ROOT, tmp), ROOT)
    source = _farm_xacro(tmp) if xacro is not None else None
    if xacro is not None and source is not None:
        cases[("xacro farm.urdf.xacro", "-")] = ([xacro, str(source), "-o", str(tmp / "farm.urdf")],
                                                 _env(ROOT, tmp), ROOT)
    return cases


def _time(cmd: list[str], env: dict, cwd: Path) -> tuple[float, float, int]:
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    code = subprocess.run(cmd, env=env, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime, wall, code


def _new_arm_cache(warm: Path, where: Path) -> Path:
    """A modc cache as an install that has run modc before has it: INSTALL_CACHES copied from a warm
    cache, nothing keyed by an arm."""
    where.mkdir(parents=True)
    for kind in INSTALL_CACHES:
        if not (warm / kind).is_dir():  # the definition would be wrong: say so rather than measure another thing
            raise SystemExit(f"bench_startup: the warm cache {warm} has no {kind!r}: is INSTALL_CACHES still modc's?")
        shutil.copytree(warm / kind, where / kind)
    return where


def measure(trees: dict[str, Path], runs: int, tmp: Path) -> dict:
    cases = _cases(trees, tmp)
    codes = {k: subprocess.run(cmd, env=e, cwd=cwd, capture_output=True).returncode
             for k, (cmd, e, cwd) in cases.items()}  # warm-up: bytecode, and the cache the cached compile hits
    cpu: dict[tuple[str, str], list[float]] = {k: [] for k in cases}
    wall: dict[tuple[str, str], list[float]] = {k: [] for k in cases}
    for i in range(runs):
        for key, (cmd, e, cwd) in cases.items():  # interleaved: load changes hit every command alike
            if key[0] in EMPTY_CACHE:  # an empty modc cache every time
                e = dict(e, MODC_CACHE_DIR=str(tmp / f"empty-{EMPTY_CACHE.index(key[0])}-{key[1]}-{i}"))
            elif key[0] == NEW_ARM:  # install-level caches warm (the warm-up made them), the arm's empty
                e = dict(e, MODC_CACHE_DIR=str(_new_arm_cache(Path(e["MODC_CACHE_DIR"]), tmp / f"new-{key[1]}-{i}")))
            c, w, code = _time(cmd, e, cwd)
            cpu[key].append(c)
            wall[key].append(w)
            codes[key] = codes[key] or code
    return {f"{c} [{t}]": {"cpu_s": statistics.median(cpu[(c, t)]), "wall_s": statistics.median(wall[(c, t)]),
                           "exit_code": codes[(c, t)]} for c, t in cases}


def goals(rows: dict, trees: dict[str, Path]) -> list[dict]:
    """The goals' ratios (met or not), then the informational ratios (goal None)."""
    out = []
    for command, peer, limit in [*GOALS, *((c, p, None) for c, p in INFORMATIONAL)]:
        if f"{peer} [-]" not in rows:
            continue
        for label in trees:
            ratio = rows[f"{command} [{label}]"]["cpu_s"] / rows[f"{peer} [-]"]["cpu_s"]
            out.append({"command": command, "tree": label, "peer": peer, "ratio": ratio, "goal": limit,
                        "met": None if limit is None else ratio <= limit})
    return out


def table(rows: dict, trees: dict[str, Path], runs: int, core: int | None, met: list[dict]) -> str:
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    lines = [f"modc start-up, medians of {runs} interleaved runs, one core (cpu {core}), load average {load:.2f}",
             *(f"  [{label}] {tree}" for label, tree in trees.items()),
             f"  files: {FARM} {(ROOT / FARM).stat().st_size} bytes, yamllint's {FARM_YAML.name} "
             f"{FARM_YAML.stat().st_size} bytes", "",
             f"  {'command':<62}{'cpu ms':>8}{'wall ms':>9}  rc"]
    for name, r in rows.items():
        lines.append(f"  {name:<62}{1000 * r['cpu_s']:>8.0f}{1000 * r['wall_s']:>9.0f}  {r['exit_code']}")
    if met:
        lines += ["", "  goals (CPU medians, modc / peer):"]
        for g in met:
            verdict = ("(no goal: informational)" if g["goal"] is None
                       else f"(goal <= {g['goal']:g}x: {'met' if g['met'] else 'MISSED'})")
            lines.append(f"  {g['command'] + ' [' + g['tree'] + ']':<62} / {g['peer']:<22} {g['ratio']:5.2f}x"
                         f"  {verdict}")
    if len(trees) == 2:
        a, b = trees
        lines.append("")
        for command in COMMANDS:
            x, y = rows[f"{command} [{a}]"]["cpu_s"], rows[f"{command} [{b}]"]["cpu_s"]
            lines.append(f"  {command:<62} {a} - {b}: {1000 * (x - y):+.0f} ms CPU ({(x - y) / y:+.0%})")
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
    met = goals(rows, trees)
    doc = {"runs": args.runs, "load_average": os.getloadavg()[0] if hasattr(os, "getloadavg") else None,
           "trees": {k: str(v) for k, v in trees.items()}, "results": rows, "goals": met}
    report(doc, table(rows, trees, args.runs, core, met), args.json)
    return 0


if __name__ == "__main__":
    sys.exit(main())
