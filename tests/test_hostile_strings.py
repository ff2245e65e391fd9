"""Hostile strings: one identifier rule for every name, library strings validated, outputs escaped
by construction, and nothing xacro would expand comes from user text (issue 10, part 1).

Classes of input, each through both forms and every backend:
- names (robot, unit, pose, target, obstacle, joint reference) holding any XML, YAML or xacro
  metacharacter, a line break or non-ASCII: rejected with invalid-name at the name (YAML form), or
  with a syntax error at the name (.mod, whose grammar lexes names), and refused by the model itself;
- names longer than modc.names.MAX_NAME: invalid-name in both forms;
- library strings (name, variant names, descriptions, actuator model, source): library-invalid at
  the offending line of the library file;
- text that is allowed to reach outputs (the input file's name, library descriptions): every XML
  output parses, every YAML output loads, every Python launch file compiles, no output has more
  "${" or "$(" than with plain text, and xacro run on every .xacro, .urdf and .srdf written never
  runs the canary payload (a payload proven to run when placed where xacro evaluates).
"""
from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from conftest import ROOT

from modc import names
from modc.compiler import build, check_text, write_tree
from modc.model import JointLimit, Obstacle, Pose, Robot, Target, Transform, UnitSpec

XACRO = Path(sys.executable).with_name("xacro")

METACHARACTERS = ["a<b", "a>b", "a&b", 'a"b', "a'b", "${x}", "a${x}", "$(arg x)", "a\nb", "a-->b", "a:b", "a#b",
                  "é", "arm\u2028x", "a b", "a-b", "a/b", "1a", "", "a\x00b", "a\tb", "a.b"]
TOO_LONG = "a" * (names.MAX_NAME + 1)
AT = '        at: "(1, 1, 1) m"'
FARM = "robot farm {\n    chain H1 - L4(port=45deg) - L1\n}\n"


# --- the rule itself -----------------------------------------------------------------------------

@pytest.mark.parametrize("bad", [*METACHARACTERS, TOO_LONG], ids=repr)
def test_the_model_refuses_any_other_name(bad):
    """No backend can see a non-identifier: the model's Name type refuses it (lowering reports it
    first, as a diagnostic, so this is the guarantee, not the user's path)."""
    makes = [
        lambda: Robot(name=bad),
        lambda: UnitSpec(name=bad),
        lambda: Pose(name=bad, q=()),
        lambda: Target(name=bad, xyz=(0, 0, 0)),
        lambda: Obstacle(name=bad, shape="sphere", size=(1.0,), origin=Transform()),
        lambda: JointLimit(joint=bad, lower=0, upper=1),
    ]
    for make in makes:
        with pytest.raises(ValueError):  # the model's InvalidModel
            make()


def test_the_rule_is_the_grammars():
    """modc.names states the .mod grammar's own NAME and LIBRARY_REF terminals (one rule, two forms)."""
    from modc.syntax.parser import _lark

    assert _lark().get_terminal("NAME").pattern.value == names.IDENTIFIER
    assert _lark().get_terminal("LIBRARY_REF").pattern.value == names.LABEL
    assert re.fullmatch(_lark().get_terminal("UNIT_NAME").pattern.value, "H" * names.MAX_VARIANT + "4")


def test_the_rule_accepts_identifiers_up_to_the_limit():
    for good in ("a", "_", "A_9", "joint_1", "a" * names.MAX_NAME):
        assert names.identifier_problem(good) is None
        Pose(name=good, q=())


RULES = {"identifier": (names.identifier_problem, "joint_1"), "variant": (names.variant_problem, "H"),
         "label": (names.label_problem, "mark2-strict"),
         "ros package": (names.ros_package_problem, "farm_moveit_config")}


@pytest.mark.parametrize("rule", RULES)
@pytest.mark.parametrize("tail", ["\n", "\r\n", "\n\n", " ", "\x00"], ids=repr)
def test_every_rule_matches_the_whole_string(rule, tail):
    """`^…$` with re.match lets a trailing newline through; every rule refuses it."""
    problem, good = RULES[rule]
    assert problem(good) is None
    assert problem(good + tail) is not None


def test_ros_package_with_a_trailing_newline_is_refused(tmp_path):
    """It reached package:// URIs and launch files, one line too many."""
    src = tmp_path / "a.mod"
    src.write_text(FARM)
    for bad in ("farm_pkg\n", "farm_pkg\r\n", "farm__pkg", "farm_pkg_", "Farm"):
        r = subprocess.run([sys.executable, "-m", "modc", str(src), "-o", str(tmp_path / "out"), "--ros", "2",
                            "--ros-package", bad], capture_output=True, text=True)
        assert r.returncode == 2 and "is not a valid ROS package name" in r.stderr, (bad, r.stderr)
        assert "\n'" not in r.stderr.replace("\\n'", "")  # the name is shown escaped, on one line
        assert not (tmp_path / "out").exists()


# --- names in the YAML form ------------------------------------------------------------------------

def _yaml_robot(kind: str, name: str) -> tuple[str, str]:
    """A YAML robot with `name` in one name position; returns (text, marker) where marker is the
    quoted name as written, whose position the diagnostic must point at."""
    q = json.dumps(name)  # a JSON string is a YAML double-quoted scalar
    robot = {"robot": f"  - name: {q}\n    chain: [H1, {{unit: L4, port: 45deg}}, L1]\n"}.get(kind)
    if robot is None:
        lines = ["  - name: farm", "    chain: [H1, {unit: L4, port: 45deg}, L1]"]
        lines += {
            "unit": [],
            "pose": ["    poses:", f"      {q}: \"(0, 0, 0) deg\""],
            "target": ["    targets:", f"      {q}: \"(0.3, 0, 0.2) m\""],
            "limit": ["    limits:", f"      {q}: \"(0, 10) deg\""],
            "box": ["    obstacles:", f"      - box: {q}", "        size: \"(0.1, 0.1, 0.1) m\"", AT],
            "sphere": ["    obstacles:", f"      - sphere: {q}", "        radius: 0.1 m", AT],
            "cylinder": ["    obstacles:", f"      - cylinder: {q}", "        radius: 0.1 m", "        length: 0.2 m",
                         AT],
        }[kind]
        if kind == "unit":
            lines[1] = f"    chain: [H1, {{unit: {q}, port: 45deg}}, L1]"
        robot = "\n".join(lines) + "\n"
    return "robots:\n" + robot, q


YAML_KINDS = ["robot", "unit", "pose", "target", "limit", "box", "sphere", "cylinder"]


@pytest.mark.parametrize("kind", YAML_KINDS)
@pytest.mark.parametrize("bad", [*METACHARACTERS, TOO_LONG], ids=repr)
def test_yaml_names_are_rejected_at_the_name(kind, bad):
    text, marker = _yaml_robot(kind, bad)
    c = check_text(text, "t.yaml")
    errors = [d for d in c.diagnostics if d.is_error]
    assert [d.code for d in errors] == ["invalid-name"], [(d.code, d.message) for d in errors]
    d = errors[0]
    offset = text.index(marker)
    line = text.count("\n", 0, offset) + 1
    col = offset - (text.rfind("\n", 0, offset) + 1) + 1
    assert (d.span.line, d.span.col) == (line, col)
    assert "\n" not in d.message and len(d.message) < 200  # the name is quoted escaped and cut short
    assert not c.design.robots or all(r.name == "farm" for r in c.design.robots)


@pytest.mark.parametrize("kind", YAML_KINDS)
def test_yaml_names_at_the_limit_are_fine(kind):
    name = ("joint_" + "1" * 58) if kind == "limit" else ("H1" if kind == "unit" else "a" * names.MAX_NAME)
    text, _ = _yaml_robot(kind, name)
    codes = {d.code for d in check_text(text, "t.yaml").diagnostics}
    assert "invalid-name" not in codes


# --- names in .mod -------------------------------------------------------------------------------

MOD_POSITIONS = {
    "robot": "robot {n} {{\n    chain H1 - L4(port=45deg) - L1\n}}\n",
    "pose": "robot farm {{\n    chain H1 - L4(port=45deg) - L1\n    pose {n} (0, 0, 0) deg\n}}\n",
    "target": "robot farm {{\n    chain H1 - L4(port=45deg) - L1\n    target {n} at (0.3, 0, 0.2) m\n}}\n",
    "limit": "robot farm {{\n    chain H1 - L4(port=45deg) - L1\n    limit {n} (0, 10) deg\n}}\n",
    "box": "robot farm {{\n    chain H1 - L4(port=45deg) - L1\n    box {n} size (0.1, 0.1, 0.1) m at (1, 1, 1) m\n}}\n",
    "sphere": "robot farm {{\n    chain H1 - L4(port=45deg) - L1\n    sphere {n} radius 0.1 m at (1, 1, 1) m\n}}\n",
    "cylinder": "robot farm {{\n    chain H1 - L4(port=45deg) - L1\n"
                "    cylinder {n} radius 0.1 m length 0.2 m at (1, 1, 1) m\n}}\n",
}
SYNTAX_CODES = {"unexpected-character", "syntax-error", "expected-statement", "missing-equals", "unclosed-block",
                "expected-robot"}


@pytest.mark.parametrize("kind", list(MOD_POSITIONS))
@pytest.mark.parametrize("bad", [b for b in METACHARACTERS if b and b[0].isalpha() and b not in ("a b",)], ids=repr)
def test_mod_names_with_metacharacters_are_syntax_errors_at_the_name(kind, bad):
    """The .mod grammar lexes a name as an identifier: anything else stops the parse right there."""
    text = MOD_POSITIONS[kind].format(n=bad)
    c = check_text(text, "t.mod")
    errors = [d for d in c.diagnostics if d.is_error]
    assert errors and {d.code for d in errors} <= SYNTAX_CODES | {"invalid-name"}, [(d.code, d.message) for d in errors]
    offset = text.index(bad)
    line = text.count("\n", 0, offset) + 1
    bad_at = offset + next(i for i, ch in enumerate(bad) if not re.fullmatch(names.IDENTIFIER, bad[: i + 1]))
    bad_line = text.count("\n", 0, bad_at) + 1
    assert errors[0].span.line in (line, bad_line, bad_line + 1), (errors[0], line)
    assert not any(r.name == bad for r in c.design.robots)


@pytest.mark.parametrize("kind", list(MOD_POSITIONS))
def test_mod_names_too_long_are_invalid_names(kind):
    name = "joint_" + "1" * names.MAX_NAME if kind == "limit" else TOO_LONG
    text = MOD_POSITIONS[kind].format(n=name)
    c = check_text(text, "t.mod")
    assert [(d.code, d.span.line, d.span.col) for d in c.diagnostics if d.is_error] == [
        ("invalid-name", text.count("\n", 0, text.index(name)) + 1,
         text.index(name) - text.rfind("\n", 0, text.index(name)))]


def test_a_250_character_robot_name_fails_lint_not_the_compile():
    """Issue 10: it passed lint, then died on 'file name too long'."""
    c = check_text(FARM.replace("farm", "a" * 250), "t.mod")
    assert [d.code for d in c.diagnostics] == ["invalid-name"]


def test_a_unit_name_with_thousands_of_digits_is_a_diagnostic():
    c = check_text(FARM.replace("L1\n", "L" + "1" * 5000 + "\n"), "t.mod")
    assert [d.code for d in c.diagnostics] == ["invalid-name"]


# --- library strings -----------------------------------------------------------------------------

MARK2 = (ROOT / "libraries" / "mark2.yaml").read_text(encoding="utf-8")

# (what, regex of the line to replace in mark2.yaml, replacement template with {v})
LIBRARY_FIELDS = [
    ("name", r"^name: .*$", "name: {v}"),
    ("description", r"^description: .*$", "description: {v}"),
    ("source", r"^source: .*$", "source: {v}"),
    ("variant", r"^  L:$", "  {v}:"),
    ("variant description", r"^    description: Light .*$", "    description: {v}"),
    ("actuator model", r"^      model: KA-58$", "      model: {v}"),
    ("first_variant", r"^  first_variant: .*$", "  first_variant: {v}"),
]
LIBRARY_BAD = {
    "name": ["a b", "mark2\n", "a<b", "${x}", "é", "a" * 65],
    "description": ["line\nbreak", "bell\x07", "rtl\u202eoverride", "ls\u2028sep", "x" * (names.MAX_TEXT + 1)],
    "source": ["line\nbreak", "nul\x00"],
    "variant": ["L'", "L_", "L2", "L x", "L-->", "${L}", "é", "L" * 17],
    "variant description": ["a\rb"],
    "actuator model": ["KA\n58"],
    "first_variant": ["H'", "H\n"],
}


def _library_case(tmp_path: Path, what: str, value: str) -> tuple[Path, int]:
    _, pattern, template = next(f for f in LIBRARY_FIELDS if f[0] == what)
    m = re.search(pattern, MARK2, flags=re.M)
    assert m, pattern
    text = MARK2[: m.start()] + template.format(v=json.dumps(value)) + MARK2[m.end():]
    path = tmp_path / "lib.yaml"
    path.write_text(text, encoding="utf-8")
    return path, MARK2.count("\n", 0, m.start()) + 1


@pytest.mark.parametrize(("what", "value"), [(w, v) for w, vs in LIBRARY_BAD.items() for v in vs], ids=repr)
def test_library_strings_are_validated_in_the_library_file(tmp_path, what, value):
    lib, line = _library_case(tmp_path, what, value)
    src = tmp_path / "t.mod"
    c = check_text(FARM.replace("{\n", '{\n    library "lib.yaml"\n', 1), str(src))
    errors = [d for d in c.diagnostics if d.is_error]
    assert [d.code for d in errors] == ["library-invalid"], [(d.code, d.message) for d in errors]
    d = errors[0]
    assert (d.span.file, d.span.line) == (str(lib), line), d
    assert c.sources.get(str(lib)) is not None  # the caret excerpt can show the library's line


def test_library_numbers_must_be_finite(tmp_path):
    path = tmp_path / "lib.yaml"
    for bad in (".nan", ".inf", "-.inf"):
        assert "    lower_deg: -170  " in MARK2
        path.write_text(MARK2.replace("    lower_deg: -170  ", f"    lower_deg: {bad}  ", 1), encoding="utf-8")
        c = check_text(FARM.replace("{\n", '{\n    library "lib.yaml"\n', 1), str(tmp_path / "t.mod"))
        assert [d.code for d in c.diagnostics] == ["library-invalid"], bad
        assert "finite" in c.diagnostics[0].message and c.diagnostics[0].span.file == str(path)



def test_library_text_may_hold_metacharacters(tmp_path):
    """Free text is not an identifier: <, &, quotes, ${...}, -- and unicode are fine (escaped on output)."""
    lib, _ = _library_case(tmp_path, "description", "<a> & \"b\" 'c' ${d} $(e) -- é °")
    c = check_text(FARM.replace("{\n", '{\n    library "lib.yaml"\n', 1), str(tmp_path / "t.mod"))
    assert not c.diagnostics


# --- outputs: escaped by construction --------------------------------------------------------------

def _payload(canary: str) -> str:
    """Python that xacro's expression sandbox runs: it reaches os.system through object's subclasses
    (names with dunders are refused by xacro, so they are looked up as strings)."""
    return ("[python.vars(python.type(g))['__get__'](g, f)['system']('touch " + canary + "') "
            "for c in python.vars(python.type)['__subclasses__'](python.type(1).mro()[-1]) "
            "if '_wrap_close' in python.str(c) for f in [python.vars(c)['__init__']] "
            "for g in [python.vars(python.type(f))['__globals__']]][0] and 'x'")


def _xacro(path: Path, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([str(XACRO), str(path)], cwd=cwd, capture_output=True, text=True, timeout=60)


@pytest.fixture(scope="module")
def canary_dir(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("canary")


@pytest.mark.skipif(not XACRO.exists(), reason="the xacro command is not installed in this environment")
def test_the_canary_payload_runs_where_xacro_evaluates(tmp_path):
    """Positive control: the payload used below does run when xacro evaluates it as ${...}, so its
    silence in modc's outputs means something. ($(eval ...) cannot hold it: xacro ends a substitution
    argument at the first ')'; "$(" is checked by counting, below.)"""
    for i, form in enumerate(("${%s}",)):
        doc = tmp_path / f"t{i}.xacro"
        expr = form % _payload(f"fired{i}")
        doc.write_text('<?xml version="1.0"?>\n<robot name="t" xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
                       f'  <link name="{expr}"/>\n</robot>\n', encoding="utf-8")
        r = _xacro(doc, tmp_path)
        assert r.returncode == 0, r.stderr
        assert (tmp_path / f"fired{i}").exists()


HOSTILE_TEXT = "a-->b&c<d>'e\"f #g: h\n\x01é\u2028 -"  # a file name may hold anything but '/'
LIBRARY_TEXT = "a-->b&c<d>'e\"f #g: h é ° ${x} $(y) -"  # library text holds no control characters


def _hostile_tree(tmp_path: Path, text_of) -> tuple[dict, dict]:
    """(hostile build, plain build): the same arm compiled with a hostile / plain file name and
    library text (description, source, actuator model, variant description)."""
    out = {}
    for kind in ("hostile", "plain"):
        d = tmp_path / kind
        d.mkdir()
        lib = MARK2
        for what in ("description", "source", "actuator model", "variant description"):
            _, pattern, template = next(f for f in LIBRARY_FIELDS if f[0] == what)
            value = text_of(what) if kind == "hostile" else "plain text"
            lib = re.sub(pattern, lambda m, t=template, v=value: t.format(v=json.dumps(v)), lib, count=1, flags=re.M)
        (d / "lib.yaml").write_text(lib, encoding="utf-8")
        name = text_of("file").replace("/", "_") + ".mod" if kind == "hostile" else "plain.mod"
        text = ("robot farm {\n    library \"lib.yaml\"\n    chain H1 - L4(port=45deg) - L1\n"
                "    tool at (0.05, 0, 0) m\n    payload 0.2 kg\n    pose bent (0, 30, -45) deg\n"
                "    box crate size (0.2, 0.2, 0.2) m at (0.6, 0, 0.1) m\n    target p1 at (0.3, 0, 0.2) m\n}\n")
        c = check_text(text, str(d / name))
        assert c.ok, [(x.code, x.message) for x in c.diagnostics]
        out[kind] = build(c, collision_samples=50)
    return out["hostile"], out["plain"]


def _check_formats(files: dict) -> None:
    from lxml import etree

    for rel, content in files.items():
        if isinstance(content, bytes):
            continue
        if rel.endswith((".urdf", ".srdf", ".xacro", ".launch", ".xml")):
            etree.fromstring(content.encode("utf-8"))  # raises on malformed XML
        elif rel.endswith((".yaml", ".rviz", ".setup_assistant")):
            yaml.safe_load(content)
        elif rel.endswith(".py"):
            compile(content, rel, "exec")
        elif rel.endswith(".json"):
            json.loads(content)


def test_metacharacters_in_the_file_name_and_library_text_give_valid_outputs(tmp_path):
    hostile, plain = _hostile_tree(tmp_path, lambda what: HOSTILE_TEXT if what == "file" else LIBRARY_TEXT)
    assert sorted(hostile) == sorted(plain)  # no file is named after the text
    _check_formats(hostile)
    for rel, content in hostile.items():
        if isinstance(content, str) and not rel.endswith(".json"):
            assert "\x01" not in content and "\u2028" not in content, rel


def test_no_output_expands_user_text(tmp_path, canary_dir):
    """The payload in the file name and every library string that reaches outputs: no output has
    more ${ or $( than the same build from plain text, and xacro on every .xacro, .urdf and .srdf
    written runs none of it."""
    hostile, plain = _hostile_tree(tmp_path, lambda what: "${" + _payload(f"canary_{what.replace(' ', '_')}") + "}"
                                   if what != "source" else "$(eval " + _payload("canary_eval") + ")")
    for rel, content in hostile.items():
        if isinstance(content, str) and not rel.endswith(".json"):  # report.json is data: it keeps the name as it is
            for opener in ("${", "$("):
                assert content.count(opener) == plain[rel].count(opener), (rel, opener)
    # the payloads did reach the outputs (neutralised in comments), they were not just dropped
    assert "python.vars" in hostile["urdf/mod3_farm.urdf"] and "python.vars" in hostile["urdf/modc_modules.xacro"]
    out = canary_dir / "out"
    write_tree(hostile, out, force=True)
    ran = 0
    for path in sorted(out.rglob("*")):
        if path.suffix in (".xacro", ".urdf", ".srdf"):
            r = _xacro(path, canary_dir)
            assert r.returncode == 0, (path, r.stderr)
            ran += 1
    assert ran >= 6
    fired = [p.name for p in canary_dir.rglob("canary*")] + [p.name for p in out.rglob("canary*")]
    assert not fired, fired


def test_the_scene_format_keeps_one_value_per_line():
    from modc.backends.templates import scene_token

    assert scene_token("crate") == "crate"
    assert "\n" not in scene_token("a\nb\r\nc\u2028d") and " " not in scene_token("a b")


def test_the_comment_sanitiser():
    from modc.backends.templates import comment

    for text in (HOSTILE_TEXT, "-", "--", "---", "a-", "${x}", "$(find x)", "$${x}", "\x00\x7f\x85"):
        s = comment(text)
        assert "--" not in s and not s.endswith("-") and "${" not in s and "$(" not in s
        assert s.isascii() and s.isprintable()
    assert comment("farm.mod") == "farm.mod"
