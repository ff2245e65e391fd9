"""Robustness: whatever the input, checking it yields diagnostics, never an exception (docs/reliability.md).

(a) grammar-aware inputs built from .mod fragments, valid and invalid (unknown units such as H5
    or X1, parameters with and without units, 1e999, nan, junk tokens, unclosed blocks, …);
(b) byte- and character-level mutations of the shipped examples;
(c) `modc lint` in a subprocess on mutated files: exit 0 or 1, no traceback;
(d) oversized inputs (a 10,000-unit chain, a file over 1 MB) end quickly in one clear error;
(e) the YAML form: mutations of a full YAML document, and pinned YAML crashes;
(f) the torque analysis (compile, `modc check`) on generated valid arms, and pinned failures.

The invariant checked for every input (`assert_sane`): check_text returns; every diagnostic has a
registered code with its registered severity, a message, a hint, and a span in the checked file
whose line is at most the text's count of "\n" + 1 (the line where the file ends); the text and
JSON renderers do not fail.
Known crashes (KNOWN_CRASHES) are pinned by xfail tests and skipped by the fuzzers.
"""
from __future__ import annotations

import importlib.util
import json
import random
import subprocess
import sys
import time
from pathlib import Path

import pytest
from conftest import run_cpu
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from modc.compiler import Checked, InputError, check_file, check_text
from modc.diagnostics import REGISTRY
from modc.diagnostics.render import render_json, render_text

ROOT = Path(__file__).resolve().parent.parent
YAML_FORM = importlib.util.find_spec("modc.syntax.yaml_form") is not None
EXAMPLE_FILES = sorted((ROOT / "examples").glob("*.mod"))
EXAMPLES = {p.name: p.read_bytes() for p in EXAMPLE_FILES}

FUZZ = settings(
    max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large]
)

# Known crashes (bugs reported to the lead, each pinned by an xfail test below): a crash raised
# from one of these modc functions with this exception type rejects the example (hypothesis
# `assume`) instead of failing the run, so the fuzzers stay useful for finding new bugs. Remove
# an entry once its bug is fixed.
KNOWN_CRASHES: dict = {}  # none known; add (exception type, modc function): test name while a crash is open


def _known_crash(e: BaseException) -> str | None:
    import traceback

    frames = [f for f in traceback.extract_tb(e.__traceback__) if "/modc/" in f.filename.replace("\\", "/")]
    for (etype, func), test in KNOWN_CRASHES.items():
        if isinstance(e, etype) and frames and frames[-1].name == func:
            return test
    return None


def assert_sane(text: str, path: str = "fuzz.mod", fuzzing: bool = False) -> Checked:
    """check_text(text) returns, with well-formed diagnostics that render. fuzzing: inside a
    hypothesis test, where a known crash rejects the example instead of failing."""
    try:
        c = check_text(text, path)
    except Exception as e:
        if fuzzing and _known_crash(e):
            assume(False)
        raise AssertionError(f"check_text raised {type(e).__name__}: {e}\ninput: {text[:2000]!r}") from e
    from modc.syntax.parser import normalize_newlines

    n_lines = normalize_newlines(text).count("\n") + 1  # modc's count (a lone CR ends a line too)
    for d in c.diagnostics:
        assert d.code in REGISTRY, d
        assert d.severity == REGISTRY[d.code].severity, d
        assert d.message.strip() and d.hint.strip(), d
        s = d.span
        assert s.file == path, d
        assert 1 <= s.line <= n_lines, (d, n_lines)
        assert s.col >= 1 and (s.end_line, s.end_col) >= (s.line, s.col), d
    render_text(c.diagnostics, c.sources)
    json.loads(render_json(c.diagnostics))
    return c


# --- (a) grammar-aware generation ------------------------------------------------------------------

def mostly(valid, invalid, odds: int = 6):
    """`valid` about odds times in odds + 1: inputs should get past the parser often enough
    for the passes behind it to be fuzzed too."""
    return st.sampled_from([True] * odds + [False]).flatmap(lambda ok: valid if ok else invalid)


ODD_NUMBERS = st.sampled_from(["1e999", "-1e999", "1e307", "-1e307", "1e308", "1e-400", "nan", "inf", "-inf",
                               "-0", ".5", "5.", "+3", "1e", "--1", "0x10", "1_000", "45.0.0", ""])
NUMBERS = mostly(
    st.one_of(st.integers(-400, 400).map(str),
              st.floats(-1e4, 1e4, allow_nan=False).map(lambda x: f"{x:.6g}"),
              st.sampled_from(["0", "15", "-90", "45", "0.22", "180", "-180", "360", "0.05"])),
    st.one_of(ODD_NUMBERS, st.floats(allow_nan=False, allow_infinity=False).map(repr)),
    odds=40,
)
KIND_UNITS = {"angle": ["deg", "rad"], "length": ["m", "mm", "cm"], "mass": ["kg", "g"]}
ODD_MEASURES = st.sampled_from(["", "degrees", "meters", "X1", "m/s", "Deg", "deg", "m", "kg", "µm", "H1"])
UNIT_NAMES = mostly(st.sampled_from(["H1", "H2", "H3", "H4", "L1", "L2", "L3", "L4"]),
                    st.sampled_from(["H5", "X1", "L0", "h1", "H10", "HL1", "L9", "Q4"]), odds=5)
PARAM_NAMES = mostly(st.sampled_from(["pivot", "port", "link"]), st.sampled_from(["pivt", "twist", "Port", "x"]))
NAMES = mostly(st.sampled_from(["farm", "cell", "a", "_x", "p1", "home", "shelf", "H1", "joint_1", "wrist"]),
               st.sampled_from(["robot", "chain", "9lives", "é", "a-b", ""]), odds=30)
JOINTS = mostly(
    st.sampled_from(["joint_1", "joint_2", "joint_3"]), st.sampled_from(["joint_7", "joint_0", "j1", "base"]), odds=4
)
CODE_NAMES = mostly(st.sampled_from(["first-variant", "last-variant", "illegal-succession", "epsilon-exceeded"]),
                    st.sampled_from([*REGISTRY, "foo", "first_variant", "Missing-Unit"]), odds=3)
SPACE = st.sampled_from([" ", "\n", "\n", "  ", "\t", " # note\n", "\r\n"])
PARAM_OF = {"pivot": "angle", "port": "angle", "link": "length"}


@st.composite
def quantity(draw, kind="angle"):
    unit = draw(mostly(st.sampled_from(KIND_UNITS[kind]), ODD_MEASURES, odds=4))
    return draw(NUMBERS) + draw(st.sampled_from(["", " "])) + unit


@st.composite
def vector(draw, kind="length", n=3):
    size = draw(mostly(st.just(n), st.integers(0, 5)))
    values = [draw(NUMBERS) for _ in range(size)]
    close = draw(mostly(st.just(")"), st.sampled_from(["", "]", "))"]), odds=40))
    unit = draw(mostly(st.sampled_from(KIND_UNITS[kind]), ODD_MEASURES, odds=4))
    return "(" + draw(st.sampled_from([", ", ",", " , "])).join(values) + close + " " + unit


@st.composite
def unit(draw):
    name = draw(UNIT_NAMES)
    if draw(st.booleans()):
        return name
    params = []
    for _ in range(draw(st.integers(0, 3))):
        key = draw(PARAM_NAMES)
        eq = draw(mostly(st.sampled_from(["=", " = "]), st.sampled_from([" ", "==", ":"]), odds=40))
        params.append(key + eq + draw(quantity(PARAM_OF.get(key, "angle"))))
    close = draw(mostly(st.just(")"), st.sampled_from(["", ",)", "("]), odds=40))
    return name + "(" + ", ".join(params) + close


@st.composite
def chain(draw):
    units = draw(st.lists(unit(), min_size=1, max_size=8))
    out = units[0]
    for u in units[1:]:
        out += draw(mostly(st.sampled_from([" - ", "-", " -"]), st.sampled_from([" ", " -- ", " + "]), odds=40)) + u
    return "chain " + out


@st.composite
def dh_block(draw):
    rows = []
    for _ in range(draw(st.integers(0, 7))):
        params = [("a", "length"), ("alpha", "angle"), ("d", "length"), ("theta", "angle")]
        chosen = draw(mostly(st.just(params[:3]), st.lists(st.sampled_from(params + [("q", "length")]), max_size=5)))
        if draw(st.booleans()):
            chosen = [*chosen, params[3]]
        rows.append("row " + ", ".join(f"{k}={draw(quantity(kind))}" for k, kind in chosen))
    fit = draw(st.sampled_from(["", "fit-links "]))
    return f"dh {fit}{{\n        " + "\n        ".join(rows) + "\n    }"


@st.composite
def at(draw):
    return " at " + draw(vector("length"))


@st.composite
def rpy(draw):
    return " rpy " + draw(vector("angle")) if draw(st.booleans()) else ""


@st.composite
def statement(draw):
    kind = draw(st.sampled_from(["chain", "library", "base", "tool", "payload", "pose", "limit",
                                 "box", "sphere", "cylinder", "target", "allow", "dh"]))
    if kind == "dh":
        return draw(dh_block())
    if kind == "chain":
        return draw(chain())
    if kind == "library":
        return "library " + draw(st.sampled_from(["mark2", "mark2-strict", "mark3", '"nope.yaml"', '"mark2"']))
    if kind in ("base", "tool"):
        return kind + (draw(at()) if draw(st.booleans()) else "") + draw(rpy())
    if kind == "payload":
        return "payload " + draw(quantity("mass")) + (draw(at()) if draw(st.booleans()) else "")
    if kind == "pose":
        return f"pose {draw(NAMES)} {draw(vector('angle', n=draw(st.integers(1, 6))))}"
    if kind == "limit":
        return f"limit {draw(JOINTS)} {draw(vector('angle', n=2))}"
    if kind == "box":
        return f"box {draw(NAMES)} size {draw(vector())}{draw(at())}{draw(rpy())}"
    if kind == "sphere":
        return f"sphere {draw(NAMES)} radius {draw(quantity('length'))}{draw(at())}"
    if kind == "cylinder":
        name, radius, length = draw(NAMES), draw(quantity("length")), draw(quantity("length"))
        return f"cylinder {name} radius {radius} length {length}{draw(at())}{draw(rpy())}"
    if kind == "target":
        return f"target {draw(NAMES)}{draw(at())}"
    return "allow " + ", ".join(draw(st.lists(CODE_NAMES, min_size=1, max_size=3)))


JUNK = st.one_of(
    st.sampled_from(
        ["}", "{", "robot", "(", ")", "-", "=", ",", "@", "$", '"open string', "# comment", "42", "deg", "chain"]
    ),
    st.text(min_size=1, max_size=6),
)


@st.composite
def robot(draw):
    stmts = [draw(mostly(chain(), dh_block(), odds=5))] if draw(mostly(st.just(True), st.just(False))) else []
    stmts += draw(st.lists(mostly(statement(), JUNK, odds=60), max_size=7))
    if draw(st.integers(0, 9)) == 0:
        stmts = draw(st.permutations(stmts))
    sp = draw(SPACE)
    close = draw(mostly(st.just("}"), st.just(""), odds=30))
    return f"robot {draw(NAMES)} {{" + sp + (draw(SPACE) + "    ").join(stmts) + sp + close


@st.composite
def mod_file(draw):
    parts = draw(st.lists(mostly(robot(), st.one_of(statement(), JUNK), odds=30), min_size=0, max_size=3))
    head = draw(mostly(st.sampled_from(["", "# header\n", "\n\n"]), st.just("\ufeff"), odds=30))
    return head + "\n".join(parts) + draw(st.sampled_from(["", "\n"]))


# A guard on the generator itself: enough of its inputs get past the parser that the lowering and
# the semantic passes are fuzzed too (a run typically reaches 20+ of their codes).
PARSE_CODES = {"syntax-error", "unexpected-character", "unclosed-block", "missing-dash", "missing-equals",
               "expected-statement", "expected-robot", "empty-file", "input-too-large"}
MIN_SEMANTIC_CODES = 8


@pytest.mark.slow
def test_generated_mod_text_never_crashes():
    seen: set[str] = set()

    @settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
    @given(mod_file())
    def run(text):
        c = assert_sane(text, fuzzing=True)
        seen.update(d.code for d in c.diagnostics)
        if not c.diagnostics:
            seen.add("<no diagnostics>")

    run()
    semantic = seen - PARSE_CODES - {"<no diagnostics>"}
    assert len(semantic) >= MIN_SEMANTIC_CODES, f"the generator rarely gets past the parser; reached {sorted(seen)}"


@pytest.mark.slow
@settings(max_examples=100, deadline=None)
@given(st.lists(unit(), min_size=1, max_size=8), st.sampled_from(["mark2", "mark2-strict"]))
def test_generated_chains_never_crash(units, library):
    """Chains alone (well-formed around them), so the passes behind the parser get exercised."""
    text = f"robot arm {{\n    library {library}\n    chain " + " - ".join(units) + "\n}\n"
    assert_sane(text, fuzzing=True)


# --- (b) mutations of the examples -----------------------------------------------------------------

ALPHABET = st.one_of(
    st.sampled_from(
        list('{}()-=,#"\n\t .0123456789eE+')
        + ["deg", "rad", "mm", "H", "L", "robot", "chain", "\r", "\x00", "é", "\u2028"]
    ),
    st.characters(),
)


@st.composite
def byte_mutation(draw):
    name = draw(st.sampled_from(sorted(EXAMPLES)))
    data = bytearray(EXAMPLES[name])
    for _ in range(draw(st.integers(1, 8))):
        op = draw(st.sampled_from(["insert", "delete", "replace", "truncate", "duplicate"]))
        i = draw(st.integers(0, max(0, len(data) - 1)))
        if op == "insert":
            data[i:i] = draw(st.binary(min_size=1, max_size=4))
        elif op == "delete":
            del data[i:i + draw(st.integers(1, 8))]
        elif op == "replace":
            data[i:i + 1] = draw(st.binary(min_size=1, max_size=1))
        elif op == "truncate":
            del data[i:]
        else:
            j = draw(st.integers(i, min(len(data), i + 40)))
            data[j:j] = data[i:j]
    return name, bytes(data)


@st.composite
def text_mutation(draw):
    name = draw(st.sampled_from(sorted(EXAMPLES)))
    text = EXAMPLES[name].decode("utf-8")
    for _ in range(draw(st.integers(1, 6))):
        op = draw(st.sampled_from(["insert", "delete", "replace", "swap"]))
        i = draw(st.integers(0, len(text)))
        if op == "insert":
            text = text[:i] + draw(ALPHABET) + text[i:]
        elif op == "delete":
            text = text[:i] + text[i + draw(st.integers(1, 6)):]
        elif op == "replace":
            text = text[:i] + draw(ALPHABET) + text[i + 1:]
        else:
            j = draw(st.integers(0, len(text)))
            a, b = sorted((i, j))
            text = text[:a] + text[b:] + text[a:b]
    return name, text


@pytest.mark.slow
@FUZZ
@given(byte_mutation())
def test_byte_mutated_examples_never_crash(case):
    _, data = case
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError:
        text = data.decode("utf-8", errors="replace")
    assert_sane(text, "mutant.mod", fuzzing=True)


@pytest.mark.slow
@FUZZ
@given(text_mutation())
def test_text_mutated_examples_never_crash(case):
    _, text = case
    assert_sane(text, "mutant.mod", fuzzing=True)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(byte_mutation())
def test_byte_mutated_files_are_read_or_rejected_cleanly(tmp_path, case):
    """From disk: either checked, or an InputError (bad-encoding) carrying a diagnostic."""
    name, data = case
    p = tmp_path / name
    p.write_bytes(data)
    try:
        c = check_file(p)
    except InputError as e:
        d = e.diagnostic
        assert d.code == "bad-encoding", d
        assert 1 <= d.span.line <= data.count(b"\n") + 1 and d.span.col >= 1
        return
    assert_sane(c.sources[str(p)], str(p), fuzzing=True)


def test_examples_check_clean():
    """The unmutated examples are the baseline the mutations start from."""
    assert EXAMPLES
    for name, data in EXAMPLES.items():
        c = assert_sane(data.decode("utf-8"), name)
        assert not [d for d in c.diagnostics if d.is_error], (name, c.diagnostics)


# --- (c) the command line on mutated files ------------------------------------------------------------

def _mutants(n: int, seed: int) -> list[tuple[str, str]]:
    rng = random.Random(seed)
    out = []
    chars = list("{}()-=,#\"\n .0123456789") + ["deg", "H5", "X1", "1e999", "é", "\t"]
    for k in range(n):
        name = sorted(EXAMPLES)[k % len(EXAMPLES)]
        text = EXAMPLES[name].decode("utf-8")
        for _ in range(rng.randint(1, 5)):
            i = rng.randrange(len(text) + 1)
            op = rng.choice(["insert", "delete", "replace"])
            if op == "insert":
                text = text[:i] + rng.choice(chars) + text[i:]
            elif op == "delete":
                text = text[:i] + text[i + rng.randint(1, 5):]
            else:
                text = text[:i] + rng.choice(chars) + text[i + 1:]
        out.append((name, text))
    return out


@pytest.mark.slow
@pytest.mark.parametrize("fmt", ["text", "json"])
def test_lint_subprocess_on_mutated_files(tmp_path, fmt):
    paths = []
    for k, (name, text) in enumerate(_mutants(4, seed={"text": 1, "json": 2}[fmt])):
        p = tmp_path / f"{k}-{name}"
        p.write_text(text, encoding="utf-8")
        paths.append(str(p))
    r = subprocess.run([sys.executable, "-m", "modc", "lint", "--format", fmt, *paths],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode in (0, 1), r.stderr
    assert "Traceback" not in r.stderr and "Traceback" not in r.stdout
    if fmt == "json":
        doc = json.loads(r.stdout)
        assert {d["file"] for d in doc["diagnostics"]} <= set(paths)
        assert r.returncode == (1 if any(d["severity"] == "error" for d in doc["diagnostics"]) else 0)


# --- (d) oversized inputs ---------------------------------------------------------------------------

# "Quickly" is a bound on the work done, so it is CPU time (of this process, or of a child), which
# other load on the machine does not stretch; 10x what these take alone. Speed is benchmarks/' job.
CPU_LIMIT_S = 5.0


@pytest.mark.slow
def test_ten_thousand_unit_chain_is_rejected_quickly():
    text = "robot snake {\n    chain " + " - ".join(["H1"] * 9_999 + ["L1"]) + "\n}\n"
    t0 = time.process_time()
    c = assert_sane(text, "snake.mod")
    render_text(c.diagnostics, c.sources)
    cpu = time.process_time() - t0
    assert [(d.code, d.span.line) for d in c.diagnostics] == [("too-many-units", 2)]
    assert "10,000 units" in c.diagnostics[0].message
    assert cpu < CPU_LIMIT_S, f"{cpu:.2f} s of CPU time"


def test_oversized_dh_table_is_one_error():
    text = "robot snake {\n    dh {\n" + "        row a=0.3 m, alpha=14deg, d=0 m\n" * 1_000 + "    }\n}\n"
    c = assert_sane(text, "snake.mod")
    assert [d.code for d in c.diagnostics] == ["too-many-units"]


def test_one_megabyte_file_is_rejected_quickly(tmp_path):
    unit = "robot a { chain H1 - L4(port=45deg) - L1 }\n"
    text = unit * (1_000_000 // len(unit) + 1)
    assert len(text) > 1_000_000
    t0 = time.process_time()
    c = assert_sane(text, "big.mod")
    assert [d.code for d in c.diagnostics] == ["input-too-large"]
    # the same through the file reader, and one huge line (a minified or binary file)
    p = tmp_path / "big.mod"
    p.write_text("x" * 1_048_576, encoding="utf-8")
    c = check_file(p)
    assert [d.code for d in c.diagnostics] == ["input-too-large"]
    render_text(c.diagnostics, c.sources)
    cpu = time.process_time() - t0
    assert cpu < CPU_LIMIT_S, f"{cpu:.2f} s of CPU time"


def test_long_single_line_renders_a_window():
    line = "robot a { chain " + " - ".join(["H1"] * 5) + " - X9 - L1" + " " * 5000 + "}"
    c = assert_sane(line, "long.mod")
    out = render_text(c.diagnostics, c.sources)
    assert "error[unknown-module]" in out
    assert max(len(x) for x in out.splitlines()) < 400


# --- known crashes, pinned ------------------------------------------------------------------------

@pytest.mark.parametrize("param", ["pivot", "port"])
def test_huge_twist_angle_in_radians(param):
    c = assert_sane(f"robot farm {{\n    chain H1 - H4({param}=1e307rad) - L4\n}}\n")
    assert [(d.code, d.span.line) for d in c.diagnostics] == [("out-of-range", 2)]


@pytest.mark.parametrize("limit", ["(1, 0) deg", "(171, 175) deg"], ids=["inverted", "disjoint"])
def test_inverted_limit_with_a_dh_table(limit):
    text = (
        "robot planar {\n    dh {\n        row a=0.3 m, alpha=0deg, d=0 m\n        row a=0 m, alpha=0deg, d=0.075 m\n"
        f"    }}\n    limit joint_1 {limit}\n}}\n"
    )
    c = assert_sane(text)
    assert any(d.is_error and d.span.line == 6 for d in c.diagnostics), c.diagnostics


def test_huge_angles_elsewhere_are_diagnosed():
    """Poses and limits far beyond any angle are out of range, not a crash or a garbled number."""
    c = assert_sane("robot farm {\n    chain H1 - L4 - L1\n    limit joint_1 (-1e307, 1e307) rad\n"
                    "    pose p (1e307, 0, 0) rad\n}\n")
    assert {d.code for d in c.diagnostics} == {"out-of-range"}


# --- (f) the torque analysis (compile and `modc check` run it; lint does not) -----------------------

def _has_analyses() -> bool:
    from modc.passes import Context

    return "analyses" in getattr(Context, "__dataclass_fields__", {})


TORQUE = frozenset({"torque"})
needs_analyses = pytest.mark.skipif(not _has_analyses(), reason="the pass Context has no `analyses` (torque check)")


@st.composite
def valid_arm(draw):
    """A rule-abiding arm (H^k L^m) with realisable twists and printable links, and extras."""
    k, m = draw(st.integers(1, 3)), draw(st.integers(1, 3))
    units = []
    for v in ["H"] * k + ["L"] * m:
        kind = draw(st.integers(1, 4))
        params = []
        if draw(st.booleans()):
            params.append(f"pivot={draw(st.sampled_from(range(-90, 91, 15)))}deg")
        if kind >= 3 and draw(st.booleans()):
            params.append(f"port={draw(st.sampled_from(range(-165, 181, 15)))}deg")
        if kind >= 3 and draw(st.booleans()):
            params.append(f"link={draw(st.integers(50, 500))}mm")
        units.append(f"{v}{kind}" + (f"({', '.join(params)})" if params else ""))
    extra = []
    if draw(st.booleans()):
        extra.append(f"payload {draw(st.floats(0.001, 20)):.4g} kg at (0, 0, {draw(st.floats(-1, 1)):.3g}) m")
    if draw(st.booleans()):
        extra.append(
            f"tool at ({draw(st.floats(-1, 1)):.3g}, 0, {draw(st.floats(-1, 1)):.3g}) m "
            f"rpy (0, {draw(st.integers(-180, 180))}, 0) deg"
        )
    if draw(st.booleans()):
        extra.append(
            f"base at (0, 0, 0.5) m rpy ({draw(st.integers(-180, 180))}, {draw(st.integers(-180, 180))}, 0) deg"
        )
    if draw(st.booleans()):
        extra.append(
            f"limit joint_{draw(st.integers(1, k + m))} ({draw(st.integers(-170, 0))}, {draw(st.integers(1, 170))}) deg"
        )
    return "robot arm {\n    chain " + " - ".join(units) + "\n    " + "\n    ".join(extra) + "\n}\n"


@pytest.mark.slow
@needs_analyses
@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(valid_arm())
def test_torque_analysis_on_valid_arms_never_crashes(text):
    try:
        c = check_text(text, "arm.mod", analyses=TORQUE)
    except Exception as e:
        raise AssertionError(f"{type(e).__name__}: {e}\n{text}") from e
    assert {d.code for d in c.diagnostics} <= {"torque-over-peak", "torque-over-nominal", "limit-exceeds-hardware"}, (
        c.diagnostics
    )
    for d in c.diagnostics:
        assert 1 <= d.span.line <= text.count("\n") + 1 and d.hint


@needs_analyses
def test_limit_disjoint_from_the_hardware_range():
    text = "robot farm {\n    chain H1 - L4(port=45deg) - L1\n    limit joint_1 (171, 175) deg\n}\n"
    c = check_text(text, "l.mod", analyses=TORQUE)
    assert any(d.is_error and d.span.line == 3 for d in c.diagnostics), c.diagnostics


@needs_analyses
def test_empty_dh_table_under_the_torque_analysis():
    c = check_text("robot planar {\n    dh {\n    }\n}\n", "e.mod", analyses=TORQUE)
    assert any(d.is_error for d in c.diagnostics)


@needs_analyses
@pytest.mark.parametrize("extra", ["payload 1 kg at (1e200, 0, 0) m", "tool at (1e200, 0, 0) m\n    payload 1 kg"],
                         ids=["payload-offset", "tool-offset"])
def test_absurd_offsets_are_not_silently_accepted(extra):
    text = f"robot farm {{\n    chain H1 - H4(pivot=-90deg) - L1\n    {extra}\n}}\n"
    c = check_text(text, "o.mod", analyses=TORQUE)
    assert any(d.is_error for d in c.diagnostics), c.diagnostics


# --- (e) the YAML form ------------------------------------------------------------------------------

YAML_DOC = """# every statement of the YAML form
robots:
  - name: cell
    library: mark2
    chain: [H1, "H4(pivot=-90deg, link=200mm)", {unit: L4, port: 45deg}]
    tool: {at: "(0, 0, 0.05) m", rpy: "(0, 90, 0) deg"}
    base: {at: "(1, 0, 0) m"}
    payload: {mass: 200 g, at: "(0, 0, 0.01) m"}
    poses: {home: "(0, 30, -45) deg"}
    limits: {joint_2: "(-90, 90) deg"}
    obstacles:
      - {box: shelf, size: "(0.6, 0.4, 0.02) m", at: "(0.3, 0, 0.25) m", rpy: "(0, 0, 10) deg"}
      - {sphere: ball, radius: 0.05 m, at: "(0.2, 0.2, 0.2) m"}
      - {cylinder: post, radius: 0.02 m, length: 0.5 m, at: "(-0.3, 0, 0.25) m"}
    targets: {p1: "(0.3, 0.1, 0.4) m"}
    allow: [first-variant]
"""
YAML_ALPHABET = st.one_of(
    st.sampled_from(list("{}[]:,-'\"#\n &*!|>?%@`") + ["  ", "null", "~", "1e999", ".nan", "yes", "0x1F", "- ",
                                                         ": ", "deg", "? ", "&a ", "*a", "!!str ", "\t"]),
    st.characters(),
)


@st.composite
def yaml_mutation(draw):
    text = YAML_DOC
    for _ in range(draw(st.integers(1, 5))):
        op = draw(st.sampled_from(["insert", "delete", "replace"]))
        i = draw(st.integers(0, len(text)))
        if op == "insert":
            text = text[:i] + draw(YAML_ALPHABET) + text[i:]
        elif op == "delete":
            text = text[:i] + text[i + draw(st.integers(1, 6)):]
        else:
            text = text[:i] + draw(YAML_ALPHABET) + text[i + 1:]
    return text


@pytest.mark.skipif(not YAML_FORM, reason="modc.syntax.yaml_form is not implemented yet")
def test_yaml_document_is_valid():
    c = assert_sane(YAML_DOC, "doc.yaml")
    assert not c.diagnostics


@pytest.mark.slow
@pytest.mark.skipif(not YAML_FORM, reason="modc.syntax.yaml_form is not implemented yet")
@FUZZ
@given(yaml_mutation())
def test_yaml_mutations_never_crash(text):
    assert_sane(text, "mutant.yaml", fuzzing=True)


@pytest.mark.skipif(not YAML_FORM, reason="modc.syntax.yaml_form is not implemented yet")
@pytest.mark.parametrize("text", [
    "robots:\n  - name: a\n    chain: [H1, L1]\n    ? [x, y]\n    : 1\n",
    "? [robots]\n: []\n",
], ids=["in-robot", "top-level"])
def test_yaml_complex_mapping_key(text):
    c = assert_sane(text, "k.yaml")
    assert "yaml-schema" in {d.code for d in c.diagnostics}


@pytest.mark.skipif(not YAML_FORM, reason="modc.syntax.yaml_form is not implemented yet")
@pytest.mark.parametrize("text", [
    "robots: &r\n  - name: a\n    chain: *r\n",
    "robots:\n  - &a {name: a, chain: [H1, L1], poses: *a}\n",
], ids=["sequence", "mapping"])
def test_yaml_recursive_alias(text):
    c = assert_sane(text, "r.yaml")
    assert "yaml-schema" in {d.code for d in c.diagnostics}


@pytest.mark.skipif(not YAML_FORM, reason="modc.syntax.yaml_form is not implemented yet")
def test_yaml_alias_bomb_is_rejected_quickly(tmp_path):
    lines = ["a0: &a0 [x, x, x, x, x, x, x, x, x, x]"]
    lines += [f"a{i}: &a{i} [" + ", ".join([f"*a{i - 1}"] * 10) + "]" for i in range(1, 7)]
    text = "\n".join(lines) + "\nrobots: []\n"
    assert len(text) < 500
    bomb = tmp_path / "bomb.yaml"
    bomb.write_text(text, encoding="utf-8")
    # in a subprocess, so that an expanding bomb costs its CPU time (+ start-up), not the test run;
    # the timeout only guards against a hang
    code = ("import json, sys; from modc.compiler import check_file; "
            "print(json.dumps([d.code for d in check_file(sys.argv[1]).diagnostics]))")
    p, cpu = run_cpu([sys.executable, "-c", code, str(bomb)], timeout=600)
    assert p.returncode == 0, p.stderr
    assert cpu < CPU_LIMIT_S, f"checking a {len(text)}-byte YAML file took {cpu:.2f} s of CPU time"
    assert json.loads(p.stdout) == ["yaml-schema"]  # aliases are refused before they expand
