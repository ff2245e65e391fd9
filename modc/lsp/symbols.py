"""Document symbols (the outline of robots and what they declare) and go-to-definition."""

from __future__ import annotations

import re
from pathlib import Path

from lsprotocol import types

from ..model.library import resolve as resolve_library
from ..syntax import ast
from . import convert
from .document import DECL_KINDS, DECLARING, Analysis, Tok, declared, extent, joint_number, offsets, tokens_of

SYMBOL_KIND = {
    "robot": types.SymbolKind.Class,
    "chain": types.SymbolKind.Array,
    "unit": types.SymbolKind.Module,
    "dh": types.SymbolKind.Array,
    "row": types.SymbolKind.Field,
    "pose": types.SymbolKind.Constant,
    "target": types.SymbolKind.Variable,
    "box": types.SymbolKind.Struct,
    "sphere": types.SymbolKind.Struct,
    "cylinder": types.SymbolKind.Struct,
    "region": types.SymbolKind.Variable,
    "task": types.SymbolKind.Event,
    "path": types.SymbolKind.Event,
}


def _sym(
    an: Analysis, name: str, kind: str, rng: tuple[int, int], sel: tuple[int, int], detail: str = "", children=None
) -> types.DocumentSymbol:
    a, b = min(rng[0], sel[0]), max(rng[1], sel[1])
    return types.DocumentSymbol(
        name=name or "?",
        kind=SYMBOL_KIND[kind],
        range=an.index.range(a, b),
        selection_range=an.index.range(*sel),
        detail=detail or None,
        children=children,
    )


def symbols(an: Analysis) -> list[types.DocumentSymbol]:
    """Robots, each with its chain (units), dh table (rows), poses, targets and obstacles.
    From the AST when the file parses, from the token outline otherwise."""
    out = []
    if an.parsed:
        for r in an.tree.robots:
            children = []
            for st in r.body:
                rng = an.offsets(st.span)
                if isinstance(st, ast.Chain):
                    units = [
                        _sym(an, u.name.text, "unit", an.offsets(u.span), an.offsets(u.name.span), f"joint_{i}")
                        for i, u in enumerate(st.units, 1)
                    ]
                    children.append(
                        _sym(
                            an, "chain", "chain", rng, (rng[0], rng[0]), "-".join(u.name.text for u in st.units), units
                        )
                    )
                elif isinstance(st, ast.DH):
                    rows = [
                        _sym(an, f"row {i}", "row", an.offsets(row.span), an.offsets(row.span), f"joint_{i}")
                        for i, row in enumerate(st.rows, 1)
                    ]
                    children.append(_sym(an, "dh", "dh", rng, (rng[0], rng[0]), f"{len(st.rows)} rows", rows))
                elif isinstance(st, DECLARING):
                    kind = DECL_KINDS[type(st)]
                    children.append(_sym(an, st.name.text, kind, rng, an.offsets(st.name.span), kind))
            out.append(_sym(an, r.name.text, "robot", an.offsets(r.span), an.offsets(r.name.span), "robot", children))
        return out
    for b in an.blocks:
        if b.name is None:
            continue
        children = []
        for node in b.stmts:
            if (span := extent(node)) is None:
                continue
            rng = an.stmt_range(node, span)
            keyword = (rng[0], rng[0] + len(node.data))
            if node.data == "chain":
                units = [
                    _sym(an, str(t), "unit", offsets(t), offsets(t), f"joint_{i}")
                    for i, t in enumerate((t for t in tokens_of(node) if t.type == "UNIT_NAME"), 1)
                ]
                children.append(_sym(an, "chain", "chain", rng, keyword, "", units))
            elif node.data == "dh":
                children.append(_sym(an, "dh", "dh", rng, keyword))
            elif (n := declared(node)) is not None and node.data in SYMBOL_KIND:
                children.append(_sym(an, str(n), node.data, rng, offsets(n), node.data))
        name = offsets(b.name)
        out.append(
            _sym(
                an,
                str(b.name),
                b.keyword if b.keyword in SYMBOL_KIND else "robot",
                (b.start, b.end),
                name,
                b.keyword,
                children,
            )
        )
    return out


def definition(an: Analysis, offset: int, uri: str) -> list[types.Location]:
    """Where a name under the cursor is defined:
    - a robot, pose, target or obstacle name: its declaration (the same robot's first, then any);
    - `joint_N` (in `limit`, or a YAML limits key): unit N of the robot's chain (or dh row N);
    - a `library` reference: the library file."""
    tok = an.name_at(offset)
    if tok is None:
        return []
    prev, _ = an.neighbours(tok)
    robot = an.robot_at(tok.start)
    if _names_library(an, tok, prev):
        path = resolve_library(tok.text.strip('"'), Path(an.path).parent)
        if path is None:
            return []
        return [convert.location(convert.path_to_uri(str(path)), convert.top())]
    if (n := joint_number(tok.text)) is not None and robot is not None:
        units = an.units_of(robot)
        if 1 <= n <= len(units):
            return [convert.location(uri, an.index.range(*units[n - 1][1]))]
        return []
    return [convert.location(uri, an.index.range(*d.name_range)) for d in _declarations(an, tok, prev, robot)]


def _names_library(an: Analysis, tok: Tok, prev: Tok | None) -> bool:
    """The token is a `library` statement's reference (or the YAML form's `library:` value)."""
    if prev is None:
        return False
    return prev.text == "library" or (an.is_yaml and prev.text == ":" and _yaml_key_before(an, tok) == "library")


def _declarations(an: Analysis, tok: Tok, prev: Tok | None, robot: str | None) -> list:
    """The declarations of the name under the cursor: the same robot's first, then any."""
    matches = [d for d in an.decls if d.name == tok.text]
    if prev is not None and prev.text == "robot" or not any(d.robot == robot for d in matches):
        pool = matches
    else:
        pool = [d for d in matches if d.robot == robot]
    if robot is not None and any(d.kind == "robot" and d.name_range[0] <= tok.start < d.name_range[1] for d in pool):
        pool = [d for d in pool if d.kind == "robot"]
    return pool


def _yaml_key_before(an: Analysis, tok: Tok) -> str | None:
    m = re.match(r"\s*(?:-\s+)?([A-Za-z_]+)\s*:", an.text[an.line_start(tok.start) : tok.start])
    return m.group(1) if m else None
