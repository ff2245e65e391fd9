"""The generators and runners of issue 21 for the fuzz campaign (scripts/fuzz_campaign.py):

- "design": design blocks (examples/farm_cell.mod and a small problem) with extreme numbers
  (1e400, 1e-320, -0, numbers of hundreds of digits, nan/inf spellings) put in place of their
  numbers; checked, their search space enumerated, the small problem searched;
- "library": the shipped library file with extreme numbers; a robot using it is checked and,
  when it checks, compiled in full (outputs scanned for non-finite numbers);
- "traj": trajectory files (a valid one with extreme numbers, deep nesting, non-UTF-8 bytes,
  huge, wrong types, a directory, a FIFO, /dev/zero) read as `modc check --traj`, `modc play`
  and `modc view --traj` read them;
- "ranking": ranking.json files (the same families) read as `modc view ranking.json` does;
- "cli": random values for the options of every command (--workers, --scheduler, --size,
  --elevation, --ros-package, --timeout, …), each a `python -m modc` subprocess in an empty
  directory holding copies of its inputs: no traceback, exit 0/1/2, inputs unchanged, nothing
  written but the named output;
- "plan": `modc plan` (the API) on random valid arms with a random target, obstacle and `allow`;
- "ws": random websocket frames to one `modc view` server (scripts/fuzz_ws.py).

A runner returns the text of a robot to compile in full, or None; it raises on a finding.
"""
from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
FARM = ROOT / "examples" / "farm.mod"

EXTREME = ["1e400", "-1e400", "1e-320", "-1e-320", "4.9e-324", "1e-400", "-0", "-0.0", "0", "1" * 400, "9" * 40,
           "nan", "NaN", "-nan", "inf", "-inf", "Infinity", ".nan", ".inf", "-.inf", "1e308", "2e308", "0x10",
           "1_000", "+1", "1e", ".", "1.7976931348623157e308", "-9" * 20]
NUMBER = re.compile(r"(?<![\w.])-?\d+(?:\.\d+)?(?:e-?\d+)?(?![\w])")

TINY_DESIGN = """design tiny {
    payload 50 g at (0.01, 0, 0) m
    box wall size (0.05, 0.05, 0.05) m at (0.30, 0.20, 0.10) m
    target t at (0.25, 0, 0.20) m within 5 mm, 2 deg
    units 1 to 2
    modules H1, L1, L4
    links 150 mm to 200 mm step 50 mm
}
"""  # searched in ~0.5 s of CPU time (one design found), so that every input can be
TRAJ = {"robot": "farm", "joint_names": ["joint_1", "joint_2", "joint_3"],
        "points": [{"t": 0.0, "q": [0.0, 0.0, 0.0]}, {"t": 0.5, "q": [0.1, -0.2, 0.3]},
                   {"t": 1.0, "q": [0.2, -0.4, 0.6]}]}
RANKING = {"problem": "farm_cell", "evaluated": 7, "seconds": 1.0, "designs": [
    {"rank": 1, "file": "d_1.mod", "chain": "H1 - L4(pivot=-90deg, port=45deg) - L3(link=180mm)", "modules": 3,
     "mass_kg": 1.874, "torque_margin": 0.9, "design": "farm_cell"},
    {"rank": 2, "file": "d_2.mod", "chain": "H1 - L4(pivot=-90deg, port=45deg) - L3(link=180mm)", "modules": 3,
     "mass_kg": 1.874, "torque_margin": 0.8, "design": "farm_cell"}]}


class Finding(BaseException):  # not an Exception: modc code catching Exception must not swallow it
    """What a runner saw go wrong outside this process or in modc's output: kind (a finding type
    of the campaign), a one-line detail that groups findings, the evidence."""

    def __init__(self, kind: str, detail: str, text: str = ""):
        super().__init__(detail)
        self.kind, self.detail, self.text = kind, detail, text


def tb_detail(text: str) -> str:
    """'ExceptionType: message in file.py:function' of the last traceback in a process's output."""
    lines = text[text.rfind("Traceback"):].splitlines()
    frames = [ln.strip() for ln in lines if ln.strip().startswith("File ")]
    where = re.match(r'File "([^"]+)", line \d+, in (\S+)', frames[-1]) if frames else None
    last = next((ln for ln in reversed(lines) if ln.strip() and not ln.startswith(" ")), "?")
    return f"{last.strip()[:140]} in {Path(where.group(1)).name}:{where.group(2)}" if where else last.strip()[:140]


def extreme_numbers(text: str):
    """A strategy: text with 1 to 4 of its numbers replaced by extreme spellings."""
    from hypothesis import strategies as st

    spots = [m.span() for m in NUMBER.finditer(text)]

    def apply(edits):
        out, chosen = text, sorted({i % len(spots): v for i, v in edits}.items(), reverse=True)
        for k, v in chosen:  # from the end, so earlier spans stay valid
            a, b = spots[k]
            out = out[:a] + v + out[b:]
        return out

    return st.lists(st.tuples(st.integers(0, 10**6), st.sampled_from(EXTREME)), min_size=1, max_size=4).map(apply)


def json_files(base: dict):
    """A strategy of (form, payload): a JSON file's bytes, or a special file ("dir", "fifo", "zero")."""
    from hypothesis import strategies as st

    text = json.dumps(base, indent=1)
    leaves = st.one_of(st.none(), st.booleans(), st.integers(-10**30, 10**30), st.floats(), st.text(max_size=8))
    docs = st.recursive(leaves, lambda inner: st.lists(inner, max_size=4) | st.dictionaries(
        st.sampled_from([*base, "points", "t", "q", "designs", "rank", "file", "chain", "mass_kg", "x"]), inner,
        max_size=5), max_leaves=25)
    sized = st.tuples(st.sampled_from([10, 1000, 100_000, 300_000]), st.integers(1, 99)).map(
        lambda t: t[0] * t[1] // 50)
    return st.one_of(
        extreme_numbers(text).map(lambda t: ("bytes", t.encode())),
        docs.map(lambda d: ("bytes", json.dumps(d).encode())),
        st.tuples(sized, st.sampled_from(["[", '{"a": '])).map(
            lambda t: ("bytes", (t[1] * t[0] + "1" + {"[": "]", '{"a": ': "}"}[t[1]] * t[0]).encode())),
        st.binary(max_size=40).map(lambda b: ("bytes", text[:60].encode() + b + text[60:].encode())),
        sized.map(lambda n: ("bytes", json.dumps({**base, "points": [{"t": k * 0.01, "q": [0.0, 0.0, 0.0]}
                                                                     for k in range(n)]}).encode())),
        sized.map(lambda n: ("bytes", json.dumps({**base, "robot": "x" * n * 10}).encode())),
        st.sampled_from(["dir", "fifo", "zero"]).map(lambda k: (k, b"")),
    )


def put(path: Path, item) -> Path:
    """Write a json_files item at path."""
    form, payload = item
    if form == "dir":
        path.mkdir()
    elif form == "fifo":
        os.mkfifo(path)
    elif form == "zero":
        path.symlink_to("/dev/zero")
    else:
        path.write_bytes(payload)
    return path


# option values: numbers of every kind, addresses, names with newlines, paths, junk
VALUES = ["", " ", "\n", "-1", "0", "1", "2", "3", "0.5", "1e9", "99999999999999999999", "-99999999999999999999",
          "100x100", "0x0", "1x99999", "99999x99999", "65536x65536", "-5x5", "800x600\n", "nanxnan", "1e400x2",
          "tls://127.0.0.1:1", "ucx://127.0.0.1:1", "inproc://x", "tcp://", "tcp://[::1", "127.0.0.1:1", "::",
          "farm_moveit_config\n", "a b", "A", "../x", "/etc/passwd", "/dev/zero", "noetic", "humble\n", "effort",
          "kdl", "urdf,nope", "srdf", "home", "plant", "nope", "-o", "--force", "%s%n", "\u202e", "é" * 300]
WORKERS_CAP = 64  # a process pool larger than this is the finding (Uncapped), before it forks them all
UNCAPPED_EXIT = 97
# `python -m modc` with a guard: a process pool over WORKERS_CAP ends the process with UNCAPPED_EXIT
GUARDED_MAIN = f"""
import concurrent.futures as cf, os, sys
_init = cf.ProcessPoolExecutor.__init__
def _guarded(self, max_workers=None, *a, **kw):
    if max_workers is not None and max_workers > {WORKERS_CAP}:
        sys.stderr.write(f"a process pool of {{max_workers}} workers\\n")
        sys.stderr.flush()
        os._exit({UNCAPPED_EXIT})
    _init(self, max_workers, *a, **kw)
cf.ProcessPoolExecutor.__init__ = _guarded
from modc.cli import main
sys.argv[0] = "modc"
main()
"""


def cli_items():
    """A strategy of (argv template, value): "{v}" in the template is the value; IN/ holds the inputs."""
    from hypothesis import strategies as st

    compile_ = ["IN/farm.mod", "-o", "out", "--collision-samples", "0"]
    render = ["render", "IN/farm.mod", "-o", "out.png", "--size", "64x48"]
    design = ["design", "IN/tiny.mod", "-o", "out", "--no-render"]
    plan = ["plan", "IN/farm.mod", "--to", "plant", "--timeout", "1"]
    templates = [
        ["lint", "IN/farm.mod", "--format", "{v}"], ["check", "IN/farm.mod", "--payload", "{v}"],
        ["check", "IN/farm.mod", "--traj", "{v}"], ["dh2mod", "IN/example_a.csv", "--name", "{v}"],
        *[[*compile_, opt, "{v}"] for opt in ("--ros-package", "--ros-distro", "--ik-solver", "--command-interface",
                                              "--only", "--ros", "--torque", "--library", "--seed")],
        ["IN/farm.mod", "-o", "out", "--only", "srdf", "--collision-samples", "{v}"],
        ["render", "IN/farm.mod", "-o", "out.png", "--size", "{v}"],
        *[[*render, opt, "{v}"] for opt in ("--elevation", "--azimuth", "--colors", "--pose")],
        *[[*design, opt, "{v}"] for opt in ("--workers", "--scheduler", "--max-units", "--top", "--seed",
                                            "--time-budget")],
        ["plan", "IN/farm.mod", "--to", "{v}", "--timeout", "1"], ["plan", "IN/farm.mod", "--to", "plant", "--timeout",
                                                                    "{v}"],
        *[[*plan, opt, "{v}"] for opt in ("--start", "--seed", "--robot")],
        ["sim", "IN/farm.mod", "--engine", "{v}"], ["play", "IN/farm.mod", "--headless", "--traj", "{v}"],
    ]
    curated = st.sampled_from(VALUES + EXTREME)  # drawn 3 times in 5: the values that found crashes
    values = st.one_of(curated, curated, curated, st.integers(-10**25, 10**25).map(str),
                       st.floats().map(repr), st.text(st.characters(blacklist_categories=["Cs"],
                                                                    blacklist_characters="\x00"), max_size=20))
    return st.tuples(st.sampled_from(templates), values)


def plan_arms():
    """A strategy: (the .mod text of a valid arm with a random target t, maybe an obstacle and an
    `allow`, or a one-unit arm; joint fractions for a second target `reach` on tool0's workspace)."""
    import strategies as S
    from hypothesis import strategies as st

    xyz = st.tuples(*[st.floats(-0.8, 0.8).map(lambda v: round(v, 3))] * 3)
    one_unit = st.sampled_from(["L1", "L2", "L3(link=180mm)", "L4(port=45deg)"]).map(
        lambda u: f"robot one {{\n    chain {u}\n    allow first-variant\n}}\n")
    extra = st.tuples(xyz, st.booleans(), st.one_of(st.none(), xyz), st.booleans())

    def arm(t):
        text, (target, rpy, box, allow) = t
        lines = [f"    target t at ({target[0]}, {target[1]}, {target[2]}) m" + (" rpy (0, 90, 0) deg" if rpy else "")]
        if box is not None:
            lines.append(f"    box b size (0.05, 0.05, 0.05) m at ({box[0]}, {box[1]}, {box[2]}) m")
        if allow and "allow" not in text:
            lines.append("    allow first-variant")
        return text.rstrip().rstrip("}") + "\n".join(lines) + "\n}\n"

    fractions = st.lists(st.floats(0, 1), min_size=6, max_size=6)
    return st.tuples(st.tuples(st.one_of(S.valid_chains(2, 4), one_unit), extra).map(arm), fractions)


def strategies() -> dict:
    import fuzz_ws

    lib = (ROOT / "libraries" / "mark2.yaml").read_text(encoding="utf-8")
    lib_values = "\n".join(line for line in lib.splitlines() if not line.lstrip().startswith("#"))
    cell = (ROOT / "examples" / "farm_cell.mod").read_text(encoding="utf-8")
    from hypothesis import strategies as st

    return {"design": st.one_of(extreme_numbers(cell), extreme_numbers(TINY_DESIGN)),
            "library": extreme_numbers(lib_values), "traj": json_files(TRAJ), "ranking": json_files(RANKING),
            "cli": cli_items(), "plan": plan_arms(), "ws": fuzz_ws.ws_frames()}


# --- runners ----------------------------------------------------------------------------------------

# inf or nan printed as a quantity (a quoted token of the input, 'inf', is fine)
NONFINITE = re.compile(r"(?<![\w.'\"])[-+]?(inf|nan|infinity)\s?(m|mm|cm|deg|°|rad|kg|g|N·m|s|%)(?![\w])",
                       re.IGNORECASE)


def no_nonfinite(diagnostics) -> None:
    for d in diagnostics:
        if NONFINITE.search(d.message):
            raise Finding("nonfinite", f"inf/nan as a quantity in {d.code}", d.message[:300])


def sane(text: str, path: str):
    """check_text returns, every diagnostic has a registered code and renders (its span may lie in
    another file: the library's), and no message prints inf or nan as a quantity."""
    from modc.compiler import check_text
    from modc.diagnostics import REGISTRY
    from modc.diagnostics.render import render_json, render_text

    c = check_text(text, path)
    for d in c.diagnostics:
        assert d.code in REGISTRY, d.code
    render_text(c.diagnostics, c.sources)
    render_json(c.diagnostics)
    no_nonfinite(c.diagnostics)
    return c


def run_design(text: str, work: Path) -> None:
    from modc.design import space

    c = sane(text, str(work / "cell.mod"))
    if not c.ok:
        return
    for problem in c.design.problems:
        for n in range(1, min(problem.max_units, 3) + 1):
            space.shapes(problem, n)
        if "design tiny" in text:
            from modc.design.run import design

            design(problem, top=1, max_units=2)


def run_library(text: str, work: Path) -> str | None:
    lib = work / "lib.yaml"
    lib.write_text(text, encoding="utf-8")
    robot = f'robot a {{\n    library "{lib}"\n    chain H1 - L4(port=45deg) - L1\n    pose p (10, 20, 30) deg\n}}\n'
    c = sane(robot, str(work / "a.mod"))
    return robot if c.ok else None


def run_traj(item, work: Path) -> None:
    from modc.compiler import InputError, check_file
    from modc.model.select import RobotChoiceError
    from modc.sim.play import _trajectory_for
    from modc.sim.scene import UsageError
    from modc.view.page import Source, ViewError, read_trajectory

    path = put(work / "traj.json", item)
    try:
        Source(FARM, traj=read_trajectory(str(path))).load(strict=True)  # modc view --traj
    except (ViewError, InputError, RobotChoiceError):  # what `modc view` turns into exit 2
        pass
    try:
        _trajectory_for(check_file(FARM), str(path), None)  # modc play --traj
    except (UsageError, InputError, RobotChoiceError):  # what `modc play` turns into exit 2
        pass


def run_ranking(item, work: Path) -> None:
    from modc.compiler import InputError
    from modc.model.select import RobotChoiceError
    from modc.view.page import Page, Ranking, ViewError

    d = work / "designs"
    d.mkdir()
    for name in ("d_1.mod", "d_2.mod"):
        shutil.copy(FARM, d / name)
    try:
        page = Page.for_ranking(Ranking(put(d / "ranking.json", item)))
        assert isinstance(page.caption, str)
    except (ViewError, InputError, RobotChoiceError):
        pass


def _tree(d: Path) -> dict[str, bytes]:
    return {p.relative_to(d).as_posix(): p.read_bytes() for p in sorted(d.rglob("*")) if p.is_file()}


def run_cli(item, work: Path, wall: float, cpu: float) -> None:
    """One `python -m modc` with an option value, in its own empty directory (IN/ holds copies of
    the inputs). A crash of modc (a signal, a C library's abort) is a finding, not the campaign's end."""
    import resource

    template, value = item
    root = Path(tempfile.mkdtemp(prefix="modc-fuzz-cli-", dir=work))
    (root / "IN").mkdir()
    for src in (FARM, ROOT / "examples" / "example_a.csv"):
        shutil.copy(src, root / "IN" / src.name)
    (root / "IN" / "tiny.mod").write_text(TINY_DESIGN, encoding="utf-8")
    before = _tree(root / "IN")
    argv = [value if a == "{v}" else a for a in template]
    def limits():
        resource.setrlimit(resource.RLIMIT_CPU, (int(cpu) + 1, int(cpu) + 2))

    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]),
           "DISPLAY": "", "WAYLAND_DISPLAY": ""}
    with subprocess.Popen([sys.executable, "-c", GUARDED_MAIN, *argv], cwd=root, env=env, stdout=subprocess.DEVNULL,
                          stderr=subprocess.PIPE, stdin=subprocess.DEVNULL, preexec_fn=limits) as p:
        try:
            _, err = p.communicate(timeout=wall)
        except subprocess.TimeoutExpired:
            p.kill()
            p.communicate()
            raise Finding("hang", f"over {wall:g} s of wall-clock time: modc {argv[0]} {template[-2]}") from None
    err = err.decode("utf-8", "replace")
    if "Traceback" in err:
        raise Finding("traceback", f"modc {argv[0]} {template[-2]}: {tb_detail(err)}", err[-3000:])
    if p.returncode == UNCAPPED_EXIT:
        raise Finding("resource", f"modc {argv[0]} {template[-2]} {value[:30]}: {err.strip()[-100:]}")
    if p.returncode not in (0, 1, 2):
        raise Finding("traceback", f"modc {argv[0]} {template[-2]}: exit {p.returncode}", err[-3000:])
    if _tree(root / "IN") != before:
        raise Finding("escape", f"modc {argv[0]} {template[-2]}: an input file was changed or deleted")
    beside = sorted(q.name for q in root.iterdir() if q.name not in ("IN", "out", "out.png"))
    if beside:
        raise Finding("escape", f"modc {argv[0]} {template[-2]}: files outside OUT: {beside[:5]}")
    shutil.rmtree(root, ignore_errors=True)


def run_plan(item, work: Path) -> None:
    """Plan to the random target t and to a target on the arm's workspace (tool0 at random joint
    values within the limits), so that the planner's later stages run too."""
    import modc
    from modc.compiler import check_text
    from modc.plan import PlanError, plan

    text, fractions = item
    c = check_text(text, "arm.mod")
    if c.ok and c.design.robots:
        robot = c.design.robots[0]
        q = []
        for i in range(robot.dof):
            lo, hi = robot.joint_range(i + 1)
            q.append(lo + fractions[i % len(fractions)] * (hi - lo))
        x, y, z = (float(v) for v in modc.chain(robot).T_base_tool(q)[:3, 3])
        text = text.rstrip().rstrip("}") + f"    target reach at ({x:.4f}, {y:.4f}, {z:.4f}) m\n}}\n"
    path = work / "arm.mod"
    path.write_text(text, encoding="utf-8")
    for target in ("t", "reach"):
        try:
            plan(path, target, timeout=1.0)
        except PlanError as e:
            no_nonfinite(e.diagnostics)
