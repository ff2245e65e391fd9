"""The .mod language for the language server and the editor grammars.

What the grammar says is read from it (grammar/modc.lark through Lark's rules): which keywords
open a block, start a statement or a clause, which take a name, each keyword's syntax. What only
the model knows is written here, in words: the hover text of keywords, parameters and units of
measure, and which kind of quantity follows a keyword. Tests check that every keyword and every
value-taking keyword of the grammar has its entry.
"""
from __future__ import annotations

from functools import cache

from ..model import quantities

# --- read from the grammar ---------------------------------------------------------------------

def grammar():
    """The Lark parser of grammar/modc.lark (looked up on every call: tests swap it)."""
    from ..syntax import parser

    return parser._lark()


_lark = grammar


@cache
def _literals() -> dict[str, str]:
    """Keyword terminal name -> its word (CHAIN -> chain, DH_FIT -> fit-links)."""
    import re

    return {t.name: t.pattern.value for t in _lark().terminals
            if t.pattern.type == "str" and re.fullmatch(r"[a-z]+(?:-[a-z]+)*", t.pattern.value)}


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
            body = exp[exp.index("LBRACE") + 1:]
            words = out.setdefault(kw, [])
            for sym in body:
                for item in (_items(sym) if sym.startswith("_") else [sym] if sym.islower() else []):
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
    return frozenset(w for r in _lark().rules if len(r.expansion) > 1 and r.expansion[1].name == "NAME"
                     and (w := literal_of(r.expansion[0].name)) is not None)


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


def syntax_of(keyword: str) -> str:
    """The keyword's rule written out, its longest form: `target NAME at (…)`."""
    rule = next((r.origin.name for r in _lark().rules if r.expansion and literal_of(r.expansion[0].name) == keyword),
                None)
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
            words.append(syntax_of(_first_keyword(sym)) if _first_keyword(sym) else sym.upper())
        elif sym.startswith("_"):
            words.append("…")
        else:
            words.append({"LBRACE": "{", "RBRACE": "}", "LPAR": "(", "RPAR": ")", "MINUS": "-", "COMMA": ","}.get(sym, sym))
    return " ".join(words)


def reset() -> None:
    """Forget what was read from the grammar (tests that swap the grammar call this)."""
    for fn in (_literals, _blocks, declaration_keywords, statement_keywords, clause_keywords, name_takers,
               value_keywords):
        fn.cache_clear()
    from . import tolerant

    tolerant._restart.cache_clear()
    tolerant._block_for.cache_clear()


def statements(block: str = "robot") -> tuple[str, ...]:
    """The statement keywords of a block, in grammar order."""
    return tuple(_blocks().get(block, ()))


# --- what the model knows ----------------------------------------------------------------------

# The kind of quantity after a value keyword (value_keywords(); a test keeps them in step).
QUANTITY_KINDS = {"at": "a length", "size": "a length", "radius": "a length", "length": "a length",
                  "rpy": "an angle", "pose": "an angle", "limit": "an angle", "payload": "a mass"}
# Name-taking statements whose name refers to something (a joint) rather than declaring one.
REFERS = frozenset({"limit"})

KEYWORDS = {
    "robot": "`robot NAME { … }` — one arm; a file holds one or more robot blocks.",
    "chain": "`chain H1 - H4(pivot=-90deg) - L4` — the modular units, base first (required unless a `dh` table is given).",
    "dh": "`dh [fit-links] { row a=…, alpha=…, d=… … }` — a standard DH table that modc turns into a chain of units (paper section 4.2).",
    "row": "`row a=0.3 m, alpha=-90deg, d=0 m[, theta=0deg]` — one row of a `dh` table (standard DH), base first.",
    "fit-links": "`dh fit-links { … }` — print link modules whose length realises each row's `a` exactly.",
    "library": "`library mark2` | `library mark2-strict` | `library \"path.yaml\"` — the module library this robot is built from (default mark2).",
    "base": "`base at (x, y, z) m rpy (r, p, y) deg` — where base_link sits in the cell (for simulation and planning).",
    "tool": "`tool at (x, y, z) m rpy (r, p, y) deg` — tool0 relative to the last unit's last frame.",
    "payload": "`payload 0.2 kg at (x, y, z) m` — a payload's mass and its centre of mass in tool0.",
    "pose": "`pose NAME (q1, …, qn) deg` — a named joint pose, one angle per joint; `home` is the robot's home pose.",
    "limit": "`limit joint_N (lower, upper) deg` — narrow joint N's range (within the library's).",
    "box": "`box NAME size (x, y, z) m at (x, y, z) m [rpy (…) deg]` — a box obstacle in base_link (size = full edge lengths).",
    "sphere": "`sphere NAME radius R m at (x, y, z) m` — a sphere obstacle in base_link.",
    "cylinder": "`cylinder NAME radius R m length L m at (x, y, z) m [rpy (…) deg]` — a cylinder obstacle in base_link, axis along z before rpy.",
    "target": "`target NAME at (x, y, z) m` — a position for tool0, in base_link.",
    "allow": "`allow first-variant, …` — silence one of the paper's assembly rules for this robot on purpose (e.g. for a wrist).",
    "at": "`at (x, y, z) m` — a position (in base_link for obstacles and targets, in tool0 for a payload).",
    "rpy": "`rpy (roll, pitch, yaw) deg` — an orientation as fixed-axis roll, pitch, yaw (as in URDF).",
    "size": "`size (x, y, z) m` — a box's full edge lengths.",
    "radius": "`radius R m` — the radius of a sphere or cylinder.",
    "length": "`length L m` — a cylinder's length along its axis.",
}

PARAMS = {
    "pivot": ("an angle", "turns the joint axis in the adaptive twist unit: a rotation about y before the joint "
              "(intersecting axes, the paper's type III twist)."),
    "port": ("an angle", "turns the next module where it meets the end of the link: a rotation about x (skew axes, "
             "the paper's type II twist). Only units with a link module (types 3 and 4)."),
    "link": ("a length", "the printed link module's length (x23). Only units with a link module (types 3 and 4)."),
    "a": ("a length", "DH `a`: length of the common normal, along x_i (standard DH: Rz(θ) Tz(d) Tx(a) Rx(α))."),
    "alpha": ("an angle", "DH `alpha`: twist about x_i between consecutive joint axes."),
    "d": ("a length", "DH `d`: offset along z_(i-1)."),
    "theta": ("an angle", "DH `theta`: joint angle offset about z_(i-1) (default 0)."),
}
UNIT_PARAMS = ("pivot", "port", "link")
DH_PARAMS = ("a", "alpha", "d", "theta")
MEASURES = {
    **{u: ("an angle", n) for u, n in (("deg", "degrees"), ("rad", "radians"))},
    **{u: ("a length", n) for u, n in (("m", "metres"), ("cm", "centimetres"), ("mm", "millimetres"))},
    **{u: ("a mass", n) for u, n in (("kg", "kilograms"), ("g", "grams"))},
}
assert set(MEASURES) == set(quantities.ALL)
KIND_MEASURES = {kind: list(table) for kind, table in quantities.KINDS.items()}




def keyword_doc(keyword: str) -> str:
    """Hover text of a keyword: its prose when written, else its syntax from the grammar."""
    return KEYWORDS.get(keyword) or f"`{syntax_of(keyword)}`"

