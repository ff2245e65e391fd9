"""The error-tolerant parse: the real grammar (grammar/modc.lark) run on half-typed text.

Lark's interactive LALR parser is fed the text token by token (Preql's autocomplete habit, and
lark's examples/advanced/error_handling.py). Two questions are answered from it, so that the
language server keeps no grammar of its own:

- `stand_at(text)`: where the parser stands at the end of `text` (the text before the cursor):
  the terminals it accepts next and the value stack of the rules still open. Completion reads
  what to offer from those.
- `outline(text)`: the parse trees of every robot block, an unfinished one closed by feeding
  the parser placeholder tokens until the file may end. Symbols and declarations of a file
  that does not parse come from these trees.

A syntax error does not end either: the parse restarts at the next line that begins with a
keyword, inside the block kind whose body accepts that keyword (`robot _ {` for a statement).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from functools import cache
from typing import Any

from lark import Token, Tree
from lark.exceptions import UnexpectedInput

from . import language

END = "$END"
SYNTHETIC = -1  # start_pos of a placeholder token (never shown)


@dataclass
class Stand:
    """The parser at the end of a text: what it accepts next, what is open."""

    accepts: frozenset[str]
    stack: list[Any]  # Tokens and Trees of the rules still open, outermost first
    ok: bool = True  # False when nothing could be parsed up to here


@dataclass
class Segment:
    """One stretch of text parsed without error; `inside` names the block kind it was restarted in."""

    base: int
    inside: str | None


def _token(kind: str, value: str, pos: int = SYNTHETIC) -> Token:
    return Token(kind, value, start_pos=pos, line=1, column=1, end_line=1, end_column=1, end_pos=pos)


@cache
def _restart() -> re.Pattern[str]:
    words = sorted(language.declaration_keywords() | language.statement_keywords(), key=len, reverse=True)
    return re.compile(r"^[ \t]*(" + "|".join(map(re.escape, words)) + r")(?![\w-])", re.M)


@cache
def _block_for(keyword: str) -> str | None:
    """The block keyword whose body accepts `keyword` (None: it is accepted at the top level)."""
    if keyword in language.declaration_keywords():
        return None
    for block in sorted(language.declaration_keywords()):
        ip = language.grammar().parse_interactive("", start="start")
        try:
            for tok in _opening(block):
                ip.feed_token(tok)
        except UnexpectedInput:
            continue
        if language.terminal_of(keyword) in ip.accepts():
            return block
    return None


def _opening(block: str) -> list[Token]:
    return [_token(language.terminal_of(block), block), _token("NAME", "_"), _token("LBRACE", "{")]


def _open_block(stack: list[Any]) -> str | None:
    """The block keyword of a value stack's open block (its tokens are not reduced yet)."""
    for tok in stack:
        if isinstance(tok, Token) and tok.value in language.declaration_keywords():
            return str(tok.value)
    return None


def _segments(text: str, pos: int = 0, inside: str | None = None):
    """Yield (segment, interactive parser at its end, error offset or None) over the text from
    pos (inside a block of that kind). After an error the parse restarts at the next line that
    begins with a keyword; failing that, at the end of the text when the error's line is over
    (so that a new line may start afresh)."""
    while True:
        ip = language.grammar().parse_interactive(text[pos:], start="start")
        if inside is not None:
            for tok in _opening(inside):
                ip.feed_token(tok)
        seg = Segment(pos, inside)
        try:
            for _ in ip.iter_parse():
                pass
        except UnexpectedInput as e:
            at = pos + (getattr(e, "pos_in_stream", None) or 0)
            yield seg, ip, at
            m = _restart().search(text, at)
            # strictly forward: a restart that fails on its own first word moves on
            while m is not None and (m.start(1) < at or m.start(1) == pos):
                m = _restart().search(text, m.end())
            if m is not None:
                pos, inside = m.start(1), _block_for(m.group(1))
            elif "\n" in text[at:] and not text[text.rindex("\n") + 1 :].strip():
                pos, inside = len(text), _open_block(list(ip.parser_state.value_stack))
            else:
                return
            continue
        yield seg, ip, None
        return


def stand_at(text: str) -> Stand:
    """The parser at the end of text (errors before it skipped as described above)."""
    # Only the last statement matters: start at the last line that begins with a keyword whose
    # block is known (not `row`, whose `dh { … }` may span lines), so the cost does not grow
    # with the file.
    pos, inside = 0, None
    for m in reversed(list(_restart().finditer(text))):
        word = m.group(1)
        if word in language.declaration_keywords() or (block := _block_for(word)) is not None:
            pos, inside = m.start(1), (None if word in language.declaration_keywords() else block)
            break
    *_, (_seg, ip, err) = _segments(text, pos, inside)
    if err is not None:  # an error on the cursor's own line: nothing is known at the cursor
        return Stand(frozenset(), [], ok=False)
    return Stand(frozenset(ip.accepts()), list(ip.parser_state.value_stack))


# Placeholder tokens that close an unfinished parse, in order of preference: closers first, then
# values, then openers and required keywords.
_PLACEHOLDERS = {
    "NUMBER": "0",
    "NAME": "_",
    "UNIT_NAME": "X0",
    "CODE_NAME": "x",
    "STRING": '""',
    "LIBRARY_REF": "_",
    "MEASURE": "_",
    "LPAR": "(",
    "LBRACE": "{",
    "COMMA": ",",
    "EQUAL": "=",
}


def _close(ip) -> Tree | None:
    """Feed placeholders until the file may end; the tree, or None after too many steps. The
    parse table's choices are tried in order of preference on a copy (cheaper than accepts(),
    which tries every one)."""
    for _ in range(64):
        choices = ip.choices()
        if END in choices:
            try:
                return ip.copy(deepcopy_values=False).feed_eof()
            except UnexpectedInput:
                pass
        order = [k for k in ("RBRACE", "RPAR", *_PLACEHOLDERS) if k in choices]
        order += sorted(k for k in choices if language.literal_of(k) is not None)
        for kind in order:
            attempt = ip.copy(deepcopy_values=False)
            try:
                attempt.feed_token(_token(kind, _PLACEHOLDERS.get(kind) or language.literal_of(kind) or kind))
            except UnexpectedInput:
                continue
            ip = attempt
            break
        else:
            return None
    return None


def outline(text: str) -> list[tuple[int, str | None, Tree]]:
    """(base offset, block kind restarted in, tree) of every block, in the order of the text."""
    out = []
    for seg, ip, _err in _segments(text):
        try:
            tree = _close(ip)
        except UnexpectedInput:
            tree = None
        if tree is not None:
            out += [(seg.base, seg.inside, t) for t in tree.children if isinstance(t, Tree)]
    return out


def real(tok: Any) -> bool:
    """A token of the text (not a placeholder)."""
    return isinstance(tok, Token) and tok.start_pos is not None and tok.start_pos >= 0
