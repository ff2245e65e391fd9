"""What the language server knows about a document: diagnostics, hover, completion, symbols,
definitions and formatting, as plain functions of (Analysis, character offset).

Two views of a document are used side by side:

- the checked one (modc.compiler.check_text: the AST's spans and the model), exact but only
  there when the file parses;
- a token view (a small lexer over the raw text and an outline of `robot NAME { statement … }`
  blocks), which needs no parse and so keeps completion, hover, symbols and definitions
  working while a file is half typed.

Every position conversion goes through convert.LineIndex; the server (server.py) only
converts LSP positions to offsets and back.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import NamedTuple

from lsprotocol import types

from ..compiler import YAML_SUFFIXES, Checked, check_text, parse_text
from ..diagnostics import REGISTRY
from ..model import quantities
from ..model.library import BUILTIN, Library
from ..model.library import default as default_library
from ..model.library import load as load_library
from ..model.library import resolve as resolve_library
from ..syntax import ast
from . import convert

# --- the language, in words ---------------------------------------------------------------------

STATEMENTS = ("chain", "dh", "library", "base", "tool", "payload", "pose", "limit", "box", "sphere",
              "cylinder", "target", "allow")
# Keywords after which a NAME follows (so `pose chain (…)` names a pose 'chain').
NAME_TAKERS = frozenset({"robot", "pose", "limit", "box", "sphere", "cylinder", "target"})

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

# Clauses after a statement keyword, in grammar order: (keyword, required). "" is a bare value.
CLAUSES = {
    "box": (("size", True), ("at", True), ("rpy", False)),
    "sphere": (("radius", True), ("at", True)),
    "cylinder": (("radius", True), ("length", True), ("at", True), ("rpy", False)),
    "base": (("at", False), ("rpy", False)),
    "tool": (("at", False), ("rpy", False)),
    "payload": (("", True), ("at", False)),
    "target": (("at", True),),
}
OBSTACLES = ("box", "sphere", "cylinder")
REPARSE_LIMIT = 100_000  # characters


def _g(x: float) -> str:
    return f"{x:g}"


# --- tokens and outline ---------------------------------------------------------------------------

class Tok(NamedTuple):
    kind: str  # comment string number code word punct other
    text: str
    start: int
    end: int
    bol: bool = False  # first token on its line


_TOKEN = re.compile(r"""
   (?P<ws>\s+)
  |(?P<comment>\#[^\n]*)
  |(?P<string>"[^"\n]*"?)
  |(?P<number>[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?)
  |(?P<code>[a-z][a-z0-9]*(?:-[a-z0-9]+)+)
  |(?P<word>[A-Za-z_][A-Za-z0-9_]*)
  |(?P<punct>[{}(),=\-])
  |(?P<other>.)
""", re.X | re.S)


def lex(text: str) -> list[Tok]:
    out = []
    bol = True
    for m in _TOKEN.finditer(text):
        kind = m.lastgroup
        if kind == "ws":
            bol = bol or "\n" in m.group()
        else:
            out.append(Tok(kind, m.group(), m.start(), m.end(), bol))
            bol = False
    return out


@dataclass
class Stmt:
    keyword: Tok
    toks: list[Tok] = field(default_factory=list)

    @property
    def end(self) -> int:
        return self.toks[-1].end if self.toks else self.keyword.end


@dataclass
class Block:
    """`robot NAME { … }` as tokens: what survives a half-typed file."""

    robot: Tok
    name: Tok | None = None
    start: int = 0
    end: int = 0
    closed: bool = False
    depth: int = 0  # brace depth reached at the end of the tokens seen (0 = header not opened)
    stmts: list[Stmt] = field(default_factory=list)

    def find(self, keyword: str) -> list[Stmt]:
        return [s for s in self.stmts if s.keyword.text == keyword]


def outline(toks: list[Tok], text_len: int) -> list[Block]:
    blocks: list[Block] = []
    cur: Block | None = None
    paren = 0
    prev: Tok | None = None
    for t in toks:
        if t.kind == "comment":
            continue
        takes_name = prev is not None and prev.text in NAME_TAKERS
        if t.bol and t.kind == "word" and t.text in (*STATEMENTS, "robot") and not takes_name:
            paren = 0  # a keyword first on its line starts afresh, whatever was left open before
        if t.kind == "word" and t.text == "robot" and not takes_name and paren == 0 and (cur is None or cur.depth <= 1 or t.bol):
            if cur is not None:  # a robot inside an unclosed robot: the old one ends here
                cur.end = t.start
            cur = Block(robot=t, start=t.start, end=text_len)
            blocks.append(cur)
            paren = 0
        elif cur is None:
            pass  # top-level junk
        elif cur.depth == 0:
            if t.text == "{":
                cur.depth = 1
            elif cur.name is None and t.kind in ("word", "code"):
                cur.name = t
        else:
            if t.text == "(":
                paren += 1
            elif t.text == ")":
                paren = max(0, paren - 1)
            if t.text == "}" and cur.depth == 1:
                cur.end, cur.closed, cur.depth = t.end, True, 0
                cur = None
                paren = 0
                prev = t
                continue
            if t.text == "{":
                cur.depth += 1
            elif t.text == "}":
                cur.depth -= 1
            if t.kind == "word" and t.text in STATEMENTS and cur.depth == 1 and paren == 0 and not takes_name:
                cur.stmts.append(Stmt(t))
                paren = 0
            elif cur.stmts:
                cur.stmts[-1].toks.append(t)
        prev = t
    return blocks


def _unit_words(stmt: Stmt) -> list[Tok]:
    """Unit-name tokens of a chain statement (words outside parentheses)."""
    out, paren = [], 0
    for t in stmt.toks:
        if t.text == "(":
            paren += 1
        elif t.text == ")":
            paren = max(0, paren - 1)
        elif paren == 0 and t.kind == "word":
            out.append(t)
    return out


# --- the analysis of one document version ---------------------------------------------------------

@dataclass
class Decl:
    kind: str  # robot pose target box sphere cylinder
    name: str
    robot: str | None
    name_range: tuple[int, int]
    range: tuple[int, int]


class Analysis:
    """One version of one document; everything is computed on first use and then kept."""

    def __init__(self, text: str, path: str, encoding: str = convert.UTF16):
        self.text = text
        self.path = path
        self.encoding = encoding

    @property
    def is_yaml(self) -> bool:
        return self.path.lower().endswith(YAML_SUFFIXES)

    @cached_property
    def index(self) -> convert.LineIndex:
        return convert.LineIndex(self.text, self.encoding)

    @cached_property
    def checked(self) -> Checked:
        # Lint-level checks only: the torque analysis needs pinocchio and takes seconds.
        return check_text(self.text, self.path)

    def diagnostics(self) -> list[types.Diagnostic]:
        return [convert.diagnostic(d, self.index, self.path) for d in self.checked.diagnostics]

    @cached_property
    def tree(self) -> ast.File:
        """The AST: the check's own if it keeps one (Checked.tree), else parsed again (a
        fraction of a millisecond for an ordinary file). A very large .mod text is served
        from the token view instead of being parsed a second time."""
        try:
            tree = getattr(self.checked, "tree", None)
        except Exception:
            tree = None
        if isinstance(tree, ast.File):
            return tree
        if len(self.text) > REPARSE_LIMIT and not self.is_yaml:
            return ast.File(self.path, ())
        return parse_text(self.text, self.path)[0]

    @cached_property
    def tokens(self) -> list[Tok]:
        return lex(self.text)

    @cached_property
    def blocks(self) -> list[Block]:
        return [] if self.is_yaml else outline(self.tokens, len(self.text))

    def offsets(self, span) -> tuple[int, int]:
        return self.index.span_offsets(span)

    # --- where is an offset ----------------------------------------------------------------
    def token_at(self, offset: int) -> Tok | None:
        """The token under the cursor: one containing offset, else one ending at it."""
        import bisect

        toks = self.tokens
        i = bisect.bisect_right([t.start for t in toks], offset) - 1
        best = None
        for j in (i, i - 1):
            if 0 <= j < len(toks):
                t = toks[j]
                if t.start <= offset < t.end:
                    return t
                if t.end == offset and best is None and t.kind in ("word", "code", "number"):
                    best = t
        return best

    def neighbours(self, tok: Tok) -> tuple[Tok | None, Tok | None]:
        sig = [t for t in self.tokens if t.kind != "comment"]
        try:
            i = sig.index(tok)
        except ValueError:
            return None, None
        return (sig[i - 1] if i > 0 else None), (sig[i + 1] if i + 1 < len(sig) else None)

    def block_at(self, offset: int) -> Block | None:
        for b in self.blocks:
            if b.start <= offset <= b.end:
                return b
        return None

    def robot_at(self, offset: int) -> str | None:
        for r in self.tree.robots:
            a, b = self.offsets(r.span)
            if a <= offset <= b:
                return r.name.text
        b = self.block_at(offset)
        return b.name.text if b is not None and b.name is not None else None

    @cached_property
    def model_robots(self) -> tuple:
        """The checked robots; none if the check itself fails (a compiler bug, which the
        server reports as a diagnostic): the token view still serves every feature."""
        try:
            return self.checked.design.robots
        except Exception:
            return ()

    def model_robot(self, name: str | None):
        if name is None:
            return None
        return next((r for r in self.model_robots if r.name == name), None)

    def library_for(self, robot: str | None) -> Library:
        """The robot's module library: the checked model's, else its `library` statement's,
        else the default."""
        r = self.model_robot(robot)
        if r is not None and r.library is not None:
            return r.library
        block = next((b for b in self.blocks if b.name is not None and b.name.text == robot), None)
        if block is not None:
            for st in block.find("library"):
                if st.toks:
                    ref = st.toks[0].text.strip('"')
                    try:
                        return load_library(ref, Path(self.path).parent)
                    except Exception:
                        pass
        return default_library()

    # --- declarations and units (AST when it parses, tokens otherwise) ---------------------
    @property
    def parsed(self) -> bool:
        return bool(self.tree.robots)

    @cached_property
    def decls(self) -> list[Decl]:
        out: list[Decl] = []
        if self.parsed:
            for r in self.tree.robots:
                out.append(Decl("robot", r.name.text, None, self.offsets(r.name.span), self.offsets(r.span)))
                for st in r.body:
                    kind = {ast.Pose: "pose", ast.Target: "target", ast.Box: "box", ast.Sphere: "sphere", ast.Cylinder: "cylinder"}.get(type(st))
                    if kind:
                        out.append(Decl(kind, st.name.text, r.name.text, self.offsets(st.name.span), self.offsets(st.span)))
            return out
        for b in self.blocks:
            if b.name is None:
                continue
            out.append(Decl("robot", b.name.text, None, (b.name.start, b.name.end), (b.start, b.end)))
            for st in b.stmts:
                if st.keyword.text in ("pose", "target", *OBSTACLES) and st.toks and st.toks[0].kind == "word":
                    n = st.toks[0]
                    out.append(Decl(st.keyword.text, n.text, b.name.text, (n.start, n.end), (st.keyword.start, st.end)))
        return out

    def units_of(self, robot: str) -> list[tuple[str, tuple[int, int]]]:
        """(unit text, offsets) of a robot's joints in order: chain units, or dh rows."""
        if self.parsed:
            for r in self.tree.robots:
                if r.name.text == robot:
                    for st in r.body:
                        if isinstance(st, ast.Chain):
                            return [(u.name.text, self.offsets(u.span)) for u in st.units]
                        if isinstance(st, ast.DH):
                            return [(f"row {i}", self.offsets(row.span)) for i, row in enumerate(st.rows, 1)]
            return []
        for b in self.blocks:
            if b.name is not None and b.name.text == robot:
                for st in b.stmts:
                    if st.keyword.text == "chain":
                        return [(t.text, (t.start, t.end)) for t in _unit_words(st)]
                    if st.keyword.text == "dh":
                        rows = [t for t in st.toks if t.text == "row"]
                        return [(f"row {i}", (t.start, t.end)) for i, t in enumerate(rows, 1)]
        return []


# --- hover ------------------------------------------------------------------------------------------

def unit_markdown(lib: Library, name: str, spec=None) -> str | None:
    split = lib.split(name)
    if split is None:
        return None
    v, k = split
    var, typ = lib.variants[v], lib.units[k]
    a = var.actuator
    lines = [
        f"**{name}** — {var.description}; unit type {k} (library {lib.name})",
        "",
        f"- actuator **{a.model}**: {_g(a.mass)} kg, {_g(a.rpm)} rpm ({a.velocity:.3g} rad/s), "
        f"nominal torque {_g(a.torque_nominal)} N·m, peak torque {_g(a.torque_peak)} N·m, "
        f"ε = {a.epsilon} (at most {a.epsilon} {v} modules per arm)",
        f"- type {k}: input port **{typ.port}**, link module **{'yes' if typ.link else 'no'}**",
        f"- x01 = {_g(typ.x01)} m, z01 = {_g(typ.z01)} m, z12 = {_g(typ.z12)} m"
        + (f", x23 = {_g(typ.x23)} m (default link length)" if typ.link else ""),
        f"- joint range {_g(var.lower_deg)}° … {_g(var.upper_deg)}°",
        "- parameters: " + ", ".join(f"`{p}`" for p in (UNIT_PARAMS if typ.link else ("pivot",))),
    ]
    if spec is not None:
        parts = [f"pivot {_g(round(math.degrees(spec.pivot), 9))}°"]
        if typ.link:
            parts.append(f"port {_g(round(math.degrees(spec.port), 9))}°")
            parts.append(f"link {_g(spec.link if spec.link is not None else typ.x23)} m")
        lines.append(f"- here: {', '.join(parts)}")
    return "\n".join(lines)


def param_markdown(name: str, lib: Library) -> str:
    kind, text = PARAMS[name]
    extra = ""
    if name == "pivot":
        t = lib.twists.pivot
        extra = f" Realisable in {lib.name}: {_g(t.min_deg)}° … {_g(t.max_deg)}° in {_g(t.step_deg)}° steps."
    elif name == "port":
        t = lib.twists.port
        extra = f" Realisable in {lib.name}: multiples of {_g(t.step_deg)}°" + ("." if t.wraps else f" in {_g(t.min_deg)}° … {_g(t.max_deg)}°.")
    elif name == "link":
        extra = f" Printable in {lib.name}: {_g(lib.link_length_min)} … {_g(lib.link_length_max)} m; default {_g(lib.units[max(lib.units)].x23)} m."
    return f"**{name}** ({kind}) — {text}{extra}"


def code_markdown(name: str) -> str:
    c = REGISTRY[name]
    tail = " — may be silenced with `allow`" if c.allowable else ""
    return f"**{name}** ({c.severity.value}{tail}): {c.summary}"


def hover(an: Analysis, offset: int) -> types.Hover | None:
    tok = an.token_at(offset)
    if tok is None or tok.kind not in ("word", "code", "string"):
        return None
    prev, nxt = an.neighbours(tok)
    text = tok.text
    robot = an.robot_at(tok.start)
    lib = an.library_for(robot)
    md = None
    if prev is not None and prev.text in NAME_TAKERS - {"limit"} and tok.kind == "word":
        md = _decl_markdown(an, text, robot, prev.text)
    elif text in PARAMS and nxt is not None and nxt.text in ("=", ":"):
        md = param_markdown(text, lib)
    elif prev is not None and prev.text == "library":
        md = _library_markdown(an, text.strip('"'))
    elif tok.kind == "code" and text in REGISTRY:
        md = code_markdown(text)
    elif (m := re.fullmatch(r"joint_(\d+)", text)) is not None:
        md = _joint_markdown(an, robot, int(m.group(1)), lib)
    elif tok.kind == "word" and lib.split(text) is not None:
        md = unit_markdown(lib, text, _unit_spec_at(an, robot, tok))
    elif text in KEYWORDS:
        md = KEYWORDS[text]
    elif text in MEASURES and prev is not None and (prev.kind == "number" or prev.text == ")"):
        kind, word = MEASURES[text]
        md = f"**{text}**: {word} ({kind})"
    else:
        decl = next((d for d in an.decls if d.name == text and (d.robot == robot or d.kind == "robot")), None)
        if decl is not None:
            md = _decl_markdown(an, text, decl.robot, decl.kind)
    if md is None:
        return None
    return types.Hover(contents=types.MarkupContent(kind=types.MarkupKind.Markdown, value=md), range=an.index.range(tok.start, tok.end))


def _decl_markdown(an: Analysis, name: str, robot: str | None, kind: str) -> str | None:
    if kind == "robot":
        r = an.model_robot(name)
        seq = f": {r.sequence} ({r.dof} joints)" if r is not None and r.units else ""
        return f"**robot {name}**{seq}"
    for d in an.decls:
        if d.name == name and d.kind == kind and d.robot == robot:
            source = " ".join(an.text[d.range[0]:d.range[1]].split())
            return f"**{kind} {name}** (robot {robot})\n\n```\n{source}\n```"
    return f"**{kind} {name}**"


def _library_markdown(an: Analysis, ref: str) -> str | None:
    try:
        lib = load_library(ref, Path(an.path).parent)
    except Exception:
        return None
    return f"**library {lib.name}** — {lib.description}\n\nunits: {', '.join(lib.unit_names())}; source: {lib.source}"


def _joint_markdown(an: Analysis, robot: str | None, n: int, lib: Library) -> str | None:
    r = an.model_robot(robot)
    if r is None or not 1 <= n <= r.dof:
        units = an.units_of(robot) if robot else []
        if 1 <= n <= len(units):
            return f"**joint_{n}**: the joint of unit {n} ({units[n - 1][0]})"
        return None
    u = r.units[n - 1]
    lo, hi = r.joint_range(n)
    return (f"**joint_{n}**: the joint of unit {n} ({u.name}); range {_g(round(math.degrees(lo), 6))}° … "
            f"{_g(round(math.degrees(hi), 6))}° with limits applied")


def _unit_spec_at(an: Analysis, robot: str | None, tok: Tok):
    r = an.model_robot(robot)
    if r is None:
        return None
    for u in r.units:
        if u.span.file == an.path:
            a, b = an.offsets(u.span)
            if a <= tok.start < b:
                return u
    return None


# --- completion -------------------------------------------------------------------------------------

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
        word = re.search(r"[A-Za-z0-9_-]*$", an.text[an.text.rfind("\n", 0, offset) + 1:offset]).group()
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
    text = an.text
    line_start = text.rfind("\n", 0, start) + 1
    line_blank = not text[line_start:start].strip()
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


def _param_before(toks: list[Tok]) -> str | None:
    for i in range(len(toks) - 1, 0, -1):
        if toks[i].text == "=" and toks[i - 1].kind == "word":
            return toks[i - 1].text
        if toks[i].text in (",", "(", "row"):
            return None
    return None


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
                used = {t.text for j, t in enumerate(group[:-1]) if t.kind == "word" and group[j + 1].text == "="}
                return _unit_params(lib, body[open_at - 1].text, used)
            if prev.kind == "number":
                p = _param_before(group)
                return _measures(PARAMS[p][0]) if p in PARAMS else _measures(None)
        return []
    if prev.kind == "number":
        if kw == "payload":
            return _measures("a mass")
        if kw == "dh":
            p = _param_before(body)
            return _measures(PARAMS[p][0]) if p in PARAMS else _measures(None)
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
        listed = {t.text for t in body}
        return [Completion(c.name, types.CompletionItemKind.EnumMember, f"{c.severity.value}, allowable", c.summary)
                for c in REGISTRY.values() if c.allowable and c.name not in listed]
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
            return [] if "home" in have else [Completion("home", types.CompletionItemKind.Constant, "the home pose", "the pose the robot starts in (all zeros when absent)")]
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
                group = body[rows[-1] + 1:]
                used = {t.text for j, t in enumerate(group[:-1]) if t.kind == "word" and group[j + 1].text == "="}
                return [Completion(p, types.CompletionItemKind.Property, PARAMS[p][0], param_markdown(p, lib), p + "=")
                        for p in DH_PARAMS if p not in used]
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
    for st in block.stmts:
        if st.keyword.text == "chain":
            return [t.text for t in _unit_words(st)]
        if st.keyword.text == "dh":
            return [f"row {i}" for i, _ in enumerate([t for t in st.toks if t.text == "row"], 1)]
    return []


def _unit_names(lib: Library, body: list[Tok]) -> list[Completion]:
    """Every unit of the library; those the assembly rules allow after the previous unit first."""
    before = [t.text for t in _unit_words(Stmt(Tok("word", "chain", 0, 0), body))]
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
    names = UNIT_PARAMS if split is None or lib.units[split[1]].link else ("pivot",)
    return [Completion(p, types.CompletionItemKind.Property, PARAMS[p][0], param_markdown(p, lib), p + "=")
            for p in names if p not in used]


def _complete_yaml(an: Analysis, offset: int) -> list[Completion]:
    """The YAML form: unit names in a chain list or after `unit:`, codes in `allow`."""
    text = an.text
    line_start = text.rfind("\n", 0, offset) + 1
    line = text[line_start:offset]
    before = text[:line_start]
    key = None
    for m in re.finditer(r"^\s*(?:-\s+)?([A-Za-z_]+):", before, re.M):
        key = m.group(1)
    lib = an.library_for(an.robot_at(offset))
    if re.search(r"\bunit:\s*\S*$", line) or (key == "chain" and re.fullmatch(r"\s*-\s*\S*", line)) or re.search(r"chain:\s*\[[^\]]*$", line):
        return _unit_names(lib, [])
    if (key == "allow" and re.fullmatch(r"\s*-\s*\S*", line)) or re.search(r"allow:\s*\[[^\]]*$", line):
        return [Completion(c.name, types.CompletionItemKind.EnumMember, f"{c.severity.value}, allowable", c.summary)
                for c in REGISTRY.values() if c.allowable]
    return []


# --- symbols ---------------------------------------------------------------------------------------

SYMBOL_KIND = {
    "robot": types.SymbolKind.Class, "chain": types.SymbolKind.Array, "unit": types.SymbolKind.Module,
    "dh": types.SymbolKind.Array, "row": types.SymbolKind.Field, "pose": types.SymbolKind.Constant,
    "target": types.SymbolKind.Variable, "box": types.SymbolKind.Struct, "sphere": types.SymbolKind.Struct,
    "cylinder": types.SymbolKind.Struct,
}


def _sym(an: Analysis, name: str, kind: str, rng: tuple[int, int], sel: tuple[int, int], detail: str = "", children=None) -> types.DocumentSymbol:
    a, b = min(rng[0], sel[0]), max(rng[1], sel[1])
    return types.DocumentSymbol(name=name or "?", kind=SYMBOL_KIND[kind], range=an.index.range(a, b),
                                selection_range=an.index.range(*sel), detail=detail or None, children=children)


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
                    units = [_sym(an, u.name.text, "unit", an.offsets(u.span), an.offsets(u.name.span), f"joint_{i}")
                             for i, u in enumerate(st.units, 1)]
                    children.append(_sym(an, "chain", "chain", rng, (rng[0], rng[0]), "-".join(u.name.text for u in st.units), units))
                elif isinstance(st, ast.DH):
                    rows = [_sym(an, f"row {i}", "row", an.offsets(row.span), an.offsets(row.span), f"joint_{i}")
                            for i, row in enumerate(st.rows, 1)]
                    children.append(_sym(an, "dh", "dh", rng, (rng[0], rng[0]), f"{len(st.rows)} rows", rows))
                elif isinstance(st, (ast.Pose, ast.Target, ast.Box, ast.Sphere, ast.Cylinder)):
                    kind = type(st).__name__.lower()
                    children.append(_sym(an, st.name.text, kind, rng, an.offsets(st.name.span), kind))
            out.append(_sym(an, r.name.text, "robot", an.offsets(r.span), an.offsets(r.name.span), "robot", children))
        return out
    for b in an.blocks:
        if b.name is None:
            continue
        children = []
        for st in b.stmts:
            kw = st.keyword.text
            rng = (st.keyword.start, st.end)
            if kw == "chain":
                units = [_sym(an, t.text, "unit", (t.start, t.end), (t.start, t.end), f"joint_{i}") for i, t in enumerate(_unit_words(st), 1)]
                children.append(_sym(an, "chain", "chain", rng, (st.keyword.start, st.keyword.end), "", units))
            elif kw == "dh":
                children.append(_sym(an, "dh", "dh", rng, (st.keyword.start, st.keyword.end)))
            elif kw in ("pose", "target", *OBSTACLES) and st.toks and st.toks[0].kind == "word":
                n = st.toks[0]
                children.append(_sym(an, n.text, kw, rng, (n.start, n.end), kw))
        out.append(_sym(an, b.name.text, "robot", (b.start, b.end), (b.name.start, b.name.end), "robot", children))
    return out


# --- definition -------------------------------------------------------------------------------------

def definition(an: Analysis, offset: int, uri: str) -> list[types.Location]:
    """Where a name under the cursor is defined:
    - a robot, pose, target or obstacle name: its declaration (the same robot's first, then any);
    - `joint_N` (in `limit`, or a YAML limits key): unit N of the robot's chain (or dh row N);
    - a `library` reference: the library file."""
    tok = an.token_at(offset)
    if tok is None or tok.kind not in ("word", "code", "string"):
        return []
    prev, _ = an.neighbours(tok)
    robot = an.robot_at(tok.start)
    if prev is not None and prev.text == "library" or (an.is_yaml and prev is not None and prev.text == ":" and _yaml_key_before(an, tok) == "library"):
        path = resolve_library(tok.text.strip('"'), Path(an.path).parent)
        if path is None:
            return []
        zero = types.Range(start=types.Position(line=0, character=0), end=types.Position(line=0, character=0))
        return [types.Location(uri=convert.path_to_uri(str(path)), range=zero)]
    if (m := re.fullmatch(r"joint_(\d+)", tok.text)) is not None and robot is not None:
        n = int(m.group(1))
        units = an.units_of(robot)
        if 1 <= n <= len(units):
            return [types.Location(uri=uri, range=an.index.range(*units[n - 1][1]))]
        return []
    matches = [d for d in an.decls if d.name == tok.text]
    if prev is not None and prev.text == "robot" or not any(d.robot == robot for d in matches):
        pool = matches
    else:
        pool = [d for d in matches if d.robot == robot]
    if robot is not None and any(d.kind == "robot" and d.name_range[0] <= tok.start < d.name_range[1] for d in pool):
        pool = [d for d in pool if d.kind == "robot"]
    return [types.Location(uri=uri, range=an.index.range(*d.name_range)) for d in pool]


def _yaml_key_before(an: Analysis, tok: Tok) -> str | None:
    line_start = an.text.rfind("\n", 0, tok.start) + 1
    m = re.match(r"\s*(?:-\s+)?([A-Za-z_]+)\s*:", an.text[line_start:tok.start])
    return m.group(1) if m else None


# --- formatting -------------------------------------------------------------------------------------

def formatting(an: Analysis) -> list[types.TextEdit]:
    """One edit replacing the whole document with `modc fmt`'s canonical form
    (modc.syntax.format.format_text); none when the formatter is not there, the document is
    YAML, it does not parse, or it is formatted already. A formatter failure (FormatterBug)
    propagates: the server logs it and answers no edits."""
    if an.is_yaml:
        return []
    try:
        from ..syntax.format import format_text
    except ImportError:
        return []
    new = format_text(an.text, an.path)
    if isinstance(new, tuple):  # (text or None when it does not parse, diagnostics)
        new = new[0]
    if not isinstance(new, str) or new == an.text:
        return []
    return [types.TextEdit(range=an.index.whole(), new_text=new)]
