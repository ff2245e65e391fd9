"""The YAML form: same model as .mod, validated by the JSON Schema that `modc schema` prints."""
from __future__ import annotations

import json
import subprocess
import sys

import jsonschema
import pytest
import yaml
from conftest import ROOT

from modc.compiler import build, check_file, check_text


def _urdf_body(files):
    text = files["urdf/mod3_farm.urdf"]
    return text.split("\n", 2)[2]  # drop the header comment, which names the source file


def test_yaml_compiles_to_the_same_urdf_as_mod():
    a = check_file(ROOT / "examples" / "quickstart.mod")
    b = check_file(ROOT / "examples" / "quickstart.yaml")
    assert a.ok and b.ok
    assert _urdf_body(build(a, ["urdf"])) == _urdf_body(build(b, ["urdf"]))


@pytest.mark.slow
def test_schema_validates_the_yaml_example():
    r = subprocess.run([sys.executable, "-m", "modc", "schema"], capture_output=True, text=True)
    assert r.returncode == 0
    schema = json.loads(r.stdout)
    jsonschema.Draft202012Validator.check_schema(schema)
    jsonschema.validate(yaml.safe_load((ROOT / "examples" / "quickstart.yaml").read_text()), schema)
    bad = {"robots": [{"name": "x", "chain": ["H1"], "unknown": 1}]}
    assert not jsonschema.Draft202012Validator(schema).is_valid(bad)


def test_full_yaml_document_matches_mod_model():
    mod = """robot cell {
        chain H1 - H4(pivot=-90deg, link=200mm) - L4(port=45deg)
        tool at (0, 0, 0.05) m rpy (0, 90, 0) deg
        base at (1, 0, 0) m
        payload 200 g at (0, 0, 0.01) m
        pose home (0, 30, -45) deg
        limit joint_2 (-90, 90) deg
        box shelf size (0.6, 0.4, 0.02) m at (0.3, 0, 0.25) m rpy (0, 0, 10) deg
        sphere ball radius 0.05 m at (0.2, 0.2, 0.2) m
        cylinder post radius 0.02 m length 0.5 m at (-0.3, 0, 0.25) m
        target p1 at (0.3, 0.1, 0.4) m
    }"""
    yml = """robots:
  - name: cell
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
"""
    a, b = check_text(mod, "c.mod"), check_text(yml, "c.yaml")
    assert a.ok and b.ok, (a.diagnostics, b.diagnostics)
    assert a.design.robots[0].model_dump() == b.design.robots[0].model_dump()


def test_yaml_errors_point_into_the_yaml():
    c = check_text("robots:\n  - name: a\n    chain: [H1, {unit: L4, port: 45}]\n    colour: red\n", "a.yaml")
    got = {(d.code, d.span.line) for d in c.diagnostics}
    assert ("yaml-schema", 4) in got
    c = check_text("robots:\n  - name: a\n    chain: [H1, {unit: L4, port: 45}]\n", "a.yaml")
    assert [(d.code, d.span.line, d.span.col) for d in c.diagnostics] == [("missing-unit", 3, 34)]


@pytest.mark.parametrize("text, line, key", [
    # the flow form of the QA report: both values of `units` at one place, the second one flagged
    ('designs: [{name: d, targets: {a: "(0.3, 0.1, 0.25) m"}, units: "2", units: "3"}]\n', 1, "units"),
    ("robots:\n  - name: r\n    chain: [H1, L1]\nrobots: []\n", 4, "robots"),
    ("robots:\n  - name: r\n    chain: [H1, L1]\n    poses:\n      up: \"(0, 0) deg\"\n"
     "      up: \"(0, 10) deg\"\n", 6, "up"),
])
def test_a_key_given_twice_is_refused_at_the_second(text, line, key):
    """PyYAML keeps the last of two equal keys silently; a repeated .mod statement is refused."""
    c = check_text(text, "dup.yaml")
    assert [d.code for d in c.diagnostics] == ["yaml-syntax"], c.diagnostics
    d = c.diagnostics[0]
    assert d.span.line == line and f"key '{key}' is given twice" in d.message
    assert text.split("\n")[line - 1][d.span.col - 1:].startswith(key)
