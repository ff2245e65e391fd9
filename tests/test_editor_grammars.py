"""Editor grammars: the VS Code extension (TextMate grammar) and the Pygments lexer.

Both are highlighting grammars of the language that grammar/modc.lark defines. Their keyword
lists are regenerated here from the Lark grammar (modc.lsp.language: block, statement and clause
keywords) and compared: a keyword added to the Lark grammar fails these tests until both editor
grammars know it, in the right class. `pytest tests/test_editor_grammars.py --update-golden`
rewrites the Pygments lists; the TextMate grammar needs a rule per keyword (the failure says which).
Units of measure come from modc.model.quantities. The
TextMate grammar's own assertions (editors/vscode/tests/*.mod) run under vscode-tmgrammar-test
through editors/vscode/test.sh, which needs node and npm (skipped, saying so, without npm).
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import textwrap
from pathlib import Path

import pytest

pygments = pytest.importorskip("pygments")
from pygments.token import Comment, Error, Keyword, Name, Number, Operator, Punctuation, String  # noqa: E402

from modc.model.quantities import ALL as MEASURES  # noqa: E402
from modc.pygments_lexer import ModLexer  # noqa: E402
from modc.syntax import grammar_keywords  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
VSCODE = ROOT / "editors" / "vscode"
TMLANGUAGE = VSCODE / "syntaxes" / "mod.tmLanguage.json"
GRAMMAR_TESTS = sorted((VSCODE / "tests").glob("*.mod"))
EXAMPLES = sorted((ROOT / "examples").glob("*.mod"))
LEXER_FILE = ROOT / "modc" / "pygments_lexer.py"

# keyword.control.<kw>.mod (statements) or keyword.other.<kw>.mod (clauses); units of measure
# are keyword.other.unit.<unit>.mod (one segment more, so never taken for a keyword).
KEYWORD_SCOPE = re.compile(r"keyword\.(?:control|other)\.([a-z]+(?:-[a-z]+)*)\.mod")
MEASURE_SCOPE = re.compile(r"keyword\.other\.unit\.([a-z]+)\.mod")
WORD = re.compile(r"[a-z]+(?:-[a-z]+)*")


def lark_keywords() -> set[str]:
    """Every keyword of grammar/modc.lark: grammar_keywords() (the anonymous "word" terminals)
    plus named terminals whose pattern is a literal word, such as DH_FIT: "fit-links"."""
    from modc.syntax.parser import _lark

    named = {t.pattern.value for t in _lark().terminals if t.pattern.type == "str" and WORD.fullmatch(t.pattern.value)}
    return set(grammar_keywords()) | named


def scope_names(node) -> set[str]:
    """Every scope named anywhere in a TextMate grammar (rules, captures, nested patterns)."""
    out: set[str] = set()
    if isinstance(node, dict):
        for key, value in node.items():
            if key in ("name", "contentName") and isinstance(value, str):
                out.update(value.split())
            else:
                out |= scope_names(value)
    elif isinstance(node, list):
        for value in node:
            out |= scope_names(value)
    return out


def asserted_scopes(path: Path) -> set[str]:
    """Scopes that the vscode-tmgrammar-test assertions of a test file require (not the ones after ' - ')."""
    out: set[str] = set()
    for line in path.read_text(encoding="utf-8").splitlines():
        m = re.match(r"#\s*(?:\^+|<-+|<~*-+)\s+(.*)$", line)
        if m:
            out.update(m.group(1).split(" - ")[0].split())
    return out


@pytest.fixture(scope="module")
def tmlanguage() -> dict:
    return json.loads(TMLANGUAGE.read_text(encoding="utf-8"))


# --- keywords and units: one language, three grammars ---------------------------------------


def test_lark_keywords_include_the_named_terminal():
    keywords = lark_keywords()
    assert "fit-links" in keywords and {"robot", "chain", "at"} <= keywords
    assert grammar_keywords() <= keywords


def keyword_classes() -> dict[str, set[str]]:
    """The keyword lists as the grammar gives them."""
    from modc.lsp import language

    return {
        "DECLARATIONS": set(language.declaration_keywords()),
        "STATEMENTS": set(language.statement_keywords()),
        "CLAUSES": set(language.clause_keywords()),
    }


def _keyword_rule(name: str, kind: str, words: list[str]) -> str:
    """A TextMate repository entry matching words, as written in mod.tmLanguage.json."""
    alternatives = "|".join(f"({w})" for w in words)
    captures = ",\n".join(f'        "{i}": {{ "name": "keyword.{kind}.{w}.mod" }}' for i, w in enumerate(words, 1))
    return (
        f'    "{name}": {{\n      "match": "(?<![\\\\w-])(?:{alternatives})(?![\\\\w-])",\n'
        f'      "captures": {{\n{captures}\n      }}\n    }}'
    )


def refresh_textmate(tmlanguage: dict, missing: dict[str, set[str]], path: Path = TMLANGUAGE) -> None:
    """Add keywords the TextMate grammar lacks to its generic rules: statements to `placement`,
    clauses to `clause` (keywords with a structure of their own need a hand-written rule)."""
    text = path.read_text(encoding="utf-8")
    for name, kind in (("placement", "control"), ("clause", "other")):
        rule = tmlanguage["repository"][name]
        words = [c["name"].split(".")[2] for _, c in sorted(rule["captures"].items(), key=lambda kv: int(kv[0]))]
        words += sorted(missing[kind] - set(words))
        m = re.search(rf'^    "{name}": \{{\n(?:.*\n)*?    \}}', text, re.M)
        assert m, name
        text = text[: m.start()] + _keyword_rule(name, kind, words) + text[m.end() :]
    json.loads(text)
    path.write_text(text, encoding="utf-8")


def test_textmate_keywords_match_the_lark_grammar(tmlanguage, update_golden):
    scopes = scope_names(tmlanguage)
    got = {
        kind: {m.group(1) for s in scopes if (m := re.fullmatch(rf"keyword\.{kind}\.([a-z]+(?:-[a-z]+)*)\.mod", s))}
        for kind in ("control", "other")
    }
    got["other"] -= {"unit"}
    want = keyword_classes()
    expected = {"control": want["DECLARATIONS"] | want["STATEMENTS"], "other": want["CLAUSES"]}
    if update_golden and any(expected[k] - got[k] for k in got):
        refresh_textmate(tmlanguage, {k: expected[k] - got[k] for k in got})
        pytest.skip(
            "editors/vscode/syntaxes/mod.tmLanguage.json: keywords added to its generic rules; add "
            "assertions for them in editors/vscode/tests/*.mod"
        )
    for kind in ("control", "other"):
        assert got[kind] == expected[kind], (
            f"editors/vscode/syntaxes/mod.tmLanguage.json: keyword.{kind} lacks {sorted(expected[kind] - got[kind])}, "
            f"has extra {sorted(got[kind] - expected[kind])}: give each keyword a rule with scope "
            "keyword.control.<kw>.mod (block or statement) or keyword.other.<kw>.mod (clause) and an assertion in "
            "editors/vscode/tests/*.mod"
        )


def test_textmate_refresh_adds_a_new_keyword(tmlanguage, tmp_path):
    copy = tmp_path / "mod.tmLanguage.json"
    copy.write_text(TMLANGUAGE.read_text(encoding="utf-8"), encoding="utf-8")
    refresh_textmate(tmlanguage, {"control": {"gripper"}, "other": {"grip"}}, copy)
    scopes = scope_names(json.loads(copy.read_text(encoding="utf-8")))
    assert {"keyword.control.gripper.mod", "keyword.other.grip.mod"} <= scopes
    assert scope_names(tmlanguage) <= scopes


def test_textmate_units_of_measure_match_the_model(tmlanguage):
    textmate = {m.group(1) for s in scope_names(tmlanguage) if (m := MEASURE_SCOPE.fullmatch(s))}
    assert textmate == set(MEASURES)


def test_every_keyword_and_unit_is_asserted_in_the_grammar_tests():
    asserted: set[str] = set()
    for path in GRAMMAR_TESTS:
        asserted |= asserted_scopes(path)
    keywords = {m.group(1) for s in asserted if (m := KEYWORD_SCOPE.fullmatch(s))}
    measures = {m.group(1) for s in asserted if (m := MEASURE_SCOPE.fullmatch(s))}
    assert lark_keywords() <= keywords, f"no assertion for {sorted(lark_keywords() - keywords)}"
    assert set(MEASURES) <= measures, f"no assertion for {sorted(set(MEASURES) - measures)}"


def test_pygments_keywords_match_the_lark_grammar(update_golden):
    from modc import pygments_lexer

    want = keyword_classes()
    if update_golden:  # the refresh path: rewrite the tuples in modc/pygments_lexer.py
        text = LEXER_FILE.read_text(encoding="utf-8")
        for name, words in want.items():
            listed = ", ".join(f'"{w}"' for w in sorted(words)) + ("," if len(words) == 1 else "")
            line = textwrap.fill(
                f"{name} = ({listed})",
                width=110,
                subsequent_indent=" " * (len(name) + 4),
                break_long_words=False,
                break_on_hyphens=False,
            )
            text = re.sub(rf"^{name} = \((?:[^()]*)\)", line.replace("\\", "\\\\"), text, count=1, flags=re.M)
        LEXER_FILE.write_text(text, encoding="utf-8")
        pytest.skip("modc/pygments_lexer.py keyword lists rewritten from the grammar: review the diff")
    for name, words in want.items():
        listed = getattr(pygments_lexer, name)
        assert list(listed) == sorted(words), (
            f"modc/pygments_lexer.py {name} = {listed}, the grammar says {tuple(sorted(words))}: "
            "refresh with pytest tests/test_editor_grammars.py --update-golden"
        )
    assert set(pygments_lexer.MEASURES) == set(MEASURES)


def test_pygments_lexes_every_keyword_as_a_keyword():
    """The lists above are what the lexer does: every keyword in the grammar tests comes out as
    Keyword (outside comments), and nothing else does."""
    lexer = ModLexer()
    seen, measures = set(), set()
    for path in GRAMMAR_TESTS + EXAMPLES:
        for ttype, value in lexer.get_tokens(path.read_text(encoding="utf-8")):
            if ttype in Keyword.Type:
                measures.add(value)
            elif ttype in Keyword:
                seen.add(value)
    assert seen == lark_keywords()
    assert measures == set(MEASURES)


# --- Pygments ------------------------------------------------------------------------------


@pytest.mark.parametrize("path", EXAMPLES + GRAMMAR_TESTS, ids=lambda p: p.name)
def test_pygments_highlights_without_errors(path):
    text = path.read_text(encoding="utf-8")
    tokens = list(ModLexer().get_tokens(text))
    errors = [v for t, v in tokens if t in Error]
    assert not errors, f"{path.name}: Error tokens {errors[:10]}"


SNIPPET = """\
# comment
robot farm {
    chain H1 - L4(pivot=-90deg, port=0.5 rad) - L3(link=180mm)
    library "libs/my.yaml"
    payload 50 g at (0.01, 0, 0) m
    pose ready (90, -45, -90) deg
    box shelf size (0.6, 0.4, 0.02) m at (30, 0, 25) cm
    limit joint_2 (-90, 90) deg
    allow first-variant
}
robot dhbot {
    dh fit-links { row a=0.3 m, alpha=-1.5e0rad, d=0 mm }
}
"""


def _tokens(text: str) -> list[tuple[object, str]]:
    return [(t, v) for t, v in ModLexer().get_tokens(text) if v.strip()]


@pytest.mark.parametrize(
    "value, ttype",
    [
        ("# comment", Comment.Single),
        ("robot", Keyword.Declaration),
        ("farm", Name.Class),
        ("chain", Keyword),
        ("H1", Name.Builtin),
        ("L3", Name.Builtin),
        ("-", Punctuation),
        ("pivot", Name.Attribute),
        ("=", Operator),
        ("-90", Number.Float),
        ("deg", Keyword.Type),
        ("rad", Keyword.Type),
        ("mm", Keyword.Type),
        ('"libs/my.yaml"', String.Double),
        ("payload", Keyword),
        ("50", Number.Float),
        ("g", Keyword.Type),
        ("at", Keyword),
        ("m", Keyword.Type),
        ("ready", Name.Function),
        ("shelf", Name.Variable),
        ("size", Keyword),
        ("cm", Keyword.Type),
        ("joint_2", Name.Variable),
        ("first-variant", Name.Constant),
        ("fit-links", Keyword),
        ("row", Keyword),
        ("-1.5e0", Number.Float),
    ],
)
def test_pygments_token_types(value, ttype):
    types = {t for t, v in _tokens(SNIPPET) if v == value}
    assert types == {ttype}, f"{value!r}: {types}"


def test_pygments_lexer_loads_from_its_file():
    from pygments.lexers import load_lexer_from_file

    lexer = load_lexer_from_file(str(LEXER_FILE), "ModLexer")
    assert lexer.name == "modc"
    assert [v for _, v in lexer.get_tokens("robot r { chain H1 }") if v.strip()] == [
        "robot",
        "r",
        "{",
        "chain",
        "H1",
        "}",
    ]


def test_pyproject_registers_the_lexer():
    text = (ROOT / "pyproject.toml").read_text(encoding="utf-8")
    section = re.search(r'^\[project\.entry-points\."pygments\.lexers"\]\s*\n((?:[^\[\n].*\n?)*)', text, re.M)
    assert section and re.search(r'^modc\s*=\s*"modc\.pygments_lexer:ModLexer"', section.group(1), re.M), (
        'pyproject.toml needs [project.entry-points."pygments.lexers"] modc = "modc.pygments_lexer:ModLexer"'
    )


def test_pygments_finds_the_lexer_by_name_and_file_name():
    from importlib.metadata import entry_points

    if not any(ep.name == "modc" for ep in entry_points(group="pygments.lexers")):
        pytest.skip("the pygments.lexers entry point is not installed: reinstall modc (pip install -e .)")
    from pygments.lexers import get_lexer_by_name, get_lexer_for_filename

    assert isinstance(get_lexer_by_name("modc"), ModLexer)
    assert isinstance(get_lexer_by_name("mod"), ModLexer)
    # Modula-2 also claims *.mod: the robot block decides
    assert isinstance(get_lexer_for_filename("farm.mod", EXAMPLES[0].read_text(encoding="utf-8")), ModLexer)


# --- VS Code extension ---------------------------------------------------------------------


def test_vscode_extension_manifest(tmlanguage):
    package = json.loads((VSCODE / "package.json").read_text(encoding="utf-8"))
    (language,) = package["contributes"]["languages"]
    assert language["id"] == "mod" and ".mod" in language["extensions"] and language["aliases"]
    (grammar,) = package["contributes"]["grammars"]
    assert grammar["language"] == "mod" and grammar["scopeName"] == tmlanguage["scopeName"] == "source.mod"
    assert (VSCODE / grammar["path"]).resolve() == TMLANGUAGE
    assert (VSCODE / package["main"]).is_file()
    assert "vscode-languageclient" in package["dependencies"]
    assert "modc.path" in package["contributes"]["configuration"]["properties"]
    config = json.loads((VSCODE / language["configuration"]).read_text(encoding="utf-8"))
    assert config["comments"]["lineComment"] == "#"
    assert ["{", "}"] in config["brackets"] and ["(", ")"] in config["brackets"]
    assert {"open": "(", "close": ")"} in config["autoClosingPairs"]
    extension = (VSCODE / "extension.js").read_text(encoding="utf-8")
    assert "vscode-languageclient/node" in extension and '"lsp"' in extension


def test_grammar_tests_have_the_header():
    assert GRAMMAR_TESTS
    for path in GRAMMAR_TESTS:
        assert path.read_text(encoding="utf-8").startswith('# SYNTAX TEST "source.mod"'), path.name


def _run_grammar_tests(*files: Path) -> subprocess.CompletedProcess:
    if shutil.which("npm") is None or shutil.which("node") is None:
        pytest.skip("npm/node not installed: the TextMate grammar tests (editors/vscode/test.sh) need them")
    return subprocess.run(
        ["bash", str(VSCODE / "test.sh"), *map(str, files)], capture_output=True, text=True, timeout=600
    )


@pytest.mark.slow
def test_textmate_grammar_tests_pass():
    r = _run_grammar_tests()
    assert r.returncode == 0, r.stdout + r.stderr
    for path in GRAMMAR_TESTS:
        assert f"tests/{path.name} run successfuly" in r.stdout, r.stdout


@pytest.mark.slow
def test_textmate_grammar_tests_catch_a_wrong_scope(tmp_path):
    """The harness really fails: a test file asserting a wrong scope makes test.sh exit non-zero."""
    broken = tmp_path / "broken.mod"
    broken.write_text(
        '# SYNTAX TEST "source.mod"\nrobot r { chain H1 }\n#         ^^^^^ keyword.other.at.mod\n', encoding="utf-8"
    )
    r = _run_grammar_tests(broken)
    assert r.returncode != 0
    assert "missing required scopes: keyword.other.at.mod" in r.stdout, r.stdout + r.stderr


@pytest.mark.slow
def test_vsce_packages_the_extension(tmp_path):
    """`vsce package` (pinned in package-lock.json, through editors/vscode/package.sh) makes a
    .vsix: no relative README link, a repository field, a LICENSE; the runtime dependency and the
    grammar inside, the grammar tests and scripts left out."""
    import zipfile

    if shutil.which("npm") is None or shutil.which("node") is None:
        pytest.skip("npm/node not installed: packaging the VS Code extension needs them")
    vsix = tmp_path / "modc.vsix"
    r = subprocess.run(
        ["bash", str(VSCODE / "package.sh"), "-o", str(vsix)], capture_output=True, text=True, timeout=900
    )
    assert r.returncode == 0, r.stdout + r.stderr
    names = set(zipfile.ZipFile(vsix).namelist())
    assert {
        "extension/package.json",
        "extension/extension.js",
        "extension/syntaxes/mod.tmLanguage.json",
        "extension/language-configuration.json",
        "extension/readme.md",
        "extension.vsixmanifest",
    } <= {n if not n.lower().endswith("readme.md") else n.lower() for n in names}
    assert any(n.lower().startswith("extension/license") for n in names)
    assert any(n.startswith("extension/node_modules/vscode-languageclient/") for n in names)
    assert not any(n.startswith(("extension/tests/", "extension/node_modules/@vscode/vsce")) for n in names)
    assert "extension/test.sh" not in names and "extension/package.sh" not in names
