"""The diagnostics corpus: one small realistic input per diagnostic code, expectations inline.

Corpus files are ``tests/diagnostics/*.mod``, ``*.yaml`` (the YAML form) and ``*.csv`` (DH tables
for ``modc dh2mod``), top level only: ``tests/diagnostics/libraries/`` holds library fixtures the
corpus files refer to. A file is named after the code it is about, e.g. ``missing-unit.mod``;
further cases for one code are named ``<code>--<what>.mod`` (codes never contain ``--``).

Expectation comments (``#`` comments in all three formats):

    # expect: SEVERITY[code] message text    a diagnostic reported on THIS line, with exactly
                                             this message (mypy's habit: the text is pinned,
                                             not only the code)
    # expect: error[a] text, warning[b] text several on one line, separated by ", " before
                                             each SEVERITY[
    # expect-line N: SEVERITY[code], ...     reported on line N (1-based), written anywhere: for
                                             diagnostics where a trailing comment cannot sit, e.g.
                                             unclosed-block, reported where the file ends (one
                                             line past a final newline), and in CSV files, whose
                                             data lines cannot carry comments
    # expect-in FILE:N: SEVERITY[code], ...  reported on line N of another file, named relative to
                                             the case (a library fixture the case refers to)
    # corpus-xfail: REASON                   the case is a known bug: the tests comparing
                                             expectations are xfail(strict=False)
    # corpus-analyses: torque                check with these analyses on (as compile and
                                             `modc check` do; `modc lint` does not run them)

The message text may be left out (``# expect: error[code]``) while writing a case; then
``pytest tests/test_diagnostics_corpus.py --update-golden`` writes every reported message into
the comments (the refresh path; review the diff), and ``test_every_expectation_pins_its_message``
fails until it is there.

"Reported on line L" means ``diagnostic.span.line == L`` (for ``expect-in``: on line L of FILE).
Each case is checked the way the product checks it (``check_file`` for .mod/.yaml,
``convert_table`` for .csv) and the set of (line, severity, code) reported must equal the set
expected: nothing missing, nothing extra.
A file that is not UTF-8 is reported by ``check_file`` as one bad-encoding diagnostic (exit 1).
Lines are counted on the raw bytes decoded with replacement characters, so a corpus
file need not be valid UTF-8. The same expectations are checked through the command line
(``modc lint --format json``, ``modc check`` for cases with analyses, ``modc dh2mod`` for CSV),
with its exit code.

Codes that are not about the text of a file (file-not-found, output-not-modc, …) are covered by
the test functions named in ``FUNCTION_CASES``; ``test_every_code_is_covered`` checks that every
code in the registry has a corpus file (that is not a known failure) or such a function.
"""

from __future__ import annotations

import importlib.util
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from modc.compiler import InputError, SourceError, check_file, check_text, read_source, write_tree
from modc.diagnostics import REGISTRY, Diagnostic
from modc.diagnostics.render import render_json, render_text

HERE = Path(__file__).resolve().parent
CORPUS_DIR = HERE / "diagnostics"
CASES = sorted([*CORPUS_DIR.glob("*.mod"), *CORPUS_DIR.glob("*.yaml"), *CORPUS_DIR.glob("*.csv")])

SEVERITIES = ("error", "warning", "note")
_EXPECT = re.compile(r"#\s*expect(?:-line\s+(?P<n>\d+)|-in\s+(?P<file>[^\s:]+):(?P<in>\d+))?\s*:(?P<items>[^#]*)")
_ITEM = re.compile(r"^\s*(?P<sev>[a-z]+)\[(?P<code>[a-z0-9-]+)\](?:\s+(?P<msg>.*?))?\s*$")
_ITEM_SEP = re.compile(r",\s*(?=(?:error|warning|note)\[)")
_XFAIL = re.compile(r"#\s*corpus-xfail:\s*(?P<reason>.+)")
_ANALYSES = re.compile(r"#\s*corpus-analyses:\s*(?P<names>[a-z, -]+)")
# Codes only the analyses report (compile and `modc check`, not `modc lint`).
ANALYSIS_CODES = {"torque-over-peak", "torque-over-nominal", "epsilon-disagrees"}

# Codes covered by a test function in this module instead of a corpus file.
FUNCTION_CASES = {
    "file-not-found": "test_file_not_found",
    "output-not-modc": "test_output_not_modc",
    "output-unsafe": "test_output_unsafe",
    "output-unwritable": "test_output_unwritable",
    "unsupported-input": "test_unsupported_input",
    "input-too-large": "test_input_too_large",
    "bad-payload": "test_bad_payload",
    "traj-invalid": "test_traj_invalid",
    "no-design": "test_no_design",
    "task-unknown": "test_task_plan_errors",
    "task-segment-failed": "test_task_plan_errors",
    **{
        code: "test_plan_errors"
        for code in (
            "target-unknown",
            "pose-unknown",
            "robot-unknown",
            "start-in-collision",
            "target-unreachable",
            "target-in-collision",
            "no-path",
        )
    },
}

YAML_FORM = importlib.util.find_spec("modc.syntax.yaml_form") is not None


# --- reading expectations ----------------------------------------------------------------------


def source_text(path: Path) -> str:
    """The text lines are counted in: undecodable bytes replaced, a lone CR a line end (as modc counts)."""
    from modc.syntax.parser import normalize_newlines

    return normalize_newlines(path.read_bytes().decode("utf-8-sig", errors="replace"))


def pinned(path: Path) -> list[tuple[int | str, str, str, str | None]]:
    """[(line, severity, code, message or None)] written in the file's `# expect` comments; line
    is "FILE:N" for a line of another file (expect-in)."""
    out = []
    for i, line in enumerate(source_text(path).split("\n"), start=1):
        for m in _EXPECT.finditer(line):
            at: int | str = int(m.group("n")) if m.group("n") else i
            if m.group("file"):
                at = f"{m.group('file')}:{m.group('in')}"
            for item in _ITEM_SEP.split(m.group("items")):
                im = _ITEM.match(item)
                assert im, f"{path.name}:{i}: malformed expectation {item!r} (write severity[code] message)"
                out.append((at, im.group("sev"), im.group("code"), im.group("msg") or None))
    return out


def expectations(path: Path) -> set[tuple[int | str, str, str]]:
    """{(line, severity, code)} written in the file's `# expect` comments."""
    return {(at, sev, code) for at, sev, code, _ in pinned(path)}


def refresh_messages(path: Path, diags: list[Diagnostic]) -> None:
    """Rewrite the `# expect` comments with the messages reported (--update-golden). Only the
    comment is rewritten: the bytes before it (maybe not UTF-8, on purpose) are kept."""
    by_key: dict[tuple[int | str, str, str], list[str]] = {}
    for d in sorted(diags, key=lambda d: (d.span.line, d.span.col)):
        by_key.setdefault((where(path, d.span.file, d.span.line), d.severity.value, d.code), []).append(d.message)
    # lines as the product counts them (CR LF, lone CR or LF), their ends kept
    parts = re.split(rb"(\r\n|\r|\n)", path.read_bytes())
    raw, ends = parts[0::2], parts[1::2] + [b""]
    for i, chunk in enumerate(raw):
        line = chunk.decode("utf-8", errors="replace")
        first = _EXPECT.search(line)
        if first is None:
            continue
        tail = line[first.start() :]

        def items(m: re.Match, i: int = i, tail: str = tail) -> str:
            at: int | str = int(m.group("n")) if m.group("n") else i + 1
            if m.group("file"):
                at = f"{m.group('file')}:{m.group('in')}"
            out = []
            for item in _ITEM_SEP.split(m.group("items")):
                im = _ITEM.match(item)
                assert im is not None
                msgs = by_key.get((at, im.group("sev"), im.group("code")), [im.group("msg") or ""])
                out += [f"{im.group('sev')}[{im.group('code')}] {msg}".rstrip() for msg in dict.fromkeys(msgs)]
            head = m.group(0)[: m.start("items") - m.start(0)]
            return head + " " + ", ".join(out) + ("  " if m.end(0) < len(tail) else "")

        if chunk.endswith(tail.encode("utf-8")):
            raw[i] = chunk[: len(chunk) - len(tail.encode("utf-8"))] + _EXPECT.sub(items, tail).encode("utf-8")
    path.write_bytes(b"".join(line + end for line, end in zip(raw, ends, strict=True)))


def xfail_reason(path: Path) -> str | None:
    m = _XFAIL.search(source_text(path))
    return m.group("reason").strip() if m else None


def analyses(path: Path) -> frozenset[str]:
    m = _ANALYSES.search(source_text(path))
    return frozenset(x.strip() for x in m.group("names").split(",") if x.strip()) if m else frozenset()


def case_code(path: Path) -> str:
    return path.stem.split("--")[0]


def case_param(path: Path, known_bugs: bool = True):
    """A pytest param for one corpus file; known_bugs: apply its `corpus-xfail` (to the tests
    comparing expectations; the other tests run it normally, see diagnostics_of)."""
    marks = []
    reason = xfail_reason(path)
    if reason and known_bugs:
        marks.append(pytest.mark.xfail(reason=reason, strict=False))
    if path.suffix == ".yaml" and not YAML_FORM:
        marks.append(pytest.mark.xfail(reason="modc.syntax.yaml_form is not implemented yet", strict=False))
    return pytest.param(path, id=path.name, marks=marks)


def run_case(path: Path) -> list[Diagnostic]:
    if path.suffix == ".csv":
        from modc.dh2mod import convert_table

        return list(convert_table(read_source(path), str(path))[1])
    try:
        checked = check_file(path, analyses=analyses(path)) if analyses(path) else check_file(path)
        return list(checked.diagnostics)
    except InputError as e:
        return [e.diagnostic]


def diagnostics_of(path: Path) -> list[Diagnostic]:
    """run_case for the tests that do not compare expectations: a known bug that crashes is an xfail."""
    try:
        return run_case(path)
    except Exception:
        reason = xfail_reason(path)
        if reason:
            pytest.xfail(reason)
        raise


def where(path: Path, file: str, line: int) -> int | str:
    """A reported line as expectations write it: N in the case itself, "FILE:N" in another file."""
    if file == str(path) or not Path(file).is_file():
        return line
    return f"{Path(os.path.relpath(file, path.parent)).as_posix()}:{line}"


def reported(diags: list[Diagnostic], path: Path) -> set[tuple[int | str, str, str]]:
    return {(where(path, d.span.file, d.span.line), d.severity.value, d.code) for d in diags}


def _show(items) -> str:
    return "\n".join(f"    line {ln}: {sev}[{code}]" for ln, sev, code in sorted(items, key=str)) or "    (none)"


# --- the corpus ----------------------------------------------------------------------------------


def test_corpus_is_not_empty():
    assert len(CASES) >= 30


@pytest.mark.slow
@pytest.mark.parametrize("path", [case_param(p) for p in CASES])
def test_corpus(path: Path, update_golden):
    expected = expectations(path)
    assert expected, f"{path.name} has no `# expect` comment"
    diags = run_case(path)
    got = reported(diags, path)
    missing, extra = expected - got, got - expected
    assert not missing and not extra, (
        f"{path.name}:\n  missing (expected, not reported):\n{_show(missing)}\n"
        f"  extra (reported, not expected):\n{_show(extra)}"
    )
    if update_golden:
        refresh_messages(path, diags)
    messages = {(where(path, d.span.file, d.span.line), d.severity.value, d.code, d.message) for d in diags}
    wrong = [p for p in pinned(path) if p[3] is not None and p not in messages]
    assert not wrong, (
        f"{path.name}: messages changed:\n"
        + "\n".join(f"    line {ln}: {sev}[{code}] {msg}" for ln, sev, code, msg in wrong)
        + "\n  reported:\n"
        + "\n".join(f"    line {ln}: {sev}[{code}] {msg}" for ln, sev, code, msg in sorted(messages, key=str))
        + "\n  refresh with: pytest tests/test_diagnostics_corpus.py --update-golden (and review the diff)"
    )


@pytest.mark.parametrize("path", [case_param(p, known_bugs=False) for p in CASES])
def test_every_expectation_pins_its_message(path: Path):
    bare = [(ln, sev, code) for ln, sev, code, msg in pinned(path) if msg is None]
    assert not bare, (
        f"{path.name}: expectations without their message text {bare}; write them with "
        "pytest tests/test_diagnostics_corpus.py --update-golden"
    )


@pytest.mark.parametrize("path", [case_param(p, known_bugs=False) for p in CASES])
def test_corpus_file_is_about_its_code(path: Path):
    """tests/diagnostics/<code>[--what].mod expects <code> at least once (the name says what it tests)."""
    assert case_code(path) in REGISTRY, f"{path.name} is not named after a registered code"
    assert case_code(path) in {code for _, _, code in expectations(path)}


def test_expectations_name_registered_codes_with_their_severity():
    for path in CASES:
        for line, sev, code in expectations(path):
            assert code in REGISTRY, f"{path.name}:{line}: unknown code {code!r}"
            assert sev == REGISTRY[code].severity.value, (
                f"{path.name}:{line}: {code} is a {REGISTRY[code].severity.value}"
            )


def _covered_by_corpus() -> set[str]:
    """Codes with a corpus case that is not a known failure."""
    return {case_code(p) for p in CASES if case_code(p) in {c for _, _, c in expectations(p)} and not xfail_reason(p)}


def test_every_code_is_covered():
    corpus = _covered_by_corpus()
    module = sys.modules[__name__]
    for name, fn in FUNCTION_CASES.items():
        assert name in REGISTRY, f"FUNCTION_CASES names unknown code {name!r}"
        assert callable(getattr(module, fn, None)), f"FUNCTION_CASES[{name!r}] = {fn!r} is not a test function here"
    uncovered = sorted(set(REGISTRY) - corpus - set(FUNCTION_CASES))
    assert not uncovered, "codes without a corpus file or a test function: " + ", ".join(uncovered)


# --- every diagnostic is well-formed -----------------------------------------------------------

# Known bugs in where diagnostics point, by (corpus file suffix, code): the checks below turn into
# an xfail for these instead of a failure.
SPAN_BUGS: dict = {}


def check_well_formed(d: Diagnostic, text: str, path: str) -> None:
    """Registered code and severity, message, hint, and a span inside the text."""
    assert d.code in REGISTRY and d.severity == REGISTRY[d.code].severity
    assert d.message.strip(), d
    assert d.hint.strip(), d
    lines = text.split("\n")
    s = d.span
    assert s.file == path, s
    assert 1 <= s.line <= len(lines), (s, len(lines))
    assert 1 <= s.col <= len(lines[s.line - 1]) + 1, (s, lines[s.line - 1])
    assert (s.end_line, s.end_col) >= (s.line, s.col), s
    assert s.end_line <= len(lines), s


def check_rendered(d: Diagnostic, text: str, path: str) -> None:
    """render_text shows `file:line:col: severity[code]`, the message, the source line, a caret
    line under the reported column, and the hint."""
    rendered = render_text([d], {path: text})
    head = f"{path}:{d.span.line}:{d.span.col}: {d.severity.value}[{d.code}]"
    assert head in rendered, rendered
    assert d.message in rendered and d.hint in rendered
    source_line = text.split("\n")[d.span.line - 1].rstrip("\r").expandtabs(1)
    out = rendered.split("\n")
    assert any(ln.endswith("| " + source_line) for ln in out), f"source line {source_line!r} missing:\n{rendered}"
    carets = [ln for ln in out if re.fullmatch(r"\s*\| *\^+", ln)]
    assert len(carets) == 1, rendered
    assert carets[0].index("^") - carets[0].index("|") - 2 == d.span.col - 1, rendered


def _check_each(path: Path, check) -> None:
    text = source_text(path)
    diags = diagnostics_of(path)
    if not diags and (reason := xfail_reason(path)):
        pytest.xfail(reason)
    assert diags
    for d in diags:
        try:
            if where(path, d.span.file, d.span.line) == d.span.line:
                check(d, text, str(path))
            else:  # a diagnostic inside another file (a library): checked against that file
                check(d, source_text(Path(d.span.file)), d.span.file)
        except AssertionError:
            if (path.suffix, d.code) in SPAN_BUGS:
                pytest.xfail(SPAN_BUGS[path.suffix, d.code])
            raise


@pytest.mark.parametrize("path", [case_param(p, known_bugs=False) for p in CASES])
def test_corpus_diagnostics_are_well_formed(path: Path):
    _check_each(path, check_well_formed)


@pytest.mark.parametrize("path", [case_param(p, known_bugs=False) for p in CASES])
def test_corpus_diagnostics_render_with_caret(path: Path):
    _check_each(path, check_rendered)


# Known bugs: codes whose spans carry no character offsets (start = end = 0).
OFFSET_BUGS: dict = {}


@pytest.mark.parametrize("path", [case_param(p, known_bugs=False) for p in CASES if p.suffix != ".csv"])
def test_corpus_json_offsets_match_lines(path: Path):
    """JSON output carries character offsets (for editors); they agree with line and column.
    (Not for CSV tables: their diagnostics are only shown as text, by dh2mod.)"""
    for item in json.loads(render_json(diagnostics_of(path)))["diagnostics"]:
        text = source_text(path if where(path, item["file"], 1) == 1 else Path(item["file"]))
        start = item["start"]
        assert 0 <= start <= len(text), item
        if item["code"] == "bad-encoding":
            continue  # offsets of undecodable input are byte offsets
        line = text[:start].count("\n") + 1
        col = start - (text.rfind("\n", 0, start) + 1) + 1
        if (line, col) != (item["line"], item["col"]) and item["code"] in OFFSET_BUGS:
            pytest.xfail(OFFSET_BUGS[item["code"]])
        assert (line, col) == (item["line"], item["col"]), item


# --- the command line over the corpus ----------------------------------------------------------

_HEAD = re.compile(
    r"^(?P<file>.+?):(?P<line>\d+):(?P<col>\d+): (?P<sev>error|warning|note)\[(?P<code>[a-z0-9-]+)\]: ", re.M
)


def run_cli(capsys, *args: str) -> tuple[int, str, str]:
    """`modc ARGS` in-process: (exit code, stdout, stderr)."""
    from modc.cli import main

    with pytest.raises(SystemExit) as e:
        main(list(args))
    out, err = capsys.readouterr()
    return int(e.value.code or 0), out, err


def run_lint(capsys, *args: str) -> tuple[int, str, str]:
    return run_cli(capsys, "lint", *args)


def text_heads(stderr: str, path: Path) -> set[tuple[int, str, str]]:
    """(line, severity, code) of the rendered diagnostics in a text report about one file."""
    return {
        (int(m["line"]), m["sev"], m["code"]) for m in _HEAD.finditer(stderr) if m["file"] in (str(path), "<unknown>")
    }


def _exit_code_for(path: Path, got: set) -> int:
    try:
        read_source(path)
    except SourceError:  # not UTF-8 or too large: an error in the file
        return 1
    except InputError:
        return 2
    return 1 if any(sev == "error" for _, sev, _ in got) else 0


@pytest.mark.parametrize("path", [case_param(p) for p in CASES])
def test_corpus_through_the_command_line(path: Path, capsys):
    """The same diagnostics through the command the case is about, and its exit code (2 for
    unreadable input, 1 with errors, 0 with warnings and notes only):
    .mod/.yaml: `modc lint --format json` (and `modc check` for cases with analyses, whose codes
    lint leaves out); .csv: `modc dh2mod`."""
    expected = expectations(path)
    if path.suffix == ".csv":
        rc, out, err = run_cli(capsys, "dh2mod", str(path))
        assert "Traceback" not in err
        assert text_heads(err, path) == expected, err
        assert rc == _exit_code_for(path, expected)
        if rc == 0:
            assert out.lstrip().startswith("#") and "robot " in out  # the .mod text
        return
    rc, out, err = run_lint(capsys, str(path), "--format", "json")
    assert "Traceback" not in err
    got = {(where(path, d["file"], d["line"]), d["severity"], d["code"]) for d in json.loads(out)["diagnostics"]}
    lint_expected = {e for e in expected if e[2] not in ANALYSIS_CODES}
    assert got == lint_expected
    assert rc == _exit_code_for(path, lint_expected)
    if analyses(path):
        assert analyses(path) == {"torque"}
        rc, out, err = run_cli(capsys, "check", str(path))
        assert "Traceback" not in err
        assert text_heads(err, path) == expected, err
        assert rc == _exit_code_for(path, expected)


# --- codes that are not about the text of a file -------------------------------------------------------


def test_file_not_found(tmp_path, capsys):
    missing = tmp_path / "nope.mod"
    with pytest.raises(InputError) as e:
        check_file(missing)
    d = e.value.diagnostic
    assert d.code == "file-not-found" and d.is_error and d.hint
    assert str(missing) in d.message
    rc, out, err = run_lint(capsys, str(missing), "--format", "json")
    assert rc == 2
    assert [x["code"] for x in json.loads(out)["diagnostics"]] == ["file-not-found"]
    rc, out, err = run_lint(capsys, str(missing))
    assert rc == 2 and f"{missing}:1:1: error[file-not-found]" in err and "Traceback" not in err


def test_file_not_found_for_a_directory_given_as_file(tmp_path):
    d = tmp_path / "arm.mod"
    d.mkdir()
    with pytest.raises(InputError) as e:
        check_file(d)
    assert e.value.diagnostic.code == "file-not-found"


def test_output_not_modc(tmp_path):
    files: dict[str, str | bytes] = {"urdf/x.urdf": "<robot/>", "report.json": "{}"}
    # a non-empty directory modc did not write
    foreign = tmp_path / "home"
    foreign.mkdir()
    (foreign / "thesis.tex").write_text("precious", encoding="utf-8")
    with pytest.raises(InputError) as e:
        write_tree(files, foreign)
    assert e.value.diagnostic.code == "output-not-modc" and e.value.diagnostic.hint
    assert (foreign / "thesis.tex").read_text(encoding="utf-8") == "precious"
    assert sorted(p.name for p in foreign.iterdir()) == ["thesis.tex"]
    # a plain file where the output directory should go
    plain = tmp_path / "out"
    plain.write_text("x", encoding="utf-8")
    with pytest.raises(InputError) as e:  # a file is never replaced by a folder, even with --force
        write_tree(files, plain)
    assert e.value.diagnostic.code == "output-unsafe"
    assert plain.read_text(encoding="utf-8") == "x"
    # an empty directory and a directory modc wrote are fine; --force replaces a foreign one
    empty = tmp_path / "empty"
    empty.mkdir()
    write_tree(files, empty)
    write_tree({"report.json": "{}"}, empty)
    assert sorted(p.name for p in empty.iterdir()) == [".modc-manifest.json", "report.json"]
    write_tree(files, foreign, force=True)
    assert not (foreign / "thesis.tex").exists()


@pytest.mark.slow
def test_output_not_modc_from_the_command_line(tmp_path):
    src = tmp_path / "farm.mod"
    src.write_text("robot farm {\n    chain H1 - L4(port=45deg) - L1\n}\n", encoding="utf-8")
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("mine", encoding="utf-8")
    p = subprocess.run(
        [sys.executable, "-m", "modc", str(src), "-o", str(out)], capture_output=True, text=True, timeout=120
    )
    assert p.returncode == 2, p.stderr
    assert "error[output-not-modc]" in p.stderr and "Traceback" not in p.stderr
    assert [x.name for x in out.iterdir()] == ["notes.txt"]


def test_output_unsafe(tmp_path, monkeypatch):
    """OUT the working directory, a parent of it, or the directory of the input: never replaced."""
    monkeypatch.chdir(tmp_path)
    for out, inputs in ((".", ()), ("..", ()), ("src", ["src/a.mod"])):
        with pytest.raises(InputError) as e:
            write_tree({"a.txt": "x"}, out, force=True, inputs=inputs)
        d = e.value.diagnostic
        assert d.code == "output-unsafe" and d.hint and out in d.message
    assert list(tmp_path.iterdir()) == []


def test_unsupported_input(tmp_path, capsys):
    src = tmp_path / "farm.txt"
    src.write_text("robot farm {\n    chain H1 - L4(port=45deg) - L1\n}\n", encoding="utf-8")
    with pytest.raises(InputError) as e:
        check_file(src)
    assert e.value.diagnostic.code == "unsupported-input"
    rc, out, err = run_lint(capsys, str(src), "--format", "json")
    assert rc == 2
    assert [x["code"] for x in json.loads(out)["diagnostics"]] == ["unsupported-input"]


def test_input_too_large():
    from modc.syntax.parser import MAX_BYTES

    body = "robot farm {\n    chain H1 - L4(port=45deg) - L1\n}\n"
    text = body + "#" * (MAX_BYTES + 1 - len(body)) + "\n"
    c = check_text(text, "big.mod")
    assert [(d.span.line, d.code) for d in c.diagnostics] == [(1, "input-too-large")]
    check_well_formed(c.diagnostics[0], text, "big.mod")
    # just under the limit is an ordinary file
    ok = body + "#" * (MAX_BYTES - len(body) - 1) + "\n"
    assert len(ok) == MAX_BYTES
    assert not check_text(ok, "ok.mod").diagnostics


@pytest.mark.skipif(not YAML_FORM, reason="modc.syntax.yaml_form is not implemented yet")
def test_input_too_large_yaml():
    text = "robots: []\n" + "#" * 1_000_001
    c = check_text(text, "big.yaml")
    assert [d.code for d in c.diagnostics] == ["input-too-large"]


def test_input_too_large_file_on_disk(tmp_path, capsys):
    big = tmp_path / "big.mod"
    big.write_text("#" * 1_200_000, encoding="utf-8")
    rc, out, err = run_lint(capsys, str(big), "--format", "json")
    assert rc == 1
    assert [x["code"] for x in json.loads(out)["diagnostics"]] == ["input-too-large"]


def test_bad_payload(tmp_path, capsys):
    """`modc check --payload` takes a mass; anything else is a usage error (exit 2)."""
    src = tmp_path / "farm.mod"
    src.write_text("robot farm {\n    chain H1 - L4(port=45deg) - L1\n}\n", encoding="utf-8")
    for bad in ("heavy", "0.5 m", "-1kg", "nan"):
        rc, out, err = run_cli(capsys, "check", str(src), "--payload", bad)
        assert rc == 2, (bad, err)
        assert "<command line>:1:1: error[bad-payload]" in err and repr(bad) in err, err
        assert "Traceback" not in err and "= hint:" in err
    rc, out, err = run_cli(capsys, "check", str(src), "--payload", "500g")
    assert rc == 0, err


def test_bad_encoding_points_at_the_byte(tmp_path):
    src = tmp_path / "latin1.mod"
    src.write_bytes("robot farm {\n    chain H1 - L1   # 45° \n}\n".encode("latin-1"))
    [d] = check_file(src).diagnostics
    assert d.code == "bad-encoding" and "0xb0" in d.message
    assert (d.span.line, d.span.col) == (2, 25)
    # columns in characters, lines ended by CR alone counted
    src.write_bytes("robot farm {\r    chain H1 - L1 # é°\r}\n".encode().replace("°".encode(), b"\xb0"))
    [d] = check_file(src).diagnostics
    assert (d.code, d.span.line, d.span.col) == ("bad-encoding", 2, 22)


def test_utf8_bom_is_accepted(tmp_path):
    src = tmp_path / "bom.mod"
    src.write_bytes(b"\xef\xbb\xbfrobot farm {\n    chain H1 - L4(port=45deg) - L1\n}\n")
    assert not check_file(src).diagnostics


# --- rendering details ---------------------------------------------------------------------------


@pytest.mark.parametrize("sep", ["\f", "\v", "\x1c", "\x85", "\u2028", "\u2029"], ids=repr)
def test_excerpt_uses_the_same_lines_as_the_parser(sep):
    text = (
        f"# a comment with a {sep} in it\nrobot farm {{\n    chain H1 - L4(port=45deg) - L1\n"
        "    pose home (0, 30) deg\n}\n"
    )
    c = check_text(text, "t.mod")
    assert [(d.span.line, d.code) for d in c.diagnostics] == [(4, "pose-arity")]
    check_rendered(c.diagnostics[0], text, "t.mod")


def test_excerpt_with_crlf_line_endings():
    text = "robot farm {\r\n    chain H1 - L4(port=45deg) - L1\r\n    pose home (0, 30) deg\r\n}\r\n"
    c = check_text(text, "t.mod")
    assert [(d.span.line, d.code) for d in c.diagnostics] == [(3, "pose-arity")]
    check_rendered(c.diagnostics[0], text, "t.mod")


@pytest.mark.slow
def test_traj_invalid(tmp_path):
    """`modc play` with a trajectory for other joints: a diagnostic at the trajectory file, exit 1."""
    traj = tmp_path / "t.json"
    traj.write_text(json.dumps({"joint_names": ["joint_1", "joint_9"], "points": [{"t": 0, "q": [0, 0]}]}))
    src = HERE.parent / "examples" / "quickstart.mod"
    r = subprocess.run(
        [sys.executable, "-m", "modc", "play", str(src), "--traj", str(traj), "--headless"],
        capture_output=True,
        text=True,
    )
    assert r.returncode == 1, r.stderr
    assert f"{traj}:1:1: error[traj-invalid]:" in r.stderr and "= hint:" in r.stderr and "Traceback" not in r.stderr


PLAN_CELL = """robot farm {
    chain H1 - L4(pivot=-90deg, port=45deg) - L3(link=180mm)
    tool at (0.06, 0, 0) m
    pose home (0, 0, 0) deg
    box crate size (0.25, 0.25, 0.25) m at (0.3, 0, 0.3) m
    target inside at (0.3, 0, 0.3) m
    target far at (1.2, 0, 0.3) m
    target open at (0.3, 0.3, 0.3) m
}
robot other {
    chain H1 - L1
    target open at (0.3, 0.3, 0.3) m
}
"""


@pytest.mark.slow
def test_plan_errors(tmp_path, capsys):
    """`modc plan`: every way planning can fail is a diagnostic with a hint and no traceback; exit 1,
    or 2 for names given on the command line (target, start pose, robot)."""
    from modc.plan import PlanError, plan

    cell = tmp_path / "cell.mod"
    cell.write_text(PLAN_CELL, encoding="utf-8")
    blocked = tmp_path / "blocked.mod"
    blocked.write_text(
        PLAN_CELL.replace(
            "    pose home (0, 0, 0) deg\n",
            "    pose home (0, 0, 0) deg\n    box shelf size (0.3, 0.3, 0.02) m at (-0.1, 0, 0.33) m\n",
        ),
        encoding="utf-8",
    )
    cases = [  # (arguments, exit code, code, where it points)
        (["plan", str(cell), "--to", "tomato", "--robot", "farm"], 2, "target-unknown", "<command line>:1:1"),
        (["plan", str(cell), "--to", "inside", "--start", "nowhere"], 2, "pose-unknown", "<command line>:1:1"),
        (["plan", str(cell), "--to", "open"], 2, "robot-unknown", "<command line>:1:1"),
        (["plan", str(cell), "--to", "far"], 1, "target-unreachable", f"{cell}:7:5"),
        (["plan", str(cell), "--to", "inside"], 1, "target-in-collision", f"{cell}:6:5"),
        (["plan", str(blocked), "--to", "inside", "--robot", "farm"], 1, "start-in-collision", f"{blocked}:4:5"),
    ]
    for args, rc_want, code, where in cases:
        rc, out, err = run_cli(capsys, *args)
        assert rc == rc_want, (args, err)
        assert f"{where}: error[{code}]" in err, err
        assert "= hint:" in err and "Traceback" not in err and out == ""
    # no-path: a search budget too small to go round the crate (not a command-line option)
    with pytest.raises(PlanError) as e:
        plan(HERE.parent / "examples" / "farm.mod", "plant", max_checks=20)
    d = e.value.diagnostics[0]
    assert d.code == "no-path" and e.value.exit_code == 1 and d.hint
    assert d.code in REGISTRY and d.severity == REGISTRY[d.code].severity


def test_pinned_messages_are_read_and_compared(tmp_path):
    """Messages may contain commas; a changed message is caught; the refresh writes it back."""
    case = tmp_path / "missing-dash.mod"
    case.write_text(
        "robot farm {\n    chain H1 - H4 L4   # expect: error[missing-dash] expected '-', found nothing\n}\n",
        encoding="utf-8",
    )
    assert pinned(case) == [(2, "error", "missing-dash", "expected '-', found nothing")]
    diags = run_case(case)
    assert (2, "error", "missing-dash", diags[0].message) != pinned(case)[0]
    refresh_messages(case, diags)
    assert pinned(case) == [(2, "error", "missing-dash", diags[0].message)]
    assert case.read_text(encoding="utf-8").startswith(
        "robot farm {\n    chain H1 - H4 L4   # expect: error[missing-dash] "
    )


def test_no_design(tmp_path, capsys):
    """`modc design` with no chain that does the tasks: exit 1, a diagnostic on the design block
    saying what came closest, nothing written."""
    src = tmp_path / "far.mod"
    src.write_text(
        "design cell {\n    target near at (0.3, 0, 0.2) m\n    target far at (3, 0, 0) m\n    units 2 to 3\n}\n",
        encoding="utf-8",
    )
    out = tmp_path / "out"
    rc, stdout, err = run_cli(capsys, "design", str(src), "-o", str(out))
    assert rc == 1, err
    assert f"{src}:1:8: error[no-design]" in err, err
    assert "target 'far': no design gets closer than 1.88 m" in err and "= hint:" in err and "Traceback" not in err
    assert not out.exists() and stdout == ""


TASK_CELL = """robot farm {
    chain H1 - L4(pivot=-90deg, port=45deg) - L3(link=180mm)
    pose home (0, 0, 0) deg
    target plant at (0.30, 0, 0.25) m
    target far at (2, 0, 0.25) m
    task serve { visit plant, far }
}
"""


def test_task_plan_errors(tmp_path, capsys):
    """`modc plan --task`: an unknown task (exit 2) and a segment that cannot be planned (exit 1,
    naming the segment) are diagnostics with a hint, never a traceback."""
    cell = tmp_path / "cell.mod"
    cell.write_text(TASK_CELL, encoding="utf-8")
    for args, rc_want, code, where, words in [
        (["--task", "harvest"], 2, "task-unknown", "<command line>:1:1", "no task or path 'harvest'"),
        (["--task", "serve"], 1, "task-segment-failed", f"{cell}:6:5", "segment 1 (plant -> far)"),
    ]:
        rc, out, err = run_cli(capsys, "plan", str(cell), *args)
        assert rc == rc_want, (args, err)
        assert f"{where}: error[{code}]" in err and words in err, err
        assert "= hint:" in err and "Traceback" not in err and out == ""


def test_output_unwritable(tmp_path):
    """An output folder that cannot be made (a file on its way, a folder that may not be
    written) is refused before any work, with where and why; nothing is left behind."""
    from modc.outputs import check_output_dir

    plain = tmp_path / "afile"
    plain.write_text("mine", encoding="utf-8")
    with pytest.raises(InputError) as e:
        check_output_dir(plain / "sub")
    d = e.value.diagnostic
    assert d.code == "output-unwritable" and "not a directory" in d.message and d.hint
    assert plain.read_text(encoding="utf-8") == "mine"
    locked = tmp_path / "locked"
    locked.mkdir()
    locked.chmod(0o555)
    try:
        if os.access(locked, os.W_OK):  # root writes anyway: nothing to refuse then
            check_output_dir(locked / "out")
        else:
            with pytest.raises(InputError) as e:
                check_output_dir(locked / "out")
            assert e.value.diagnostic.code == "output-unwritable"
        assert list(locked.iterdir()) == []
    finally:
        locked.chmod(0o755)
    check_output_dir(tmp_path / "new" / "deeper")  # folders still to make: fine
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile", "locked"]


def test_design_refuses_an_unwritable_folder_before_searching(tmp_path):
    """`modc design -o afile/sub` fails at once (exit 2, located, coded), not after the search."""
    src = tmp_path / "cell.mod"
    src.write_text("design d {\n    target a at (0.3, 0.1, 0.25) m\n    units 6\n}\n", encoding="utf-8")
    (tmp_path / "afile").write_text("mine", encoding="utf-8")
    p = subprocess.run([sys.executable, "-m", "modc", "design", str(src), "-o", str(tmp_path / "afile" / "sub"),
                        "--no-render"], capture_output=True, text=True, timeout=300,
                       env={**os.environ, "MODC_CACHE_DIR": str(tmp_path / "cache")})
    assert p.returncode == 2, p.stderr
    assert "error[output-unwritable]" in p.stderr and "shapes" not in p.stderr  # no search ran
    assert (tmp_path / "afile").read_text(encoding="utf-8") == "mine"
