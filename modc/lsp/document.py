"""What the language server knows about one version of a document (Analysis), shared by every
feature module (hover, completion, symbols, formatting) as plain functions of
(Analysis, character offset).

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

import bisect
import re
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import NamedTuple

from lsprotocol import types

from ..compiler import YAML_SUFFIXES, Checked, check_text
from ..model.library import Library
from ..model.library import default as default_library
from ..model.library import load as load_library
from ..syntax import ast
from . import convert
from .language import DECLARING, NAME_TAKERS, STATEMENTS

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

    @property
    def declared(self) -> Tok | None:
        """The name a pose, target or obstacle statement declares."""
        if self.keyword.text in DECLARING and self.toks and self.toks[0].kind == "word":
            return self.toks[0]
        return None


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


def unit_words(toks: list[Tok]) -> list[Tok]:
    """Unit-name tokens of a chain statement's body (words outside parentheses)."""
    out, paren = [], 0
    for t in toks:
        if t.text == "(":
            paren += 1
        elif t.text == ")":
            paren = max(0, paren - 1)
        elif paren == 0 and t.kind == "word":
            out.append(t)
    return out


def block_joints(block: Block) -> list[tuple[str, tuple[int, int]]] | None:
    """(unit text, offsets) of the joints of a block's first chain (its units) or dh table (its
    rows); None when it has neither."""
    for st in block.stmts:
        if st.keyword.text == "chain":
            return [(t.text, (t.start, t.end)) for t in unit_words(st.toks)]
        if st.keyword.text == "dh":
            rows = [t for t in st.toks if t.text == "row"]
            return [(f"row {i}", (t.start, t.end)) for i, t in enumerate(rows, 1)]
    return None


def joint_number(text: str) -> int | None:
    """N of a `joint_N` name."""
    m = re.fullmatch(r"joint_([0-9]{1,9})", text)  # bounded: int() refuses 4,300+ digits
    return int(m.group(1)) if m is not None else None


# --- the analysis of one document version ---------------------------------------------------------

# The AST statements that declare a name, by the kind the token view gives them.
DECL_KINDS = {ast.Pose: "pose", ast.Target: "target", ast.Box: "box", ast.Sphere: "sphere", ast.Cylinder: "cylinder"}


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
        """The AST the check parsed (Checked.tree): one parse per version of a document."""
        return self.checked.tree or ast.File(self.path, ())

    @cached_property
    def tokens(self) -> list[Tok]:
        return lex(self.text)

    @cached_property
    def blocks(self) -> list[Block]:
        return [] if self.is_yaml else outline(self.tokens, len(self.text))

    def offsets(self, span) -> tuple[int, int]:
        return self.index.span_offsets(span)

    def line_start(self, offset: int) -> int:
        return self.text.rfind("\n", 0, offset) + 1

    # --- where is an offset ----------------------------------------------------------------
    def token_at(self, offset: int) -> Tok | None:
        """The token under the cursor: one containing offset, else one ending at it."""
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

    def name_at(self, offset: int) -> Tok | None:
        """The word, code or string under the cursor: what hover and go-to-definition look up."""
        tok = self.token_at(offset)
        return tok if tok is not None and tok.kind in ("word", "code", "string") else None

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

    def blocks_named(self, robot: str | None) -> list[Block]:
        return [b for b in self.blocks if b.name is not None and b.name.text == robot]

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

    def library_ref(self, ref: str) -> Library | None:
        """The library a `library` statement names (quoted or not, a path relative to this
        file); None when it does not load."""
        try:
            return load_library(ref.strip('"'), Path(self.path).parent)
        except Exception:
            return None

    def library_for(self, robot: str | None) -> Library:
        """The robot's module library: the checked model's, else its `library` statement's,
        else the default."""
        r = self.model_robot(robot)
        if r is not None and r.library is not None:
            return r.library
        block = next(iter(self.blocks_named(robot)), None)
        if block is not None:
            for st in block.find("library"):
                if st.toks and (lib := self.library_ref(st.toks[0].text)) is not None:
                    return lib
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
                    if kind := DECL_KINDS.get(type(st)):
                        out.append(Decl(kind, st.name.text, r.name.text, self.offsets(st.name.span), self.offsets(st.span)))
            return out
        for b in self.blocks:
            if b.name is None:
                continue
            out.append(Decl("robot", b.name.text, None, (b.name.start, b.name.end), (b.start, b.end)))
            for st in b.stmts:
                if (n := st.declared) is not None:
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
        for b in self.blocks_named(robot):
            if (joints := block_joints(b)) is not None:
                return joints
        return []
