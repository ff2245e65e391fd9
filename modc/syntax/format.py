"""`modc fmt`: the one canonical layout of a .mod file.

The formatter works on the token stream of the real grammar (grammar/modc.lark): it parses the
file with every token kept, and re-emits exactly those tokens, changing only the whitespace
between them and where comments sit on a line. Numbers, names, units and strings are written
back character for character ("0.148", "1e-3", "2.36" stay as written), no token is added or
removed (`H4()` stays `H4()`), and statements keep their order. After formatting, the output is
lexed again and its token sequence (type and text) and comment texts are compared with the
input's: a formatter bug raises instead of rewriting a file into something else. Since the
parser sees the same tokens, the AST is the same apart from source positions, so the compiled
output is the same.

Canonical layout
----------------
- one statement per line; 4 spaces per block level (`robot … {` at column 0, statements at 4,
  `row`s of a `dh` block at 8); the closing `}` on its own line at the level of its opener;
  an empty block is written `robot a {` / `}` on two lines;
- single spaces between words; `a - b` between the units of a chain; `, ` in lists;
  no spaces inside parentheses or around `=`; `H4(pivot=-90deg)` (no space before a unit's
  parameter list); a region point is one word, `tray[1,0,0]`; one space before a vector:
  `at (0.3, 0, 0.25) m`, `pose home (0, 0) deg`;
- a unit of measure is attached to its number inside `key=value` parameters (unit parameters
  and dh rows: `pivot=-90deg`, `link=180mm`, `d=0.148m`); everywhere else it follows after one
  space (`payload 50 g`, `radius 0.04 m`, and after every vector: `(0.3, 0, 0.25) m`).
  (A unit word starting with e/E keeps its space: attaching it would read as an exponent.)
- a chain longer than 100 columns is wrapped after a ` -` separator (never inside a unit), the
  continuation indented 8 spaces deeper than the statement; no other statement is wrapped;
- comments are kept verbatim (trailing whitespace removed). A trailing comment stays at the end
  of the line holding the token it followed, two spaces after it (no alignment). A full-line
  comment stays on its own line before the token it preceded, indented like that token's line
  (like the block's contents when it precedes a closing `}`). A comment inside a statement keeps
  the statement broken at that point: the rest continues on the next line, 8 spaces deeper;
- blank lines: a run of blank lines between statements, rows, comments or robots becomes one
  blank line; none at the start or end of the file, after a `{` or before a `}`, or inside a
  statement; exactly one blank line after each robot's closing `}` when anything follows it;
- the file ends with one newline ('\\n' line endings); a file with no tokens and no comments
  formats to the empty string.

The output is a function of the token sequence, where each comment sits in it (and whether it
trails a token on the same line), and where blank lines separate lines; formatting preserves all
three, so fmt(fmt(x)) == fmt(x).
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from functools import cache

from ..diagnostics import Diagnostic
from ..resources import data_dir

INDENT = 4
CONTINUATION = 8
WIDTH = 100

_COMMENT = re.compile(r"#[^\n]*")


@cache
def _lark():
    from .parser import cached_lark

    text = (data_dir("grammar") / "modc.lark").read_text(encoding="utf-8")
    # The parser's own instance drops punctuation and keywords; the formatter needs every token.
    return cached_lark(text, {"parser": "lalr", "keep_all_tokens": True, "maybe_placeholders": True, "start": "start"})


@dataclass(slots=True)
class _Tok:
    text: str
    type: str
    start: int
    end: int
    level: int | None = None  # set: this token starts a line at this block level
    close: bool = False  # a block's closing brace
    opens: bool = False  # a block's opening brace
    attach: bool = False  # written without a space after the previous token
    unit_start: bool = False  # a chain unit after a '-': the chain may wrap before it
    seg_width: int = 0  # width of the unit (and its following ' -') when unit_start


@dataclass(slots=True)
class _Comment:
    text: str
    trailing: bool


@dataclass(slots=True)
class _Elem:
    item: _Tok | _Comment
    blank_before: bool  # one or more blank lines separate it from the previous element
    next_tok: _Tok | None = None  # for a comment: the token after it (None at the end)


def _leaves(tree, parents=()):
    from lark import Tree

    here = parents + (tree.data,)
    for c in tree.children:
        if c is None:  # maybe_placeholders
            continue
        if isinstance(c, Tree):
            yield from _leaves(c, here)
        else:
            yield c, here


def _tok(t) -> _Tok:
    return _Tok(str(t), t.type, t.start_pos, t.end_pos)


def _statement(tree, level: int, out: list[_Tok]) -> None:
    """Tokens of one statement (or dh row) starting a line at `level`; a dh block nests rows."""
    from lark import Tree

    if tree.data == "dh":
        first = True
        for c in tree.children:
            if c is None:
                continue
            if isinstance(c, Tree):  # a row
                _statement(c, level + 1, out)
                continue
            t = _tok(c)
            if first:
                t.level, first = level, False
            elif t.type == "LBRACE":
                t.opens = True
            elif t.type == "RBRACE":
                t.level, t.close = level, True
            out.append(t)
        return
    after_dash = False
    for i, (c, parents) in enumerate(_leaves(tree)):
        t = _tok(c)
        if i == 0:
            t.level = level
        if t.type == "MEASURE" and parents[-1] == "quantity" and len(parents) > 1 and parents[-2] == "param":
            t.attach = t.text[:1] not in ("e", "E")
        if "point_index" in parents:  # tray[1,0,0]: a point's name is written as one word
            t.attach = True
        if tree.data in ("chain", "compare"):  # `compare with chain …` wraps as a chain does
            t.unit_start, after_dash = after_dash, t.type == "MINUS"
        out.append(t)


def _tokens(tree) -> list[_Tok]:
    from lark import Tree

    out: list[_Tok] = []
    for robot in tree.children:
        for c in robot.children:
            if c is None:
                continue
            if isinstance(c, Tree):
                _statement(c, 1, out)
                continue
            t = _tok(c)
            if t.type in ("ROBOT", "DESIGN"):
                t.level = 0
            elif t.type == "LBRACE":
                t.opens = True
            elif t.type == "RBRACE":
                t.level, t.close = 0, True
            out.append(t)
    _measure_chain_units(out)
    return out


def _space(prev: _Tok, cur: _Tok) -> str:
    if cur.type in ("RPAR", "COMMA", "EQUAL") or prev.type in ("LPAR", "EQUAL"):
        return ""
    if cur.type == "LPAR":
        return "" if prev.type == "UNIT_NAME" else " "
    return "" if cur.attach else " "


def _measure_chain_units(toks: list[_Tok]) -> None:
    for i, t in enumerate(toks):
        if not t.unit_start:
            continue
        width, j = len(t.text), i + 1
        while j < len(toks) and toks[j].level is None and not toks[j].unit_start:
            width += len(_space(toks[j - 1], toks[j])) + len(toks[j].text)
            j += 1
        t.seg_width = width


def _elements(text: str, toks: list[_Tok]) -> list[_Elem]:
    """Tokens and comments in source order. Between two tokens the text is only whitespace and
    comments (the grammar ignores nothing else), so every '#' in such a gap starts a comment."""
    elems: list[_Elem] = []
    pos = last = 0

    def gap(lo: int, hi: int) -> None:
        nonlocal last
        for m in _COMMENT.finditer(text, lo, hi):
            before = text[last:m.start()]
            elems.append(
                _Elem(_Comment(m.group().rstrip(), bool(elems) and "\n" not in before), before.count("\n") >= 2)
            )
            last = m.end()

    for t in toks:
        last = pos
        gap(pos, t.start)
        elems.append(_Elem(t, text[last:t.start].count("\n") >= 2))
        pos = t.end
    last = pos
    gap(pos, len(text))
    return elems


class _Writer:
    def __init__(self) -> None:
        self.lines: list[str] = []
        self.cur: str | None = None  # the line being built
        self.cont = CONTINUATION  # indent of a continuation line of the current statement
        self.first_in_block = True  # no blank line before the first item of a block or file
        self.after_robot = False  # one blank line after a robot's closing brace
        self.prev: _Tok | None = None

    def flush(self) -> None:
        if self.cur is not None:
            self.lines.append(self.cur)
            self.cur = None

    def block_item(self, blank_before: bool, close: bool = False) -> None:
        """Start a line that is an item of a block (statement, row, comment, robot, brace)."""
        self.flush()
        if not close and not self.first_in_block and (blank_before or self.after_robot):
            self.lines.append("")
        self.first_in_block = self.after_robot = False

    def token(self, t: _Tok, blank_before: bool) -> None:
        if t.level is not None:
            self.block_item(blank_before, t.close)
            self.cur = " " * (INDENT * t.level) + t.text
            self.cont = INDENT * t.level + CONTINUATION
        elif self.cur is None:
            self.cur = " " * self.cont + t.text
        elif t.unit_start and len(self.cur) + 1 + t.seg_width > WIDTH:
            self.flush()
            self.cur = " " * self.cont + t.text
        else:
            assert self.prev is not None
            self.cur += _space(self.prev, t) + t.text
        self.prev = t
        if t.opens:
            self.first_in_block = True
        if t.close and t.level == 0:
            self.after_robot = True

    def comment(self, c: _Comment, blank_before: bool, next_tok: _Tok | None) -> None:
        if c.trailing:
            assert self.cur is not None
            self.cur += "  " + c.text
            self.flush()
            return
        if next_tok is None:  # after the last token: a top-level comment
            self.block_item(blank_before)
            indent = 0
        elif next_tok.level is not None:  # before a line: at that line's level
            self.block_item(blank_before)
            indent = INDENT * (next_tok.level + (1 if next_tok.close else 0))
        else:  # inside a statement: it stays there, the statement continues below
            self.flush()
            indent = self.cont
        self.lines.append(" " * indent + c.text)

    def text(self) -> str:
        self.flush()
        return "".join(line + "\n" for line in self.lines)


def _layout(text: str) -> tuple[str, list[tuple[str, str]], list[str]]:
    """Format text that parses. Also returns its tokens and comments, for the safety check."""
    tree = _lark().parse(text, start="start")
    toks = _tokens(tree)
    elems = _elements(text, toks)
    w = _Writer()
    next_tok: _Tok | None = None
    for i in range(len(elems) - 1, -1, -1):  # the token after each element, found back to front
        e = elems[i]
        if isinstance(e.item, _Tok):
            next_tok = e.item
        else:
            e.next_tok = next_tok
    for e in elems:
        if isinstance(e.item, _Tok):
            w.token(e.item, e.blank_before)
        else:
            w.comment(e.item, e.blank_before, e.next_tok)
    comments = [e.item.text for e in elems if isinstance(e.item, _Comment)]
    return w.text(), [(t.type, t.text) for t in toks], comments


class FormatterBug(RuntimeError):
    """The formatted text failed the safety check: a bug in modc, never the user's fault."""


def format_text(text: str, path: str = "<string>") -> tuple[str | None, list[Diagnostic]]:
    """The canonical form of a .mod text. (None, diagnostics) when it does not parse: a file
    that does not parse is never formatted. On success the list is empty (warnings such as an
    empty file are lint's business, not fmt's). Raises FormatterBug if the result would not lex
    into the same tokens and comments (checked on every call)."""
    from lark.exceptions import LarkError

    from .parser import collector_paused, normalize_newlines, parse, too_large

    big = too_large(text, path)
    if big is not None:
        return None, [big]
    text = normalize_newlines(text)
    with collector_paused():
        try:  # one parse when the text is fine; the checker's parse only to explain why it is not
            out, toks, comments = _layout(text)
        except LarkError:
            errors = [d for d in parse(text, path)[1] if d.is_error]
            assert errors, "the formatter's grammar and the parser's disagree"
            return None, errors
        try:
            _, toks2, comments2 = _layout(out)
        except LarkError as e:
            raise FormatterBug(f"formatting {path} would make it unparsable ({e.__class__.__name__}); "
                               "the file is left as it is") from None
    if toks2 != toks or comments2 != comments:
        raise FormatterBug(f"formatting {path} would change its tokens or comments; the file is left as it is")
    return out, []


class ChangedOnDisk(Exception):
    """The file changed between modc's read and its write: left as it was saved."""


def rewrite_file(path: str, text: str, expected: bytes | None = None) -> None:
    """Replace the file's contents with text atomically, unless they are no longer `expected`
    (what was read and formatted; by default what the file holds when this starts). A temporary
    file is written next to it (same directory, same permission bits), the file compared with
    `expected` once more, then the temporary file renamed over it. A save by an editor between
    modc's read and that comparison is never lost: the file is left as saved and ChangedOnDisk
    raised. (A save in the microseconds between the comparison and the rename could still be
    replaced; no portable call closes that gap.) A symlink is followed, so the file it points
    to is rewritten and the link stays."""
    import os
    import stat

    from ..files import read_bounded
    from ..outputs import replace_file

    real = os.path.realpath(path)
    mode = stat.S_IMODE(os.stat(real).st_mode)
    if expected is None:
        expected = read_bounded(real, 1 << 30)[0]
    old = expected

    def unchanged() -> None:
        now, size = read_bounded(real, len(old))
        if size != len(old) or now != old:
            raise ChangedOnDisk(path)

    replace_file(real, text.encode("utf-8"), mode=mode, before_rename=unchanged, durable=True)
