"""Completion: what may be typed at the cursor, read from the grammar itself. The text before
the cursor goes through the error-tolerant parse (tolerant.stand_at); the terminals the parser
accepts there say what to offer: keywords (statements and clauses exactly where the grammar
allows them), unit names (the ones the assembly rules allow first), parameter names, units of
measure (of the kind the value takes), `allow` codes, libraries, `joint_N`, a pose's vector.
For YAML: unit names and `allow` codes."""

from __future__ import annotations

import re
from collections.abc import Collection
from dataclasses import dataclass
from typing import Any

from lark import Token, Tree
from lsprotocol import types

from ..diagnostics import REGISTRY
from ..model import quantities
from ..model.library import BUILTIN, Library
from ..model.library import default as default_library
from ..model.library import load as load_library
from . import document, language, tolerant
from .document import Analysis, block_joints
from .hover import param_markdown, unit_markdown
from .language import DH_PARAMS, KIND_MEASURES, MEASURES, PARAMS, QUANTITY_KINDS, UNIT_PARAMS, keyword_doc


@dataclass
class Completion:
    label: str
    kind: types.CompletionItemKind
    detail: str = ""
    doc: str = ""
    insert: str | None = None
    snippet: bool = False
    sort: str | None = None


def complete(an: Analysis, offset: int, snippets: bool = True) -> list[types.CompletionItem]:
    offset = max(0, min(offset, len(an.text)))
    if an.is_yaml:
        word = re.findall(r"[A-Za-z0-9_-]*$", an.text[an.line_start(offset) : offset])[0]
        items, start, end = _complete_yaml(an, offset), offset - len(word), offset
    else:
        items, start, end = _complete_mod(an, offset, snippets)
    rng = an.index.range(start, end)
    out = []
    for i, c in enumerate(items):
        new_text = c.insert if c.insert is not None else c.label
        out.append(
            types.CompletionItem(
                label=c.label,
                kind=c.kind,
                detail=c.detail or None,
                documentation=types.MarkupContent(kind=types.MarkupKind.Markdown, value=c.doc) if c.doc else None,
                sort_text=c.sort or f"{i:04d}",
                filter_text=c.label,
                insert_text_format=types.InsertTextFormat.Snippet if c.snippet else types.InsertTextFormat.PlainText,
                text_edit=types.TextEdit(range=rng, new_text=new_text),
            )
        )
    return out


def _in_comment_or_string(an: Analysis, offset: int) -> bool:
    for t in an.tokens:
        if t.start >= offset:
            break
        if t.kind == "comment" and offset <= t.end:
            return True
        if t.kind == "string" and (
            offset < t.end or (offset == t.end and (len(t.text) == 1 or not t.text.endswith('"')))
        ):
            return True
    return False


def _complete_mod(an: Analysis, offset: int, snippets: bool) -> tuple[list[Completion], int, int]:
    if _in_comment_or_string(an, offset):
        return [], offset, offset
    toks = [t for t in an.tokens if t.kind != "comment" and t.start < offset]
    start = end = offset
    if toks and toks[-1].kind in ("word", "code") and toks[-1].end >= offset:
        start, end = toks[-1].start, toks[-1].end  # the word being typed: replaced whole
    elif toks and toks[-1].end > offset:
        return [], offset, offset  # inside a number or other token
    stand = tolerant.stand_at(an.text[:start])
    if not stand.ok:
        return [], start, end
    return _offer(an, stand, start, snippets), start, end


def _real_tokens(stack: list[Any]) -> list[Token]:
    return [t for t in stack if isinstance(t, Token) and tolerant.real(t)]


def _statement(stack: list[Any]) -> tuple[str | None, list[Any]]:
    """The statement keyword open at the end of the stack and what follows it."""
    keywords = language.statement_keywords()
    for i in range(len(stack) - 1, -1, -1):
        item = stack[i]
        if isinstance(item, Token) and item.value in keywords and item.type == language.terminal_of(item.value):
            return str(item.value), stack[i + 1 :]
        if isinstance(item, Token) and item.type == "LBRACE":
            break
    return None, []


def _offer(an: Analysis, stand: tolerant.Stand, start: int, snippets: bool) -> list[Completion]:
    accepts, stack = stand.accepts, stand.stack
    last = stack[-1] if stack else None
    if "MEASURE" in accepts and isinstance(last, Token) and last.type in ("NUMBER", "RPAR"):
        return _measures(_value_kind(stack))  # a number or vector just typed wants its unit
    stmt, body = _statement(stack)
    # the robot and its library only where an item depends on them (in a file that does not
    # parse, finding the robot takes the whole outline)
    needs_robot = bool(accepts & {"NAME", "UNIT_NAME"}) or (stmt == "pose" and "LPAR" in accepts)
    robot = an.robot_at(start) if needs_robot else None
    lib = an.library_for(robot) if needs_robot else default_library()
    items: list[Completion] = []
    if "NAME" in accepts:
        items += _names(an, robot, stmt, body, lib)
    if "UNIT_NAME" in accepts:
        items += _unit_names(lib, [str(t) for item in body for t in document.tokens_of(item) if t.type == "UNIT_NAME"])
    if "CODE_NAME" in accepts:
        items += _allow_codes({str(t) for t in _real_tokens(body) if t.type == "CODE_NAME"})
    if accepts & {"LIBRARY_REF", "STRING"}:
        items += _libraries()
    if "LPAR" in accepts and stmt == "pose" and isinstance(last, Token) and last.type == "NAME":
        n = len(_block_units(an, robot))
        if n:
            items.append(
                Completion("(" + ", ".join(["0"] * n) + ") deg", types.CompletionItemKind.Value, f"{n} joint angles")
            )
    return items + _keywords(accepts, snippets)


def _keywords(accepts: frozenset[str], snippets: bool) -> list[Completion]:
    """The keywords the grammar accepts here: clauses first, then statements in grammar order."""
    order = {
        w: i
        for i, w in enumerate(
            w for b in ("robot", *sorted(language.declaration_keywords())) for w in language.statements(b)
        )
    }
    out = []
    for word in sorted(filter(None, map(language.literal_of, accepts)), key=lambda w: (w in order, order.get(w, 0), w)):
        if word in language.declaration_keywords():
            body = SNIPPETS.get(word, word + " ${1:name} {\n    $0\n}") if snippets else word + " "
            out.append(
                Completion(
                    word, types.CompletionItemKind.Keyword, language.syntax_of(word), keyword_doc(word), body, snippets
                )
            )
        elif word in order:
            out.append(
                Completion(
                    word,
                    types.CompletionItemKind.Keyword,
                    "statement",
                    keyword_doc(word),
                    word + " ",
                    sort=f"5{order[word]:03d}",
                )
            )
        else:
            out.append(
                Completion(
                    word, types.CompletionItemKind.Keyword, "clause", keyword_doc(word), word + " ", sort=f"4{word}"
                )
            )
    return out


SNIPPETS = {"robot": "robot ${1:arm} {\n    chain ${2:H1 - L1}\n}"}


def _names(an: Analysis, robot: str | None, stmt: str | None, body: list[Any], lib: Library) -> list[Completion]:
    """A NAME is accepted: parameter names inside a unit's parentheses or a dh row, `joint_N`
    after a statement that refers to a joint, `home` after `pose`; else a new name (nothing)."""
    for i in range(len(body) - 1, -1, -1):
        item = body[i]
        if (
            isinstance(item, Token)
            and item.type == "LPAR"
            and i > 0
            and isinstance(body[i - 1], Token)
            and body[i - 1].type == "UNIT_NAME"
        ):
            return _unit_params(lib, str(body[i - 1]), _assigned(body[i + 1 :]))
    if stmt == "row":
        return _params(DH_PARAMS, _assigned(body), lib)
    if body:
        return []
    if stmt == "rank":
        from ..objectives import REGISTRY

        return [Completion(k, types.CompletionItemKind.EnumMember, o.summary) for k, o in REGISTRY.items()]
    if stmt == "limit":
        return [
            Completion(f"joint_{i}", types.CompletionItemKind.Variable, f"unit {i}: {u}")
            for i, u in enumerate(_block_units(an, robot), 1)
        ]
    if stmt == "pose" and not any(d.kind == "pose" and d.name == "home" and d.robot == robot for d in an.decls):
        return [
            Completion(
                "home",
                types.CompletionItemKind.Constant,
                "the home pose",
                "the pose the robot starts in (when absent: 0 per joint, or mid-range where a limit excludes 0)",
            )
        ]
    return []


def _assigned(items: list[Any]) -> set[str]:
    """The parameters a `name=value, …` group has already set."""
    out = {str(t.children[0]) for t in items if isinstance(t, Tree) and t.data == "param" and t.children}
    toks = [t for t in items if isinstance(t, Token)]
    out |= {str(a) for a, b in zip(toks, toks[1:], strict=False) if a.type == "NAME" and b.type == "EQUAL"}
    return out


def _value_kind(stack: list[Any]) -> str | None:
    """The kind of quantity a number or vector at the end of the stack is: its parameter's, else
    that of the keyword (or the named statement) it follows."""
    toks = [t for t in stack if isinstance(t, Token)]
    if len(toks) >= 3 and toks[-1].type == "NUMBER" and toks[-2].type == "EQUAL" and str(toks[-3]) in PARAMS:
        return PARAMS[str(toks[-3])][0]
    for i in range(len(stack) - 1, -1, -1):
        item = stack[i]
        if isinstance(item, Tree) or item.type in ("NUMBER", "COMMA", "LPAR", "RPAR", "MEASURE"):
            continue
        if item.type == "NAME" and i > 0 and isinstance(stack[i - 1], Token):
            return QUANTITY_KINDS.get(str(stack[i - 1].value))
        return QUANTITY_KINDS.get(str(item.value))
    return None


def _measures(kind: str | None) -> list[Completion]:
    names = KIND_MEASURES.get(kind, list(quantities.ALL)) if kind else list(quantities.ALL)
    return [
        Completion(u, types.CompletionItemKind.Unit, MEASURES[u][1], f"{MEASURES[u][1]} ({MEASURES[u][0]})")
        for u in names
    ]


def _libraries() -> list[Completion]:
    out = []
    for name in BUILTIN:
        try:
            desc = load_library(name).description
        except Exception:
            desc = ""
        out.append(Completion(name, types.CompletionItemKind.Module, "built-in library", desc))
    return out


def _block_units(an: Analysis, robot: str | None) -> list[str]:
    """The robot's units (or dh rows), from the check when the file parses, else the outline."""
    if robot is not None and an.parsed:
        return [name for name, _ in an.units_of(robot)]
    for block in an.blocks_named(robot):
        if (joints := block_joints(block)) is not None:
            return [name for name, _ in joints]
    return []


def _unit_names(lib: Library, before: list[str]) -> list[Completion]:
    """Every unit of the library; those the assembly rules allow after the previous unit first."""
    prev_variant = None
    if before and (s := lib.split(before[-1])) is not None:
        prev_variant = s[0]
    allowed = set(lib.rules.may_follow.get(prev_variant, lib.variants)) if prev_variant else {lib.rules.first_variant}
    out = []
    for name in lib.unit_names():
        split = lib.split(name)
        assert split is not None  # the library's own names
        v, k = split
        a, t = lib.variants[v].actuator, lib.units[k]
        detail = f"{a.model}, type {k} ({t.port}, {'link' if t.link else 'no link'})"
        out.append(
            Completion(
                name,
                types.CompletionItemKind.Module,
                detail,
                unit_markdown(lib, name) or "",
                sort=("0" if v in allowed else "1") + name,
            )
        )
    return out


def _unit_params(lib: Library, unit: str, used: set[str]) -> list[Completion]:
    split = lib.split(unit)
    return _params(UNIT_PARAMS if split is None or lib.units[split[1]].link else ("pivot",), used, lib)


def _params(names: tuple[str, ...], used: set[str], lib: Library) -> list[Completion]:
    return [
        Completion(p, types.CompletionItemKind.Property, PARAMS[p][0], param_markdown(p, lib), p + "=")
        for p in names
        if p not in used
    ]


def _allow_codes(listed: Collection[str] = ()) -> list[Completion]:
    """The diagnostic codes `allow` may silence, but those already listed."""
    return [
        Completion(c.name, types.CompletionItemKind.EnumMember, f"{c.severity.value}, allowable", c.summary)
        for c in REGISTRY.values()
        if c.allowable and c.name not in listed
    ]


def _complete_yaml(an: Analysis, offset: int) -> list[Completion]:
    """The YAML form: unit names in a chain list or after `unit:`, codes in `allow`."""
    text = an.text
    line_start = an.line_start(offset)
    line = text[line_start:offset]
    before = text[:line_start]
    key = None
    for m in re.finditer(r"^\s*(?:-\s+)?([A-Za-z_]+):", before, re.M):
        key = m.group(1)
    lib = an.library_for(an.robot_at(offset))
    if (
        re.search(r"\bunit:\s*\S*$", line)
        or (key == "chain" and re.fullmatch(r"\s*-\s*\S*", line))
        or re.search(r"chain:\s*\[[^\]]*$", line)
    ):
        return _unit_names(lib, [])
    if (key == "allow" and re.fullmatch(r"\s*-\s*\S*", line)) or re.search(r"allow:\s*\[[^\]]*$", line):
        return _allow_codes()
    return []
