"""`modc fmt` (modc/syntax/format.py): canonical, idempotent, meaning- and comment-preserving."""
from __future__ import annotations

import json
import os
from collections import Counter
from functools import cache
from pathlib import Path

import pytest
from conftest import EXAMPLES
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from strategies import valid_chains

from modc.compiler import build, check_text
from modc.resources import data_dir
from modc.syntax.format import WIDTH, format_text, rewrite_file

POSITION_KEYS = ("line", "col", "end_line", "end_col", "start", "end")


# --- independent oracles (not the formatter's own machinery) ------------------------------------
@cache
def _lexer_with_comments():
    """The grammar with a lexer callback collecting comments (the ignored COMMENT terminal)."""
    from lark import Lark

    found: list[str] = []
    lark = Lark((data_dir("grammar") / "modc.lark").read_text(encoding="utf-8"), parser="lalr",
                keep_all_tokens=True, start="start", lexer_callbacks={"COMMENT": found.append})
    return lark, found


def tokens_and_comments(text: str) -> tuple[list[tuple[str, str]], list[str]]:
    """The significant tokens (type, text) the parser sees, and the comments (trailing
    whitespace dropped, as fmt does), in order."""
    lark, found = _lexer_with_comments()
    found.clear()
    tree = lark.parse(text, start="start")
    toks = [(t.type, str(t)) for t in tree.scan_values(lambda v: v is not None)]
    return toks, [str(c).rstrip() for c in found]


def fmt(text: str) -> str:
    out, diags = format_text(text)
    assert out is not None, [d.message for d in diags]
    return out


def outputs(text: str, path: str) -> dict[str, str | bytes]:
    """Everything `modc FILE -o OUT` writes, with the source positions in report.json's
    diagnostics dropped (formatting moves lines; the diagnostics themselves must not change)."""
    c = check_text(text, path)
    assert c.ok, [d.message for d in c.diagnostics if d.is_error]
    files = build(c)
    report = json.loads(files["report.json"])
    for d in report["diagnostics"]:
        for k in POSITION_KEYS:
            d.pop(k, None)
    files["report.json"] = json.dumps(report, indent=2)
    return files


def assert_same_meaning(original: str, formatted: str, path: str = "t.mod") -> None:
    a, b = outputs(original, path), outputs(formatted, path)
    assert sorted(a) == sorted(b)
    for rel in a:
        assert a[rel] == b[rel], f"{rel} differs after formatting"


def assert_fmt_properties(text: str) -> str:
    out = fmt(text)
    assert fmt(out) == out, "not idempotent"
    toks, comments = tokens_and_comments(text)
    toks2, comments2 = tokens_and_comments(out)
    assert toks2 == toks, "tokens changed"
    assert Counter(comments2) == Counter(comments), "comments changed"
    assert comments2 == comments, "comments reordered"
    assert out == "" or (out.endswith("\n") and not out.endswith("\n\n"))
    assert "\n\n\n" not in out and "\r\n" not in out
    for line in out.split("\n"):
        assert line == line.rstrip()
        assert line[: len(line) - len(line.lstrip())].strip(" ") == "", "indentation is spaces only"
    return out


# --- every example -------------------------------------------------------------------------------
@pytest.mark.slow
@pytest.mark.parametrize("example", EXAMPLES, ids=lambda p: p.stem)
def test_examples_idempotent_comments_kept_same_output(example: Path):
    text = example.read_text(encoding="utf-8")
    out = assert_fmt_properties(text)
    # the same path for both: library paths resolve alike and the URDF header names the same file
    assert_same_meaning(text, out, str(example))


def test_examples_lines_fit_except_comments():
    for ex in EXAMPLES:
        for line in fmt(ex.read_text(encoding="utf-8")).splitlines():
            if not line.lstrip().startswith("#"):  # a comment is never wrapped
                assert len(line.split("  #", 1)[0]) <= WIDTH, (ex.name, line)


# --- golden: a messy file and its canonical form -------------------------------------------------
MESSY = '''\r


   # header comment   \r



robot   farm{chain H1-L4 ( pivot = -90deg,port=45 deg )- # after a dash
  # inside the chain
  L3(link=180mm)
tool at(0.06,0,0)m rpy( 0 , 0 , 90 )deg   # tool
payload 50g at ( 0.01 , 0 , 0 )m


\tpose home(0,0,0)deg pose ready (90, -45, -90) deg
      dh   { row a=0.148 m,alpha=-90deg
   # a comment between rows

   row a=1e-3m }  # after the dh block
library "lib/x #not a comment.yaml"
allow first-variant,torque-limit
   # a closing comment
}# after the robot
robot b { chain H1 () - L1 }
# footer


'''

CANONICAL = '''\
# header comment

robot farm {
    chain H1 - L4(pivot=-90deg, port=45deg) -  # after a dash
            # inside the chain
            L3(link=180mm)
    tool at (0.06, 0, 0) m rpy (0, 0, 90) deg  # tool
    payload 50 g at (0.01, 0, 0) m

    pose home (0, 0, 0) deg
    pose ready (90, -45, -90) deg
    dh {
        row a=0.148m, alpha=-90deg
        # a comment between rows

        row a=1e-3m
    }  # after the dh block
    library "lib/x #not a comment.yaml"
    allow first-variant, torque-limit
    # a closing comment
}  # after the robot

robot b {
    chain H1() - L1
}

# footer
'''


def test_golden_messy_input():
    assert fmt(MESSY) == CANONICAL
    assert fmt(CANONICAL) == CANONICAL
    assert_fmt_properties(MESSY)


def test_golden_compiles_the_same():
    messy = "robot farm{chain H1-L4 ( pivot = -90deg,port=45 deg )-L3(link=180mm)\n" \
            "tool at(0.06,0,0)m   # tip\npayload 50g pose home(0,0,0)deg}"
    out = fmt(messy)
    assert out == ("robot farm {\n    chain H1 - L4(pivot=-90deg, port=45deg) - L3(link=180mm)\n"
                   "    tool at (0.06, 0, 0) m  # tip\n    payload 50 g\n    pose home (0, 0, 0) deg\n}\n")
    assert_same_meaning(messy, out)


# --- details of the layout -----------------------------------------------------------------------
@pytest.mark.parametrize("number", ["0.148", "2.36", "1e-3", "1E+2", "0.30", ".5", "5.", "+7", "-0.0", "007"])
def test_numbers_kept_exactly_as_written(number):
    out = fmt(f"robot a {{ chain H1 - L4(pivot={number}deg, link = {number} mm) "
              f"pose p ({number},{number}) rad payload {number} kg }}")
    assert f"pivot={number}deg, link={number}mm" in out
    assert f"pose p ({number}, {number}) rad" in out
    assert f"payload {number} kg" in out


def test_measure_starting_with_e_keeps_its_space():
    # `1 e5` would read as the number 1e5 if the unit word were attached
    out = fmt("robot a { chain H1(pivot=1 e5) }")
    assert "pivot=1 e5" in out
    assert tokens_and_comments(out)[0] == tokens_and_comments("robot a { chain H1(pivot=1 e5) }")[0]


def test_long_chain_wraps_after_a_dash():
    units = " - ".join("H4(pivot=-90deg, port=135deg, link=180mm)" for _ in range(6))
    out = assert_fmt_properties(f"robot a {{ chain {units} }}")
    lines = out.splitlines()[1:-1]
    assert len(lines) > 1
    assert lines[0].startswith("    chain ") and all(ln.startswith(" " * 12) and ln[12] != " " for ln in lines[1:])
    assert all(ln.endswith(" -") for ln in lines[:-1])
    assert all(len(ln) <= WIDTH for ln in lines)
    # a chain that fits is never wrapped, however it was written
    assert fmt("robot a { chain H1 -\n\n   H4 -\n L4 }") == "robot a {\n    chain H1 - H4 - L4\n}\n"


def test_blank_lines_collapse_to_one_and_not_at_block_edges():
    text = (
        "\n\n# a\n\n\n\n# b\nrobot a {\n\n\n chain H1 - L1\n\n\n\n pose p (0, 0) deg\n\n\n}\n\n\n\n"
        "robot b { chain H1 - L1 }\n\n\n"
    )
    assert fmt(text) == ("# a\n\n# b\nrobot a {\n    chain H1 - L1\n\n    pose p (0, 0) deg\n}\n\n"
                         "robot b {\n    chain H1 - L1\n}\n")


def test_one_blank_line_between_robots_and_after_a_robot():
    assert fmt("robot a { chain H1 - L1 } robot b { chain H1 - L1 }\n# end") == \
        "robot a {\n    chain H1 - L1\n}\n\nrobot b {\n    chain H1 - L1\n}\n\n# end\n"


def test_comment_placement():
    text = "robot a { # opens\n chain H1 - L1\n# last\n}\n"
    assert fmt(text) == "robot a {  # opens\n    chain H1 - L1\n    # last\n}\n"
    # trailing whitespace (and a CR) of a comment is dropped; '#' inside a string is not a comment
    assert fmt('robot a { library "a#b.yaml"   #c  \r\n chain H1 - L1 }') == \
        'robot a {\n    library "a#b.yaml"  #c\n    chain H1 - L1\n}\n'


def test_only_comments_and_empty_files():
    assert fmt("") == ""
    assert fmt("  \n\t\n") == ""
    assert fmt("#a\n\n\n  #b") == "#a\n\n#b\n"
    assert fmt("robot a { }") == "robot a {\n}\n"


def test_syntax_errors_are_refused_with_their_diagnostic():
    for text, code in [("robot a { chain H1 H4 }", "missing-dash"),
                       ("robot a { chain H1 - ", "unclosed-block"),
                       ("robot a { chain H1 - L1 } ?", "unexpected-character")]:
        out, diags = format_text(text, "bad.mod")
        assert out is None
        assert [d.code for d in diags] == [code]
        assert diags[0].span.file == "bad.mod" and diags[0].is_error


def test_a_formatter_bug_raises_instead_of_rewriting(monkeypatch):
    import modc.syntax.format as f

    monkeypatch.setattr(f, "_space", lambda prev, cur: "")  # `box a size` -> `boxasize`
    with pytest.raises(f.FormatterBug, match="unparsable"):
        f.format_text("robot a { chain H1 - L1 box a size (1, 1, 1) m at (0, 0, 0) m }")
    monkeypatch.setattr(f, "_space", lambda prev, cur: "" if cur.type == "MEASURE" else " ")
    with pytest.raises(f.FormatterBug, match="change its tokens"):  # 1 e5 -> 1e5
        f.format_text("robot a { chain H1(pivot=1 e5) }")


def test_rewrite_file_is_atomic_and_keeps_mode(tmp_path):
    p = tmp_path / "a.mod"
    p.write_text("robot a{chain H1-L1}", encoding="utf-8")
    os.chmod(p, 0o640)
    link = tmp_path / "link.mod"
    link.symlink_to(p)
    rewrite_file(str(link), fmt(p.read_text(encoding="utf-8")))
    assert link.is_symlink()
    assert p.read_bytes() == b"robot a {\n    chain H1 - L1\n}\n"
    assert oct(p.stat().st_mode & 0o777) == oct(0o640)
    assert sorted(x.name for x in tmp_path.iterdir()) == ["a.mod", "link.mod"]  # no temp file left


# --- property tests ------------------------------------------------------------------------------
PUNCT = {"LPAR", "RPAR", "COMMA", "EQUAL", "MINUS", "LBRACE", "RBRACE"}
SPACES = ("", " ", "  ", "\t", "\n", "\n\n", "\n\n\n", "\r\n", " \n  ", "\n\t\n ")
COMMENT_CHARS = "ab Z09#\"'(){}-=,.;\t\x0c°µ€😀\u2028"


def _separator(rnd, may_be_empty: bool, comment_rate: float) -> str:
    """Whitespace, blank lines and comments that may stand between two tokens."""
    sep = rnd.choice(SPACES)
    if rnd.random() < comment_rate:  # a comment, trailing or on its own line
        sep += "#" + "".join(rnd.choice(COMMENT_CHARS) for _ in range(rnd.randrange(12))) + "\n" + rnd.choice(SPACES)
    return sep if sep or may_be_empty else " "


@st.composite
def respaced(draw, text: str) -> str:
    """The same tokens, with random whitespace, blank lines and comments between them. (One
    random generator per file: drawing each separator from Hypothesis was 10x slower.)"""
    rnd = draw(st.randoms(use_true_random=True))
    rate = draw(st.sampled_from((0.0, 0.1, 0.5)))
    lark, _ = _lexer_with_comments()
    toks = [t for t in lark.parse(text, start="start").scan_values(lambda v: v is not None)]
    out = [_separator(rnd, True, rate)]
    for i, t in enumerate(toks):
        out.append(str(t))
        if i + 1 < len(toks):
            nxt = toks[i + 1]
            out.append(_separator(rnd, t.type in PUNCT or nxt.type in PUNCT or nxt.type == "MEASURE", rate))
    out.append(_separator(rnd, True, rate))
    return "".join(out)


def re_strip_comments(text: str) -> str:
    """The same tokens, single-spaced, without comments."""
    toks, _ = tokens_and_comments(text)
    return " ".join(t for _, t in toks)


messy_files = valid_chains().flatmap(lambda t: st.tuples(st.just(t), respaced(t)))


@pytest.mark.slow
@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(messy_files)
def test_property_respaced_valid_files(pair):
    original, messy = pair
    out = assert_fmt_properties(messy)
    # the layout depends on the tokens (and comments, blank lines), never on the input's spacing
    assert fmt(original) == fmt(re_strip_comments(out))
    assert_same_meaning(original, out)


@pytest.mark.slow
@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(valid_chains(), min_size=1, max_size=3).flatmap(lambda ts: respaced("\n".join(ts))))
def test_property_several_robots_idempotent(messy):
    out = assert_fmt_properties(messy)
    lines = out.split("\n")
    closes = [i for i, line in enumerate(lines) if line.startswith("}")]
    assert len(closes) == sum(1 for t, _ in tokens_and_comments(out)[0] if t == "ROBOT")
    assert all(lines[i + 1] == "" for i in closes)  # a blank line after every robot


EXAMPLE_TEXTS = {ex.stem: ex.read_text(encoding="utf-8") for ex in EXAMPLES}


@pytest.mark.slow
@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from(sorted(EXAMPLE_TEXTS)).flatmap(lambda k: st.tuples(st.just(k), respaced(EXAMPLE_TEXTS[k]))))
def test_property_respaced_examples(pair):
    """Every statement kind (dh blocks, obstacles, poses, allow …), re-spaced and commented."""
    stem, messy = pair
    out = assert_fmt_properties(messy)
    path = str(EXAMPLES[0].parent / f"{stem}.mod")
    assert_same_meaning(EXAMPLE_TEXTS[stem], out, path)
