"""The caret excerpt never echoes a control, format or undecodable character as it is: a file's
ESC or BEL would retitle or recolour the terminal, a bidi override would reorder the line. Each is
shown as its escape (the message's quoting), and the caret moves with it."""
from __future__ import annotations

import os
import subprocess
import sys
import unicodedata

from conftest import ROOT

from modc.compiler import check_text
from modc.diagnostics import Span
from modc.diagnostics.codes import Severity
from modc.diagnostics.diagnostic import Diagnostic
from modc.diagnostics.render import excerpt, render_text

UNSHOWN = {"Cc", "Cf", "Cs", "Co", "Cn", "Zl", "Zp"}


def _clean(text: str) -> bool:
    return not any(unicodedata.category(c) in UNSHOWN for c in text if c != "\n")


def _caret(lines: list[str]) -> tuple[int, int]:
    """(column of the first caret in the source line's coordinates, its width)."""
    bar = lines[1].index("| ") + 2
    marks = lines[1][bar:]
    start = len(marks) - len(marks.lstrip(" "))
    return start, len(marks.strip())


def test_escape_and_bell_in_the_line_are_escaped_and_the_caret_follows():
    src = "design d {\n target a at (0.3,0.1,0.25) m \x1b]0;PWNED\x07\x1b[31mRED\n units 2\n}\n"
    checked = check_text(src, "x.mod")
    text = render_text(checked.diagnostics, checked.sources)
    assert "unexpected-character" in text
    assert _clean(text), repr(text)
    assert "\\x1b]0;PWNED\\x07\\x1b[31mRED" in text
    lines = text.split("\n")[1:3]
    body = lines[0][lines[0].index("| ") + 2:]
    start, width = _caret(lines)
    assert body[start: start + width] == "\\x1b"


def test_the_caret_after_escaped_characters_stays_under_its_token():
    line = "chain \u202e\x00 H1 - ZZ"
    col = line.index("ZZ") + 1
    d = Diagnostic("unknown-module", Severity.ERROR, Span("f.mod", 1, col, 1, col + 2), "m")
    lines = excerpt(line + "\n", d)
    assert _clean("\n".join(lines))
    body = lines[0][lines[0].index("| ") + 2:]
    start, width = _caret(lines)
    assert body[start: start + width] == "ZZ"
    assert "\\u202e\\x00" in body


def test_wide_characters_are_still_shown_as_they_are():
    line = "robot 机械臂 { chain H1 }"
    d = Diagnostic("x", Severity.ERROR, Span("f.mod", 1, 7, 1, 10), "m")
    lines = excerpt(line, d)
    assert "机械臂" in lines[0] and _caret(lines) == (6, 6)


def test_a_binary_file_echoes_no_control_byte(tmp_path):
    src = tmp_path / "blob.mod"
    src.write_bytes(b"robot r {\n  chain H1 \x1b[2J\x07\x00\xff\xfe\x1b]0;X\x07 - L1\n}\n")
    env = dict(os.environ, PYTHONPATH=str(ROOT), MODC_CACHE_DIR=str(tmp_path / "cache"))
    r = subprocess.run([sys.executable, "-m", "modc", "lint", str(src)], capture_output=True, text=True,
                       env=env, timeout=120)
    out = r.stdout + r.stderr
    assert r.returncode == 1 and "bad-encoding" in out, out
    assert _clean(out), repr(out)
    assert "\\x1b[2J\\x07\\x00" in out
