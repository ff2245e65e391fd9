"""The fuzz campaign of issue 10: many inputs through every reader and checker, and full compiles.

    python scripts/fuzz_campaign.py --state /tmp/fuzz --inputs 100000 --compiles 2000 --seed 1

Inputs come in batches of BATCH from seven generators, in turn: grammar-aware .mod text
(tests/test_fuzz.py's mod_file), valid arms (tests/strategies.py's valid_chains), text and byte
mutations of the examples (test_fuzz's text_mutation, byte_mutation: bytes go through a file on
disk and check_file), the YAML form (mutations of examples/quickstart.yaml and random YAML
documents), DH CSV tables (random and mutated, through dh2mod's convert_table), and the
hand-made attack families of issue 10 at random sizes ("hostile": unit and joint numbers with
thousands of digits, YAML nested up to 2,000 deep or full of aliases, chains of thousands of
units, multi-byte text around the size limit, CR line ends, stray bytes). Every .mod
input that parses is also formatted (`modc fmt`'s format_text; its output must be a fixed point).
Batch k of seed S is drawn by hypothesis with seed (S, k): the same state file and seed give the
same inputs, and an interrupted campaign resumes at the batch it was in (--state holds
state.json and findings.jsonl).

Inputs that check without errors are compiled in full (every backend, collision matrix with
--collision-samples poses) into a fresh directory OUT inside an otherwise empty temporary
directory that is also the working directory; anything written beside OUT is a finding.

A finding is an exception escaping modc (a traceback), a hang or a file outside OUT. A hang is
one input taking more than --timeout seconds of CPU time (SIGPROF: other load on the machine
does not count; a first campaign timed wall-clock and, at load average 8 on 2 cores, flagged
inputs that take under 1 s alone) or more than --wall seconds of wall-clock time (SIGALRM: an
input that blocks, e.g. reading a FIFO, uses no CPU). The process runs with an address-space limit (--memory MB), so
unbounded memory shows as a MemoryError finding. Exit status: 0 with no findings, 1 otherwise.
"""
from __future__ import annotations

import argparse
import json
import os
import re
import resource
import shutil
import signal
import sys
import tempfile
import time
import traceback
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / "tests"), str(ROOT / "scripts")]
FORMS = ("mod", "yaml", "bytes", "dir", "fifo", "zero", "raw", "text", "msg")  # (form, input) items
NUMERIC_OUTPUTS = (".urdf", ".xml", ".srdf", ".xacro", ".yaml", ".json")

BATCH = 100
KINDS = ("grammar", "valid", "text", "bytes", "yaml", "csv", "hostile",  # issue 10
         "design", "library", "traj", "ranking", "cli", "plan", "ws")  # issue 21: scripts/fuzz_surfaces.py
NEW_KINDS = KINDS[7:]
COMPILING = ("valid", "grammar", "text", "hostile", "library")  # kinds whose inputs may be compiled in full
FINDING_TYPES = {"traceback": "tracebacks", "hang": "hangs", "escape": "escapes", "nonfinite": "nonfinite",
                 "resource": "resources"}


import fuzz_surfaces  # noqa: E402  (from scripts/, on the path above)


class Hang(BaseException):  # not an Exception: modc code catching Exception must not swallow it
    pass


_ARMED = [False]  # one Hang per input: the second timer (or a late one) must not hit the handler of the first


def _alarm(signum, frame):
    if _ARMED[0]:
        _ARMED[0] = False
        raise Hang("wall-clock" if signum == signal.SIGALRM else "CPU")


# --- generators (hypothesis strategies, drawn with a fixed seed per batch) -------------------------

def _strategies():
    import strategies as S
    import test_fuzz as F
    from hypothesis import strategies as st

    yaml_text = (ROOT / "examples" / "quickstart.yaml").read_text(encoding="utf-8")
    csv_text = (ROOT / "examples" / "example_a.csv").read_text(encoding="utf-8")

    def mutate(text: str):
        ops = st.lists(st.tuples(st.sampled_from(["insert", "delete", "replace", "swap"]), st.integers(0, 10**6),
                                 st.integers(0, 10**6), F.ALPHABET), min_size=1, max_size=6)

        def apply(steps):
            t = text
            for op, i, j, ch in steps:
                i, j = i % (len(t) + 1), j % (len(t) + 1)
                if op == "insert":
                    t = t[:i] + ch + t[i:]
                elif op == "delete":
                    t = t[:i] + t[i + 1 + j % 6:]
                elif op == "replace":
                    t = t[:i] + ch + t[i + 1:]
                else:
                    a, b = sorted((i, j))
                    t = t[:a] + t[b:] + t[a:b]
            return t

        return ops.map(apply)

    keys = st.sampled_from(["robots", "name", "chain", "unit", "pivot", "port", "link", "base", "tool", "at", "rpy",
                            "payload", "mass", "poses", "limits", "obstacles", "box", "sphere", "cylinder", "size",
                            "radius", "length", "targets", "allow", "library", "x", "<<", "&a", "*a"])
    leaves = st.one_of(st.none(), st.booleans(), st.integers(-10**20, 10**20), st.floats(),
                       st.sampled_from(["H1", "L4(port=45deg)", "45deg", "(0, 0, 0) m", "farm", "1e999 m", "${x}"]),
                       st.text(max_size=12))
    docs = st.recursive(leaves, lambda inner: st.lists(inner, max_size=4) | st.dictionaries(keys, inner, max_size=5),
                        max_leaves=30)

    def dump(doc) -> str:
        import yaml

        return yaml.safe_dump({"robots": doc} if not isinstance(doc, dict) else doc, allow_unicode=True)

    cells = st.one_of(st.floats().map(repr), st.integers(-400, 400).map(str),
                      st.sampled_from(["0", "0.3", "-1.5708", "1e308", "nan", "inf", "", "x", "1,2", "0.1 m"]))
    tables = st.lists(st.lists(cells, min_size=2, max_size=5).map(",".join), max_size=9).map(
        lambda rows: "a,alpha,d,theta\n" + "\n".join(rows) + "\n")
    example = (ROOT / "examples" / "farm.mod").read_text(encoding="utf-8")
    def sized(*scales: int):  # hypothesis favours small integers: draw the magnitude first, then jitter it
        return st.tuples(st.sampled_from(scales), st.integers(0, 99)).map(lambda t: max(1, t[0] + t[0] * t[1] // 100))

    digits = sized(1, 10, 300, 2000, 4300, 6000).map(lambda n: "1" * n)
    hostile = st.one_of(  # the attack families of issue 10, sized at random: (form, input)
        digits.map(lambda d: ("mod", f"robot a {{\n    chain H1 - L{d}\n}}\n")),
        digits.map(lambda d: ("mod", f"robot a {{\n    chain H1 - L1\n    limit joint_{d} (0, 1) deg\n}}\n")),
        digits.map(lambda d: ("yaml", f"robots:\n  - name: a\n    chain: [H1, L{d}]\n")),
        st.tuples(sized(5, 100, 300, 600, 1000), st.sampled_from(["[", "{a: ", "- "])).map(
            lambda t: ("yaml", "robots:\n  - name: a\n    chain: " + t[1] * t[0] + "x"
                       + {"[": "]", "{a: ": "}", "- ": ""}[t[1]] * t[0] + "\n")),
        sized(1, 100, 1500).map(lambda n: ("mod", "robot a {\n    chain H1 - " + " - ".join(["L4(port=45deg)"] * n)
                                            + "\n}\n")),
        sized(10, 100_000, 127_000).map(lambda n: ("mod", "robot a {\n    chain H1 - L1\n}\n# " + "é" * n + "\n")),
        st.sampled_from(["\r", "\r\n", "\n\r"]).map(lambda nl: ("mod", example.replace("\n", nl))),
        st.integers(1, 9).map(lambda k: ("yaml", "a0: &a0 [x, x, x, x, x, x, x, x, x, x]\n" + "".join(
            f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 10)}]\n" for i in range(1, k + 1))
            + f"robots:\n  - name: a\n    chain: *a{k}\n")),
        st.binary(max_size=64).map(lambda b: ("bytes", b"robot a {\n    chain H1 - L1  # " + b + b"\n}\n")),
    )
    import fuzz_surfaces

    return {
        **fuzz_surfaces.strategies(),
        "hostile": hostile,
        "grammar": F.mod_file(),
        "valid": S.valid_chains(),
        "text": F.text_mutation().map(lambda case: case[1]),
        "bytes": F.byte_mutation().map(lambda case: case[1]),
        "yaml": st.one_of(mutate(yaml_text), docs.map(dump)),
        "csv": st.one_of(tables, mutate(csv_text)),
    }


def draw_batch(strategy, n: int, seed: int) -> list:
    from hypothesis import HealthCheck, Phase, given, settings
    from hypothesis import seed as with_seed

    out: list = []

    @settings(max_examples=n, database=None, deadline=None, phases=[Phase.generate],
              suppress_health_check=list(HealthCheck))
    @with_seed(seed)
    @given(strategy)
    def collect(x):
        out.append(x)

    collect()
    return out


# --- running one input ------------------------------------------------------------------------------

def check_one(kind: str, item, work: Path, ctx: dict | None = None):
    """Check one input the way the product does; returns the text when it should be compiled.
    ctx holds what lives across inputs (the view server of the "ws" kind) and the limits."""
    from modc.compiler import check_file, check_text

    if kind in NEW_KINDS:
        return _check_new(kind, item, work, {} if ctx is None else ctx)
    if kind == "hostile":
        kind, item = {"mod": "grammar", "yaml": "yaml", "bytes": "bytes"}[item[0]], item[1]
    if kind == "csv":
        from modc.dh2mod import convert_table

        convert_table(item, "fuzz.csv")
        return None
    if kind == "bytes":
        path = work / "fuzz.mod"
        path.write_bytes(item)
        c = check_file(path)
        return c.sources.get(str(path)) if c.ok else None
    if kind == "yaml":
        c = check_text(item, "fuzz.yaml")
        return None
    import test_fuzz as F

    c = F.assert_sane(item, "fuzz.mod")
    if not any(d.is_error and d.code in F.PARSE_CODES for d in c.diagnostics):
        from modc.syntax.format import format_text

        out, _ = format_text(item, "fuzz.mod")
        if out is not None and format_text(out, "fuzz.mod")[0] != out:
            raise AssertionError("format_text is not idempotent")
    return item if c.ok else None


def _check_new(kind: str, item, work: Path, ctx: dict):
    import fuzz_surfaces as S

    sub = work / kind
    shutil.rmtree(sub, ignore_errors=True)
    sub.mkdir()
    if kind == "ws":
        import fuzz_ws

        if "ws" not in ctx:
            ctx["ws"] = fuzz_ws.ViewServer(work)
        ctx["ws"].send(item)
        return None
    if kind == "cli":
        S.run_cli(item, sub, wall=ctx.get("wall", 60.0) * 0.9, cpu=ctx.get("timeout", 5.0) * 6)
        return None
    return {"design": S.run_design, "library": S.run_library, "traj": S.run_traj, "ranking": S.run_ranking,
            "plan": S.run_plan}[kind](item, sub)


NONFINITE_OUT = re.compile(r"(?<![\w.])[-+]?(inf|nan|infinity)(?![\w.])", re.IGNORECASE)


def compile_one(text: str, samples: int) -> dict | None:
    """Compile in full into OUT in a fresh directory (also the working directory); a finding when
    anything appears beside OUT, or an output (URDF, MJCF, SRDF, YAML) holds inf or nan."""
    from modc.compiler import build, check_text, write_tree
    from modc.files import MANIFEST

    here = os.getcwd()
    root = Path(tempfile.mkdtemp(prefix="modc-fuzz-"))
    try:
        os.chdir(root)
        c = check_text(text, str(root / "in.mod"))
        if not c.ok:
            return None
        files = build(c, collision_samples=samples)
        write_tree(files, root / "out")
        beside = sorted(p.name for p in root.iterdir() if p.name != "out")
        inside = sorted(p.relative_to(root / "out").as_posix() for p in (root / "out").rglob("*") if p.is_file())
        if beside or inside != sorted([*files, MANIFEST]):
            return {"type": "escape",
                    "detail": f"files outside OUT or not listed: beside={beside[:5]} inside={inside[:5]}"}
        for rel, content in sorted(files.items()):
            m = NONFINITE_OUT.search(content) if isinstance(content, str) and rel.endswith(NUMERIC_OUTPUTS) else None
            if m:
                line = content[content.rfind("\n", 0, m.start()) + 1:content.find("\n", m.end())].strip()
                return {"type": "nonfinite", "detail": f"'{m.group(0)}' in {rel.rsplit('/', 1)[-1]}",
                        "line": line[:300]}
        return None
    finally:
        os.chdir(here)
        shutil.rmtree(root, ignore_errors=True)


def _shown(item) -> str:
    """The input of a finding as text: hostile and file items are (form, input); anything else
    (cli (argv, value), plan (text, fractions), ws frames) as JSON."""
    if isinstance(item, tuple) and item[0] in ("dir", "fifo", "zero"):
        return f"<{item[0]}>"  # a special file in place of the input file
    payload = item[1] if isinstance(item, tuple) and isinstance(item[0], str) and item[0] in FORMS else item
    if isinstance(payload, bytes):
        return payload.decode("latin-1")
    return payload if isinstance(payload, str) else json.dumps(payload, default=repr)


def _signature(e: BaseException) -> str:
    frames = [f for f in traceback.extract_tb(e.__traceback__) if "/modc/" in f.filename]
    where = f"{Path(frames[-1].filename).name}:{frames[-1].name}" if frames else "?"
    return f"{type(e).__name__} in {where}"


def run(args) -> int:
    state_dir = Path(args.state)
    state_dir.mkdir(parents=True, exist_ok=True)
    state_path, findings_path = state_dir / "state.json", state_dir / "findings.jsonl"
    kinds = tuple(args.kinds.split(",")) if args.kinds else KINDS
    unknown = [k for k in kinds if k not in KINDS]
    if unknown:
        sys.exit(f"--kinds: no generator {', '.join(unknown)} (there are: {', '.join(KINDS)})")
    state = {"seed": args.seed, "kinds": list(kinds), "batch": 0, "inputs": 0, "compiles": 0, "findings": 0,
             **{v: 0 for v in FINDING_TYPES.values()}, "by_kind": {k: 0 for k in kinds}, "seconds": 0.0}
    if state_path.exists():
        state = json.loads(state_path.read_text())
        if state["seed"] != args.seed or state.get("kinds", list(kinds)) != list(kinds):
            sys.exit(f"{state_path} is a campaign with seed {state['seed']} and kinds {state.get('kinds')}; "
                     "use another --state")
    os.environ.setdefault("MODC_CACHE_DIR", str(state_dir / "cache"))
    if args.memory:
        resource.setrlimit(resource.RLIMIT_AS, (args.memory * 2**20, resource.RLIM_INFINITY))
    signal.signal(signal.SIGALRM, _alarm)
    signal.signal(signal.SIGPROF, _alarm)
    gens = _strategies()
    work = Path(tempfile.mkdtemp(prefix="modc-fuzz-work-"))
    ctx: dict = {"wall": args.wall, "timeout": args.timeout}
    started = time.monotonic()
    try:
        while state["inputs"] < args.inputs or state["compiles"] < args.compiles:
            k = state["batch"]
            kind = kinds[k % len(kinds)]
            if state["inputs"] >= args.inputs and kind not in COMPILING:
                state["batch"] += 1  # only compiles are still wanted: skip kinds that never compile
                continue
            batch = draw_batch(gens[kind], args.batch, args.seed * 1_000_003 + k)
            for i, item in enumerate(batch):
                t0 = time.monotonic()
                finding: dict[str, object] | None = None
                try:
                    _ARMED[0] = True
                    signal.setitimer(signal.ITIMER_PROF, args.timeout)
                    signal.setitimer(signal.ITIMER_REAL, args.wall)
                    text = check_one(kind, item, work, ctx)
                    if text is not None and state["compiles"] < args.compiles:
                        signal.setitimer(signal.ITIMER_PROF, args.timeout * 6)  # a full compile does more
                        signal.setitimer(signal.ITIMER_REAL, args.wall * 6)
                        finding = compile_one(text, args.collision_samples)
                        state["compiles"] += 1
                except Hang as e:
                    limit = args.wall if e.args[0] == "wall-clock" else args.timeout
                    finding = {"type": "hang", "detail": f"over {limit} s of {e.args[0]} time"}
                except fuzz_surfaces.Finding as e:
                    _ARMED[0] = False
                    finding = {"type": e.kind, "detail": e.detail, "traceback": e.text}
                except BaseException as e:  # noqa: BLE001  (a finding, whatever it is)
                    _ARMED[0] = False  # no Hang inside this handler
                    if isinstance(e, KeyboardInterrupt):
                        raise
                    finding = {"type": "traceback", "detail": _signature(e),
                               "traceback": traceback.format_exc()[-3000:]}
                finally:
                    _ARMED[0] = False
                    signal.setitimer(signal.ITIMER_REAL, 0)
                    signal.setitimer(signal.ITIMER_PROF, 0)
                state["inputs"] += 1
                state["by_kind"][kind] = state["by_kind"].get(kind, 0) + 1  # (a state from before --kinds)
                if finding:
                    state["findings"] += 1
                    key = FINDING_TYPES[str(finding["type"])]
                    state[key] = state.get(key, 0) + 1
                    shown = _shown(item)
                    finding.update(kind=kind, batch=k, index=i, seconds=round(time.monotonic() - t0, 2),
                                   input=shown[:4000])
                    with open(findings_path, "a", encoding="utf-8") as f:
                        f.write(json.dumps(finding) + "\n")
                    print(f"finding: {finding['type']} {finding['detail']} ({kind} batch {k} #{i})", file=sys.stderr)
            state["batch"] += 1
            state["seconds"] = round(state["seconds"] + time.monotonic() - started, 1)
            started = time.monotonic()
            tmp = state_path.with_suffix(".tmp")
            tmp.write_text(json.dumps(state, indent=1))
            os.replace(tmp, state_path)  # a killed campaign resumes at this batch
            if args.progress:
                print(f"batch {k}: {state['inputs']} inputs, {state['compiles']} compiles, "
                      f"{state['findings']} findings",
                      file=sys.stderr)
            if args.stop_after and state["batch"] >= args.stop_after:
                break
    finally:
        if "ws" in ctx:
            ctx["ws"].close()
        shutil.rmtree(work, ignore_errors=True)
    print(json.dumps({k: v for k, v in state.items() if k != "seed"}))
    return 1 if state["findings"] else 0


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--state", required=True, help="directory for state.json and findings.jsonl (resumed if present)")
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--inputs", type=int, default=100_000)
    p.add_argument("--compiles", type=int, default=2_000)
    p.add_argument("--timeout", type=float, default=5.0, help="CPU seconds one input may take (a full compile: 6x)")
    p.add_argument("--wall", type=float, default=60.0, help="wall-clock seconds one input may take (a compile: 6x)")
    p.add_argument("--collision-samples", type=int, default=1000)
    p.add_argument("--memory", type=int, default=4096, help="address-space limit in MB (0: none)")
    p.add_argument("--batch", type=int, default=BATCH, help="inputs drawn per batch (keep it for a resumed campaign)")
    p.add_argument("--stop-after", type=int, default=0, help="stop after this batch number (to test resuming)")
    p.add_argument("--progress", action="store_true")
    p.add_argument("--kinds", default="", help=f"comma-separated generators (default: all of {','.join(KINDS)}; "
                   f"only issue 21's: {','.join(NEW_KINDS)})")
    return run(p.parse_args(argv))


if __name__ == "__main__":
    sys.exit(main())
