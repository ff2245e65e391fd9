"""Completion: what may be typed at the cursor, from the token view alone (statement keywords,
clauses in grammar order, unit names with the ones the assembly rules allow first, unit and DH
parameters, units of measure, `allow` codes, built-in libraries, `joint_N`, pose vectors), so
that it works while the file is half typed. For YAML: unit names and `allow` codes."""
from __future__ import annotations

import re
from collections.abc import Collection
from dataclasses import dataclass

from lsprotocol import types

from ..diagnostics import REGISTRY
from ..model import quantities
from ..model.library import BUILTIN, Library
from ..model.library import load as load_library
from .document import Analysis, Block, Stmt, Tok, block_joints, outline, unit_words
from .hover import param_markdown, unit_markdown
from .language import (CLAUSES, DH_PARAMS, KEYWORDS, KIND_MEASURES, MEASURES, NAME_TAKERS, OBSTACLES,
                       PARAMS, STATEMENTS, UNIT_PARAMS)


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
        word = re.search(r"[A-Za-z0-9_-]*$", an.text[an.line_start(offset):offset]).group()
        items, start, end = _complete_yaml(an, offset), offset - len(word), offset
    else:
        items, start, end = _complete_mod(an, offset, snippets)
    rng = an.index.range(start, end)
    out = []
    for i, c in enumerate(items):
        new_text = c.insert if c.insert is not None else c.label
        out.append(types.CompletionItem(
            label=c.label,
            kind=c.kind,
            detail=c.detail or None,
            documentation=types.MarkupContent(kind=types.MarkupKind.Markdown, value=c.doc) if c.doc else None,
            sort_text=c.sort or f"{i:04d}",
            filter_text=c.label,
            insert_text_format=types.InsertTextFormat.Snippet if c.snippet else types.InsertTextFormat.PlainText,
            text_edit=types.TextEdit(range=rng, new_text=new_text),
        ))
    return out


def _in_comment_or_string(an: Analysis, offset: int) -> bool:
    for t in an.tokens:
        if t.start >= offset:
            break
        if t.kind == "comment" and offset <= t.end:
            return True
        if t.kind == "string" and (offset < t.end or (offset == t.end and (len(t.text) == 1 or not t.text.endswith('"')))):
            return True
    return False


def _complete_mod(an: Analysis, offset: int, snippets: bool) -> tuple[list[Completion], int, int]:
    if _in_comment_or_string(an, offset):
        return [], offset, offset
    toks = [t for t in an.tokens if t.kind != "comment" and t.start < offset]
    start = end = offset
    if toks and toks[-1].kind in ("word", "code") and toks[-1].end >= offset:
        word = toks.pop()  # the word being typed: replaced whole
        start, end = word.start, word.end
    elif toks and toks[-1].end > offset:
        return [], offset, offset  # inside a number or other token
    line_blank = not an.text[an.line_start(start):start].strip()
    blocks = outline(toks, offset)
    block = blocks[-1] if blocks and not blocks[-1].closed else None
    if block is None:
        if not toks or toks[-1].text == "}" or line_blank:
            body = "robot ${1:arm} {\n    chain ${2:H1 - L1}\n}" if snippets else "robot "
            return [Completion("robot", types.CompletionItemKind.Keyword, "robot NAME { … }", KEYWORDS["robot"], body, snippets)], start, end
        return [], start, end
    if block.depth == 0:
        return [], start, end  # `robot NAME` before its '{'
    prev = toks[-1]
    stmt = block.stmts[-1] if block.stmts else None
    robot = block.name.text if block.name is not None else None
    items: list[Completion] = []
    if stmt is not None and (prev.text != "{" or block.depth == 2):
        items = _complete_in_statement(an, block, stmt, prev, robot)
    if block.depth == 1 and (line_blank or prev.text == "{" or (stmt is not None and _statement_complete(stmt, prev))):
        items += [Completion(k, types.CompletionItemKind.Keyword, "statement", KEYWORDS[k], k + " ", sort=f"5{k}")
                  for k in STATEMENTS]
    return items, start, end


def _statement_complete(stmt: Stmt, prev: Tok) -> bool:
    """Whether the statement may end at prev (so that a new one may start after it)."""
    kw, body = stmt.keyword.text, stmt.toks
    if _open_paren(body) is not None or prev is stmt.keyword:
        return False
    if kw == "chain" and prev.text == ")":
        return True
    if prev.kind not in ("word", "code", "string") or prev.text in ("at", "rpy", "size", "radius", "length", "row"):
        return False
    if kw in NAME_TAKERS and len(body) == 1:
        return False  # `pose NAME` needs its angles
    if kw in CLAUSES:
        words = {t.text for t in body}
        if any(req and word and word not in words for word, req in CLAUSES[kw]):
            return False
    return True


def _open_paren(toks: list[Tok]) -> int | None:
    stack = []
    for i, t in enumerate(toks):
        if t.text == "(":
            stack.append(i)
        elif t.text == ")" and stack:
            stack.pop()
    return stack[-1] if stack else None


def _measures(kind: str | None) -> list[Completion]:
    names = KIND_MEASURES.get(kind, list(quantities.ALL)) if kind else list(quantities.ALL)
    return [Completion(u, types.CompletionItemKind.Unit, MEASURES[u][1], f"{MEASURES[u][1]} ({MEASURES[u][0]})") for u in names]


def _param_measures(toks: list[Tok]) -> list[Completion]:
    """Units of measure for a number just typed: those of the parameter it is assigned to."""
    p = _param_before(toks)
    return _measures(PARAMS[p][0] if p in PARAMS else None)


def _param_before(toks: list[Tok]) -> str | None:
    for i in range(len(toks) - 1, 0, -1):
        if toks[i].text == "=" and toks[i - 1].kind == "word":
            return toks[i - 1].text
        if toks[i].text in (",", "(", "row"):
            return None
    return None


def _assigned(group: list[Tok]) -> set[str]:
    """The parameters a `name=value, …` group has already set."""
    return {t.text for j, t in enumerate(group[:-1]) if t.kind == "word" and group[j + 1].text == "="}


def _vector_kind(stmt: Stmt, toks: list[Tok], close: int) -> str | None:
    """Kind of the vector closed by toks[close] (')'): from the clause word before its '('."""
    depth = 0
    for i in range(close, -1, -1):
        if toks[i].text == ")":
            depth += 1
        elif toks[i].text == "(":
            depth -= 1
            if depth == 0:
                before = toks[i - 1].text if i > 0 else stmt.keyword.text
                if before in ("at", "size"):
                    return "a length"
                if before in ("rpy",) or stmt.keyword.text in ("pose", "limit"):
                    return "an angle"
                return "unit-params" if stmt.keyword.text == "chain" else None
    return None


def _complete_in_statement(an: Analysis, block: Block, stmt: Stmt, prev: Tok, robot: str | None) -> list[Completion]:
    kw = stmt.keyword.text
    body = stmt.toks
    lib = an.library_for(robot)
    open_at = _open_paren(body)
    if open_at is not None:
        if kw == "chain" and open_at > 0 and body[open_at - 1].kind == "word":
            group = body[open_at + 1:]
            if prev.text in ("(", ","):
                return _unit_params(lib, body[open_at - 1].text, _assigned(group))
            if prev.kind == "number":
                return _param_measures(group)
        return []
    if prev.kind == "number":
        if kw == "payload":
            return _measures("a mass")
        if kw == "dh":
            return _param_measures(body)
        if kw in ("sphere", "cylinder"):
            return _measures("a length")
        return []
    if prev.text == ")":
        kind = _vector_kind(stmt, body, len(body) - 1)
        if kind == "unit-params":
            return []
        return _measures(kind)
    if kw == "chain" and (prev is stmt.keyword or prev.text == "-"):
        return _unit_names(lib, body)
    if kw == "allow" and (prev is stmt.keyword or prev.text == ","):
        return _allow_codes({t.text for t in body})
    if kw == "library" and prev is stmt.keyword:
        out = []
        for name in BUILTIN:
            try:
                desc = load_library(name).description
            except Exception:
                desc = ""
            out.append(Completion(name, types.CompletionItemKind.Module, "built-in library", desc))
        return out
    if kw == "limit" and prev is stmt.keyword:
        units = an.units_of(robot) if robot and an.parsed else _block_units(block)
        return [Completion(f"joint_{i}", types.CompletionItemKind.Variable, f"unit {i}: {u}") for i, u in enumerate(units, 1)]
    if kw == "pose":
        if prev is stmt.keyword:
            have = {s.toks[0].text for s in block.find("pose") if s.toks and s is not stmt}
            return [] if "home" in have else [Completion("home", types.CompletionItemKind.Constant, "the home pose", "the pose the robot starts in (when absent: 0 per joint, or mid-range where a limit excludes 0)")]
        if len(body) == 1 and prev is body[0]:
            n = len(_block_units(block))
            if n:
                vec = "(" + ", ".join(["0"] * n) + ") deg"
                return [Completion(vec, types.CompletionItemKind.Value, f"{n} joint angles")]
        return []
    if kw == "dh":
        if prev is stmt.keyword:
            return [Completion("fit-links", types.CompletionItemKind.Keyword, "dh option", KEYWORDS["fit-links"])]
        if block.depth == 2:
            rows = [i for i, t in enumerate(body) if t.text == "row"]
            if rows and prev.text in ("row", ","):
                return _params(DH_PARAMS, _assigned(body[rows[-1] + 1:]), lib)
            if prev.text == "{" or (prev.kind == "word" and prev.text in MEASURES):
                return [Completion("row", types.CompletionItemKind.Keyword, "dh row", KEYWORDS["row"], "row ")]
        return []
    return _clauses(stmt, prev)


def _clauses(stmt: Stmt, prev: Tok) -> list[Completion]:
    kw = stmt.keyword.text
    seq = CLAUSES.get(kw)
    if seq is None:
        return []
    body = stmt.toks
    names_first = kw in OBSTACLES or kw == "target"
    after_value = prev.kind == "word" and prev.text in MEASURES and len(body) >= 2 and (body[-2].kind == "number" or body[-2].text == ")")
    ready = (prev is stmt.keyword and not names_first and kw != "payload") or (names_first and len(body) == 1 and prev is body[0]) or after_value
    if not ready:
        return []
    used = [i for i, (word, _) in enumerate(seq) if word and any(t.text == word for t in body)]
    last = max(used) if used else (0 if kw == "payload" and any(t.kind == "number" for t in body) else -1)
    out = []
    for word, required in seq[last + 1:]:
        if word:
            out.append(Completion(word, types.CompletionItemKind.Keyword, f"{kw} clause", KEYWORDS[word], word + " "))
        if required:
            break
    return out


def _block_units(block: Block) -> list[str]:
    return [name for name, _ in block_joints(block) or ()]


def _unit_names(lib: Library, body: list[Tok]) -> list[Completion]:
    """Every unit of the library; those the assembly rules allow after the previous unit first."""
    before = [t.text for t in unit_words(body)]
    prev_variant = None
    if before and (s := lib.split(before[-1])) is not None:
        prev_variant = s[0]
    allowed = set(lib.rules.may_follow.get(prev_variant, lib.variants)) if prev_variant else {lib.rules.first_variant}
    out = []
    for name in lib.unit_names():
        v, k = lib.split(name)
        a, t = lib.variants[v].actuator, lib.units[k]
        detail = f"{a.model}, type {k} ({t.port}, {'link' if t.link else 'no link'})"
        out.append(Completion(name, types.CompletionItemKind.Module, detail, unit_markdown(lib, name) or "",
                              sort=("0" if v in allowed else "1") + name))
    return out


def _unit_params(lib: Library, unit: str, used: set[str]) -> list[Completion]:
    split = lib.split(unit)
    return _params(UNIT_PARAMS if split is None or lib.units[split[1]].link else ("pivot",), used, lib)


def _params(names: tuple[str, ...], used: set[str], lib: Library) -> list[Completion]:
    return [Completion(p, types.CompletionItemKind.Property, PARAMS[p][0], param_markdown(p, lib), p + "=")
            for p in names if p not in used]


def _allow_codes(listed: Collection[str] = ()) -> list[Completion]:
    """The diagnostic codes `allow` may silence, but those already listed."""
    return [Completion(c.name, types.CompletionItemKind.EnumMember, f"{c.severity.value}, allowable", c.summary)
            for c in REGISTRY.values() if c.allowable and c.name not in listed]


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
    if re.search(r"\bunit:\s*\S*$", line) or (key == "chain" and re.fullmatch(r"\s*-\s*\S*", line)) or re.search(r"chain:\s*\[[^\]]*$", line):
        return _unit_names(lib, [])
    if (key == "allow" and re.fullmatch(r"\s*-\s*\S*", line)) or re.search(r"allow:\s*\[[^\]]*$", line):
        return _allow_codes()
    return []
