"""What the language server knows about one version of a document (Analysis), shared by every
feature module (hover, completion, symbols, formatting) as plain functions of
(Analysis, character offset).

Two views of a document are used side by side:

- the checked one (modc.compiler.check_text: the AST's spans and the model), exact but only
  there when the file parses;
- the error-tolerant parse (tolerant.py: the same grammar, restarted after errors and closed
  with placeholders), which keeps completion, symbols and definitions working while a file is
  half typed; and a token view of the raw text (`lex`: words, numbers, codes, comments, whose
  shapes are the grammar's own terminals) that tells hover what is under the cursor.

Every position conversion goes through convert.LineIndex; the server (server.py) only
converts LSP positions to offsets and back.
"""

from __future__ import annotations

import bisect
import re
from dataclasses import dataclass, field
from functools import cache, cached_property
from pathlib import Path
from typing import NamedTuple

from lark import Token, Tree
from lsprotocol import types

from ..compiler import YAML_SUFFIXES, Checked, check_text
from ..model import ResolvedRobot, Robot
from ..model.library import Library
from ..model.library import default as default_library
from ..model.library import load as load_library
from ..syntax import ast
from . import convert, language, tolerant

# --- tokens and outline ---------------------------------------------------------------------------


class Tok(NamedTuple):
    kind: str  # comment string number code word punct other
    text: str
    start: int
    end: int
    bol: bool = False  # first token on its line


@cache
def _token_re() -> re.Pattern[str]:
    """The token view's shapes, taken from the grammar's own terminals (so they cannot drift):
    a comment, a string (also one still being typed), a number, a diagnostic code (with a '-';
    plain lowercase words are words), a name, the grammar's punctuation."""
    grammar = language.grammar()

    def pattern(name: str) -> str:
        return grammar.get_terminal(name).pattern.to_regexp()

    punctuation = sorted(
        t.pattern.value for t in grammar.terminals if t.pattern.type == "str" and not t.pattern.value[:1].isalpha()
    )
    return re.compile(
        "|".join(
            (
                r"(?P<ws>\s+)",
                f"(?P<comment>{pattern('COMMENT')})",
                f'(?P<string>(?:{pattern("STRING")})|"[^"\n]*)',
                f"(?P<number>{pattern('NUMBER')})",
                f"(?P<code>(?=[a-z0-9]+-)(?:{pattern('CODE_NAME')}))",
                f"(?P<word>{pattern('NAME')})",
                "(?P<punct>" + "|".join(map(re.escape, punctuation)) + ")",
                "(?P<other>.)",
            )
        ),
        re.S,
    )


def lex(text: str) -> list[Tok]:
    out = []
    bol = True
    for m in _token_re().finditer(text):
        kind = m.lastgroup
        if kind == "ws":
            bol = bol or "\n" in m.group()
        else:
            if kind == "code" and "-" not in m.group():  # `a-` before a non-code character
                kind = "word"
            out.append(Tok(kind or "other", m.group(), m.start(), m.end(), bol))
            bol = False
    return out


@dataclass
class Block:
    """A block (`robot NAME { … }`) of the error-tolerant parse: what survives a half-typed file.
    Statements are parse trees whose tokens carry offsets into the document."""

    keyword: str
    name: Token | None
    start: int
    end: int
    stmts: list[Tree] = field(default_factory=list)

    def find(self, kind: str) -> list[Tree]:
        return [s for s in self.stmts if s.data == kind]


def tokens_of(node: Tree | Token) -> list[Token]:
    """The document's own tokens of a tree (placeholders left out), in order."""
    if isinstance(node, Token):
        return [node] if tolerant.real(node) else []
    return [t for t in node.scan_values(lambda v: isinstance(v, Token)) if tolerant.real(t)]


def offsets(tok: Token) -> tuple[int, int]:
    """A document token's offsets (the tolerant parse gives every one of them positions)."""
    return tok.start_pos or 0, tok.end_pos or 0


def extent(node: Tree | Token) -> tuple[int, int] | None:
    toks = tokens_of(node)
    return (offsets(toks[0])[0], offsets(toks[-1])[1]) if toks else None


def declared(stmt: Tree) -> Token | None:
    """The name a statement declares (pose, target, obstacles: keywords that take a NAME)."""
    if stmt.data in language.name_takers() - language.REFERS and stmt.children:
        first = stmt.children[0]
        if isinstance(first, Token) and first.type == "NAME" and tolerant.real(first):
            return first
    return None


def outline(text: str) -> list[Block]:
    """The blocks of the tolerant parse; statements after an error inside a block stay in it."""
    blocks: list[Block] = []
    for base, inside, tree in tolerant.outline(text):
        for tok in tree.scan_values(lambda v: isinstance(v, Token)):
            if tolerant.real(tok):
                tok.start_pos, tok.end_pos = offsets(tok)[0] + base, offsets(tok)[1] + base
        name = tree.children[0] if tree.children and isinstance(tree.children[0], Token) else None
        stmts = [c for c in tree.children if isinstance(c, Tree)]
        if inside is not None and blocks and (name is None or not tolerant.real(name)):
            blocks[-1].stmts += stmts
            continue
        span = extent(tree)
        start = offsets(name)[0] if name is not None and tolerant.real(name) else (span[0] if span else base)
        start = max(0, text.rfind(language.keyword_of(tree.data) or tree.data, 0, start + 1))
        blocks.append(
            Block(tree.data, name if name is not None and tolerant.real(name) else None, start, len(text), stmts)
        )
    for a, b in zip(blocks, blocks[1:], strict=False):
        a.end = b.start
    return blocks


def block_joints(block: Block) -> list[tuple[str, tuple[int, int]]] | None:
    """(unit text, offsets) of the joints of a block's first chain (its units) or dh table (its
    rows); None when it has neither."""
    for node in block.stmts:
        if node.data == "chain":
            return [(str(t), offsets(t)) for t in tokens_of(node) if t.type == "UNIT_NAME"]
        if node.data == "dh":
            rows = [r for r in node.children if isinstance(r, Tree) and r.data == "dh_row" and extent(r)]
            return [(f"row {i}", extent(r) or (0, 0)) for i, r in enumerate(rows, 1)]
    return None


def joint_number(text: str) -> int | None:
    """N of a `joint_N` name."""
    m = re.fullmatch(r"joint_([0-9]{1,9})", text)  # bounded: int() refuses 4,300+ digits
    return int(m.group(1)) if m is not None else None


# --- the analysis of one document version ---------------------------------------------------------

# The AST statements that declare a name, by the kind the token view gives them.
DECL_KINDS = {ast.Pose: "pose", ast.Target: "target", ast.Box: "box", ast.Sphere: "sphere", ast.Cylinder: "cylinder",
              ast.Region: "region", ast.Task: "task", ast.StraightPath: "path"}
DECLARING = (ast.Pose, ast.Target, ast.Box, ast.Sphere, ast.Cylinder, ast.Region, ast.Task, ast.StraightPath)


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
        return [] if self.is_yaml else outline(self.text)

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
        return [b for b in self.blocks if b.name is not None and b.name == robot]

    def robot_at(self, offset: int) -> str | None:
        for r in self.tree.robots:
            a, b = self.offsets(r.span)
            if a <= offset <= b:
                return r.name.text
        block = self.block_at(offset)
        return str(block.name) if block is not None and block.name is not None else None

    @cached_property
    def model_robots(self) -> tuple[Robot, ...]:
        """The checked robots; none if the check itself fails (a compiler bug, which the
        server reports as a diagnostic): the token view still serves every feature."""
        try:
            return self.checked.design.robots
        except Exception:
            return ()

    def model_robot(self, name: str | None) -> Robot | None:
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
        """The robot's module library: the checked model's (resolved once, by the compiler's
        resolve_library pass); for a block the file does not lower yet (half typed), its
        `library` statement's; else the default (also for a library that did not load)."""
        r = self.model_robot(robot)
        if isinstance(r, ResolvedRobot):
            return r.library
        block = next(iter(self.blocks_named(robot)), None) if r is None else None
        if block is not None:
            for st in block.find("library"):
                ref = tokens_of(st)
                if ref and (lib := self.library_ref(str(ref[0]))) is not None:
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
                    if isinstance(st, DECLARING):
                        kind = DECL_KINDS[type(st)]
                        out.append(
                            Decl(kind, st.name.text, r.name.text, self.offsets(st.name.span), self.offsets(st.span))
                        )
            return out
        for b in self.blocks:
            if b.name is None:
                continue
            out.append(Decl(b.keyword, str(b.name), None, offsets(b.name), (b.start, b.end)))
            for node in b.stmts:
                if (n := declared(node)) is not None and (rng := extent(node)) is not None:
                    out.append(Decl(node.data, str(n), str(b.name), offsets(n), self.stmt_range(node, rng)))
        return out

    def stmt_range(self, st: Tree, rng: tuple[int, int]) -> tuple[int, int]:
        """A statement's offsets from its keyword (which the tree leaves out) to its last token."""
        return max(0, self.text.rfind(language.keyword_of(st.data) or st.data, 0, rng[0] + 1)), rng[1]

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
