"""What a cold `modc lint` reuses from modc's cache (issue 25, item 3): the grammar's LALR tables
and the validated library, each keyed by content and never trusted when torn or altered; and the
model as plain records that need no pydantic."""
from __future__ import annotations

import dataclasses
import hashlib
import json
import marshal
import os
import subprocess
import sys

import pytest
from conftest import EXAMPLES, ROOT

from modc.model import library as L
from modc.model import library_check as C
from modc.model.robot import InvalidModel, Pose, Robot, Target, Transform, UnitSpec
from modc.syntax import parser

_PROBE = """
import json, sys
from modc.cli import main
try:
    main(sys.argv[1:])
except SystemExit as e:
    code = e.code
else:
    code = 0
sys.stderr.write(json.dumps({"exit": code, "modules": sorted(sys.modules)}))
"""


def _run(args: list[str], cache_dir) -> tuple[int, set[str]]:
    env = dict(os.environ, MODC_CACHE_DIR=str(cache_dir))
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), *filter(None, [env.get("PYTHONPATH")])])
    env.pop("MODC_NO_CACHE", None)
    p = subprocess.run([sys.executable, "-c", _PROBE, *args], capture_output=True, text=True, env=env, cwd=ROOT)
    doc = json.loads(p.stderr.strip().splitlines()[-1])
    return doc["exit"], set(doc["modules"])


def test_a_lint_with_a_warm_cache_imports_no_pydantic_no_yaml_and_no_other_command(tmp_path):
    farm = str(ROOT / "examples" / "farm.mod")
    code, first = _run(["lint", farm], tmp_path)
    assert code == 0
    assert "pydantic" in first and "yaml" in first  # the library really was validated, once
    code, again = _run(["lint", farm], tmp_path)
    assert code == 0
    assert not {"pydantic", "pydantic_core", "yaml"} & again
    # the lint's own runner, no other command's module, and neither click (a plain command line) nor
    # lark (the grammar's tables run by modc.syntax.lalr) nor anything heavy
    assert "modc.cli.lint_run" in again and not {"modc.cli.design_cmd", "modc.cli.motion", "modc.cli.view"} & again
    assert not {"click", "lark", "jinja2", "numpy", "rich", "pygments"} & again, again


def test_a_lint_command_line_click_would_read_otherwise_goes_to_click(tmp_path):
    farm = str(ROOT / "examples" / "farm.mod")
    for args in (["lint", "-q", farm, "--format=json"], ["lint", farm, "--sarif-root", ".", "-f", "sarif"]):
        code, modules = _run(args, tmp_path)
        assert code == 0 and "click" not in modules, args
    for args in (["lint", "-fjson", farm], ["lint", "--quiet", "--quiet", farm], ["lint", "--", farm],
                 ["lint", "-f", "yaml", farm], ["lint"], ["lint", "--help"]):
        code, modules = _run(args, tmp_path)
        assert "click" in modules, args  # click reads it, as before: its output and exit code are the command's
        assert code == (2 if args in (["lint", "-f", "yaml", farm], ["lint"]) else 0), args


def test_the_plain_lint_command_line_means_what_click_reads_in_it():
    from modc.cli.lint import lint_cmd
    from modc.cli.lint_run import plain_args

    for args in (["a.mod"], ["a.mod", "b.mod", "-q"], ["-f", "github", "a.mod"], ["--format=sarif", "a.mod"],
                 ["--library", "lib.yaml", "a.mod", "--sarif-root=src"], ["--quiet", "dir", "--library=mark2"]):
        ours = plain_args(args)
        assert ours is not None, args
        ctx = lint_cmd.make_context("lint", list(args))
        theirs = dict(ctx.params, files=list(ctx.params["files"]))
        assert {**theirs, **ours} == theirs, args  # the same values; the rest are click's defaults
        defaults = {"format": "text", "library": None, "quiet": False, "sarif_root": "."}
        assert {**defaults, **ours} == theirs, args
    for args in ([], ["-q"], ["-h", "a.mod"], ["-qf", "json", "a.mod"], ["--library", "-x", "a.mod"],
                 ["--quiet=1", "a.mod"], ["-f", "a.mod"], ["--form", "json", "a.mod"], ["-", "a.mod"]):
        assert plain_args(args) is None, args


def test_the_command_line_still_has_every_command():
    from modc.cli import app
    from modc.cli.app import COMMANDS

    assert list(app.commands) == list(COMMANDS)


# --- the grammar's tables ---------------------------------------------------------------------------

@pytest.fixture
def cache_dir(tmp_path, monkeypatch):
    monkeypatch.setenv("MODC_CACHE_DIR", str(tmp_path))
    monkeypatch.delenv("MODC_NO_CACHE", raising=False)
    parser._lark.cache_clear()
    parser._runtime.cache_clear()
    L._load_path.cache_clear()
    L._builtin.cache_clear()
    yield tmp_path
    parser._lark.cache_clear()
    parser._runtime.cache_clear()
    L._load_path.cache_clear()
    L._builtin.cache_clear()


def _tables(cache_dir):
    (entry,) = (cache_dir / "grammar").glob("*.lalr")
    return entry


def test_tables_from_the_cache_parse_as_freshly_built_ones(cache_dir):
    built = parser._lark()  # a miss: built, then stored
    entry = _tables(cache_dir)
    loaded = parser._load_tables(entry.name, parser._OPTIONS)
    assert loaded is not None and loaded is not built
    for path in EXAMPLES:
        text = path.read_text(encoding="utf-8")
        assert loaded.parse(text, start="start") == built.parse(text, start="start"), path.name
    assert {t.name for t in loaded.terminals} == {t.name for t in built.terminals}


@pytest.mark.parametrize("damage", ["torn", "flipped", "not lark's", "empty"])
def test_a_damaged_tables_entry_is_rebuilt_never_used(cache_dir, damage):
    parser._lark()
    entry = _tables(cache_dir)
    blob = entry.read_bytes()
    if damage == "torn":
        blob = blob[: len(blob) // 2]
    elif damage == "flipped":
        blob = blob[:-10] + bytes([blob[-10] ^ 1]) + blob[-9:]
    elif damage == "not lark's":  # a valid digest over data that is no parser
        payload = marshal.dumps(({"parser": 1}, {}))
        blob = hashlib.sha256(payload).hexdigest().encode() + b"\n" + payload
    else:
        blob = b""
    entry.write_bytes(blob)
    assert parser._load_tables(entry.name, parser._OPTIONS) is None
    parser._lark.cache_clear()
    ast_file, diags = parser.parse((ROOT / "examples" / "farm.mod").read_text(encoding="utf-8"), "farm.mod")
    assert not diags and ast_file.robots[0].name.text == "farm"
    _, diags = parser.parse("robot a {\n", "bad.mod")  # a syntax error is Lark's to describe: its tables again
    assert diags[0].code == "unclosed-block"
    assert parser._load_tables(entry.name, parser._OPTIONS) is not None  # rewritten whole


def test_the_tables_key_is_the_grammar_and_lark(cache_dir):
    a = parser._tables_name("start: NAME", parser._OPTIONS, "1.3.1")
    assert a != parser._tables_name("start: NAME ", parser._OPTIONS, "1.3.1")
    assert a != parser._tables_name("start: NAME", parser._OPTIONS, "1.3.2")
    assert a != parser._tables_name("start: NAME", {**parser._OPTIONS, "keep_all_tokens": True}, "1.3.1")


# --- the library ------------------------------------------------------------------------------------

def _entry(cache_dir):
    (entry,) = (cache_dir / "library").glob("*.json")
    return entry


def test_a_cached_library_equals_the_validated_one(cache_dir):
    fresh = C.validate(str(L.resolve("mark2")))
    assert L.load("mark2") == fresh  # a miss: validated, stored
    _entry(cache_dir)
    L._load_path.cache_clear()
    L._builtin.cache_clear()
    hit = L.load("mark2")
    assert hit == fresh and hit is not fresh
    assert type(hit.variants["H"].actuator) is L.Actuator and set(hit.units) == set(fresh.units)  # int keys


@pytest.mark.parametrize("damage", ["flipped", "unknown record", "not JSON"])
def test_a_damaged_library_entry_is_ignored(cache_dir, damage, monkeypatch):
    fresh = L.load("mark2")
    entry = _entry(cache_dir)
    digest, _, payload = entry.read_bytes().partition(b"\n")
    if damage == "flipped":
        blob = digest + b"\n" + payload.replace(b'"mass": 0.57', b'"mass": 9.57', 1)
    else:
        payload = (b'{"$record": "Path", "x": 1}' if damage == "unknown record" else b"{not json")
        blob = hashlib.sha256(payload).hexdigest().encode() + b"\n" + payload
    entry.write_bytes(blob)
    assert C._from_cache(entry.name) is None
    L._load_path.cache_clear()
    L._builtin.cache_clear()
    validated = []
    monkeypatch.setattr(C, "validate", lambda path, real=C.validate: validated.append(path) or real(path))
    assert L.load("mark2") == fresh and validated


def test_the_library_entry_is_keyed_by_the_file_and_errors_are_never_cached(cache_dir, tmp_path):
    from modc.compiler import check_text

    src = 'robot r {\n    library "lib.yaml"\n    chain H1 - L4(port=45deg) - L1\n}\n'
    text = (ROOT / "libraries" / "mark2.yaml").read_text(encoding="utf-8")
    (tmp_path / "lib.yaml").write_text(text.replace("torque_peak: 30.5 ", "torque_peak: 1e300", 1))
    for _ in range(2):
        L._load_path.cache_clear()
        c = check_text(src, str(tmp_path / "a.mod"))
        assert [d.code for d in c.diagnostics] == ["out-of-range"]
    assert not (cache_dir / "library").exists() or not list((cache_dir / "library").glob("*.json"))
    (tmp_path / "lib.yaml").write_text(text.replace("torque_peak: 30.5 ", "torque_peak: 31.5 ", 1))
    L._load_path.cache_clear()
    c = check_text(src, str(tmp_path / "a.mod"))
    assert not [d for d in c.diagnostics if d.is_error]
    assert c.design.robots[0].library.variants["H"].actuator.torque_peak == 31.5


# --- the model as records ---------------------------------------------------------------------------

def test_model_values_are_frozen_checked_and_compare_by_value():
    a = Robot(name="arm", poses=[Pose(name="home", q=[0, 1])])  # type: ignore[arg-type]
    assert a.poses == (Pose(name="home", q=(0.0, 1.0)),) and type(a.poses[0].q[1]) is float
    assert a == Robot(name="arm", poses=(Pose(name="home", q=(0.0, 1.0)),)) and a != Robot(name="arm2")
    assert hash(Transform(xyz=(1, 2, 3))) == hash(Transform(xyz=(1.0, 2.0, 3.0)))
    with pytest.raises(dataclasses.FrozenInstanceError):
        a.name = "other"  # type: ignore[misc]
    with pytest.raises(InvalidModel):
        UnitSpec(name="a b")
    with pytest.raises(TypeError):
        Robot(nme="arm")  # type: ignore[call-arg]
    with pytest.raises(TypeError):
        Target(xyz=(0, 0, 0))  # type: ignore[call-arg]  (no name)


def test_model_copy_construct_and_dump_behave_as_pydantic_did():
    r = Robot(name="arm", units=(UnitSpec(name="H1"),))
    c = r.model_copy(update={"name": "arm2"})
    assert c.name == "arm2" and c.units is r.units and r.name == "arm"
    with pytest.raises(TypeError):
        r.model_copy(update={"nme": "x"})
    point = Target.model_construct(name="tray[0,1,0]", xyz=(0.0, 0.0, 0.0))  # unchecked, defaults filled
    assert point.name == "tray[0,1,0]" and point.rpy is None
    dump = r.model_dump()
    assert "span" not in dump and "torque" not in dump and dump["units"][0]["name"] == "H1"
    assert "span" not in repr(r) and "name='arm'" in repr(r)


def test_the_formatter_s_own_tables_are_cached_and_format_alike(cache_dir):
    from modc.syntax import format as fmt

    text = (ROOT / "examples" / "farm.mod").read_text(encoding="utf-8").replace("    chain", "  chain", 1)
    fmt._lark.cache_clear()
    built = fmt.format_text(text, "farm.mod")  # a miss: built, stored
    assert len(list((cache_dir / "grammar").glob("*.lalr"))) >= 1
    fmt._lark.cache_clear()
    assert fmt.format_text(text, "farm.mod") == built and built[0] is not None and "\n    chain" in built[0]
    fmt._lark.cache_clear()


def test_the_records_code_cache_is_written_once_and_a_damaged_one_is_ignored(tmp_path):
    """The generated __init__ of every record is compiled once per Python and kept in modc's
    cache; a damaged entry is never used (its digest fails): the command compiles them again."""
    env = dict(os.environ, MODC_CACHE_DIR=str(tmp_path), PYTHONPATH=str(ROOT))

    def lint() -> subprocess.CompletedProcess:
        return subprocess.run([sys.executable, "-m", "modc", "lint", str(ROOT / "examples" / "farm.mod")],
                              capture_output=True, text=True, env=env, cwd=ROOT)

    assert lint().returncode == 0
    entries = list((tmp_path / "records").iterdir())
    assert len(entries) == 1 and entries[0].stat().st_size > 1000
    stamp = entries[0].stat().st_mtime_ns
    assert lint().returncode == 0 and entries[0].stat().st_mtime_ns == stamp  # warm: nothing new to write
    blob = bytearray(entries[0].read_bytes())
    blob[-10] ^= 0xFF
    entries[0].write_bytes(bytes(blob))
    r = lint()
    assert r.returncode == 0 and "Traceback" not in r.stderr and "0 errors" in r.stderr
