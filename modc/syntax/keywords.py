"""What the grammar (grammar/modc.lark) says about its keywords, read from Lark's rules, so that
no other place lists them: which keywords open a top-level block, start a statement inside a
block or a clause inside a statement, which take a NAME, which take a value, each keyword's
syntax. Used by the parser's error labels, the language server and the editor grammars' tests.
"""

from __future__ import annotations

import re
from functools import cache


def grammar():
    """The Lark parser of grammar/modc.lark (looked up on every call: tests swap it)."""
    from . import parser

    return parser._lark()


_lark = grammar


@cache
def _literals() -> dict[str, str]:
    """Keyword terminal name -> its word (CHAIN -> chain, DH_FIT -> fit-links)."""
    return {
        t.name: t.pattern.value
        for t in _lark().terminals
        if t.pattern.type == "str" and re.fullmatch(r"[a-z]+(?:-[a-z]+)*", t.pattern.value)
    }


def literal_of(terminal: str) -> str | None:
    return _literals().get(terminal)


def terminal_of(keyword: str) -> str:
    return next(name for name, word in _literals().items() if word == keyword)


def _expansions(rule: str) -> list[list[str]]:
    return [[s.name for s in r.expansion] for r in _lark().rules if r.origin.name == rule]


def _items(rule: str, seen: frozenset[str] = frozenset()) -> list[str]:
    """The rules a rule stands for, Lark's inlined helpers (_stmt, __robot_star_1) looked through,
    in grammar order."""
    out: list[str] = []
    for exp in _expansions(rule):
        for sym in exp:
            if sym.startswith("_") and sym not in seen:
                out += [x for x in _items(sym, seen | {rule, sym}) if x not in out]
            elif sym.islower() and not sym.startswith("_") and sym not in out:
                out.append(sym)
    return out


def keyword_of(rule: str) -> str | None:
    """The keyword a rule starts with (`pose` -> pose, `dh_row` -> row)."""
    return _first_keyword(rule)


def _first_keyword(rule: str) -> str | None:
    for exp in _expansions(rule):
        if exp and (word := literal_of(exp[0])) is not None:
            return word
    return None


@cache
def _blocks() -> dict[str, list[str]]:
    """Keyword of a rule with a `{ … }` body -> the keywords that start a statement in the body."""
    out: dict[str, list[str]] = {}
    for r in _lark().rules:
        exp = [s.name for s in r.expansion]
        if "LBRACE" in exp and (kw := literal_of(exp[0])) is not None:
            body = exp[exp.index("LBRACE") + 1 :]
            words = out.setdefault(kw, [])
            for sym in body:
                for item in _items(sym) if sym.startswith("_") else [sym] if sym.islower() else []:
                    if (w := _first_keyword(item)) is not None and w not in words:
                        words.append(w)
    return out


def all_keywords() -> frozenset[str]:
    return frozenset(_literals().values())


@cache
def declaration_keywords() -> frozenset[str]:
    """Keywords that open a top-level block (`robot`)."""
    return frozenset(w for item in _items("start") if (w := _first_keyword(item)) is not None)


@cache
def statement_keywords() -> frozenset[str]:
    """Keywords that start a statement inside a block (chain, …, and `row` inside `dh { }`)."""
    return frozenset(w for words in _blocks().values() for w in words)


@cache
def clause_keywords() -> frozenset[str]:
    """Every other keyword: inside a statement (at, rpy, size, fit-links, …)."""
    return frozenset(_literals().values()) - declaration_keywords() - statement_keywords()


@cache
def name_takers() -> frozenset[str]:
    """Keywords followed by a NAME (so `pose chain (…)` names a pose 'chain')."""
    return frozenset(
        w
        for r in _lark().rules
        if len(r.expansion) > 1 and r.expansion[1].name == "NAME" and (w := literal_of(r.expansion[0].name)) is not None
    )


@cache
def value_keywords() -> frozenset[str]:
    """Keywords right before a quantity or a vector (at, size, payload, radius, …), or before the
    NAME of a statement whose value is a vector (pose, limit): QUANTITY_KINDS must know them."""
    out = set()
    for r in _lark().rules:
        exp = [s.name for s in r.expansion]
        for i, sym in enumerate(exp[:-1]):
            word = literal_of(sym)
            nxt = exp[i + 2] if exp[i + 1] == "NAME" and i + 2 < len(exp) else exp[i + 1]
            if word is not None and nxt in ("quantity", "vector"):
                out.add(word)
    return frozenset(out)


_PUNCTUATION = {"LBRACE": "{", "RBRACE": "}", "LPAR": "(", "RPAR": ")", "MINUS": "-", "COMMA": ","}


def syntax_of(keyword: str) -> str:
    """The keyword's rule written out, its longest form: `target NAME at (…)`."""
    rule = next(
        (r.origin.name for r in _lark().rules if r.expansion and literal_of(r.expansion[0].name) == keyword), None
    )
    if rule is None:
        return keyword
    exp = max(_expansions(rule), key=len)
    words = []
    for sym in exp:
        if (w := literal_of(sym)) is not None:
            words.append(w)
        elif sym in ("vector", "params"):
            words.append("(…)")
        elif sym.islower() and not sym.startswith("_"):
            first = _first_keyword(sym)
            words.append(syntax_of(first) if first else sym.upper())
        elif sym.startswith("_"):
            words.append("…")
        else:
            words.append(_PUNCTUATION.get(sym, sym))
    return " ".join(words)


def reset() -> None:
    """Forget what was read from the grammar (tests that swap the grammar call this)."""
    for fn in (
        _literals,
        _blocks,
        declaration_keywords,
        statement_keywords,
        clause_keywords,
        name_takers,
        value_keywords,
    ):
        fn.cache_clear()


def statements(block: str = "robot") -> tuple[str, ...]:
    """The statement keywords of a block, in grammar order."""
    return tuple(_blocks().get(block, ()))


def block_statement_terminals() -> dict[str, str]:
    """Terminal -> keyword of every statement of a top-level block (not `row`, inside `dh { }`),
    in grammar order."""
    return {terminal_of(w): w for b in sorted(declaration_keywords()) for w in statements(b)}
