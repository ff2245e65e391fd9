"""A thin transformer: Lark parse tree -> frozen, spanned AST nodes. No checking happens here.

One method per grammar rule, called bottom-up with (meta, children). The walk is ours rather
than lark.Transformer + v_args(meta=True), whose per-node wrappers cost a tenth of a lint.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from ..diagnostics import Span
from . import ast

if TYPE_CHECKING:
    from lark import Token


def token_span(file: str, t: Token) -> Span:
    # the parser runs with positions on: every token it yields has them
    assert t.line is not None and t.column is not None and t.end_line is not None and t.end_column is not None
    assert t.start_pos is not None and t.end_pos is not None
    return Span(file, t.line, t.column, t.end_line, t.end_column, t.start_pos, t.end_pos)


def _num(t: Token) -> float:
    return float(t)


class ToAst:
    def __init__(self, file: str):
        self.file = file

    def transform(self, node):
        # a tree of Lark's or of modc.syntax.lalr's (the lint parse), whose leaves are tokens (str) or None
        if node is None or isinstance(node, str):
            return node
        children = [self.transform(c) for c in node.children]
        method = getattr(self, node.data, None)
        # rules without a method (the YAML form's *_text entry points) stay trees, as in Lark
        return type(node)(node.data, children, node.meta) if method is None else method(node.meta, children)

    def _span(self, meta) -> Span:
        return Span(self.file, meta.line, meta.column, meta.end_line, meta.end_column, meta.start_pos, meta.end_pos)

    def _name(self, t: Token) -> ast.Name:
        return ast.Name(str(t), token_span(self.file, t))

    def start(self, meta, blocks):
        return list(blocks)

    def design(self, meta, items):
        name, *body = items
        return ast.DesignBlock(self._name(name), tuple(body), self._span(meta))

    def units(self, meta, items):
        return ast.Units(
            self._count(items[0]), self._count(items[1]) if items[1] is not None else None, self._span(meta)
        )

    def _count(self, t: Token) -> ast.Quantity:
        return ast.Quantity(_num(t), None, token_span(self.file, t))

    def modules(self, meta, items):
        return ast.Modules(tuple(self._name(t) for t in items), self._span(meta))

    def links(self, meta, items):
        return ast.Links(items[0], items[1], items[2], self._span(meta))

    def rank(self, meta, items):
        return ast.Rank(tuple(self._name(t) for t in items), self._span(meta))

    def compare(self, meta, items):
        return ast.Compare(items[0], self._span(meta))

    def within(self, meta, items):
        return ("within", ast.Within(items[0], items[1], self._span(meta)))

    def robot(self, meta, items):
        name, *body = items
        return ast.Robot(self._name(name), tuple(body), self._span(meta))

    def quantity(self, meta, items):
        unit = str(items[1]) if len(items) > 1 else None
        return ast.Quantity(_num(items[0]), unit, self._span(meta))

    def vector(self, meta, items):
        unit = None
        if items and items[-1].type == "MEASURE":
            unit = str(items[-1])
            items = items[:-1]
        return ast.Vector(tuple(_num(t) for t in items), unit, self._span(meta))

    def param(self, meta, items):
        return ast.Param(self._name(items[0]), items[1], self._span(meta))

    def params(self, meta, items):
        return tuple(p for p in items if p is not None)

    def unit(self, meta, items):
        params = items[1] if len(items) > 1 else ()
        return ast.Unit(self._name(items[0]), params, self._span(meta))

    def chain(self, meta, units):
        return ast.Chain(tuple(units), self._span(meta))

    def dh_row(self, meta, params):
        return ast.DHRow(tuple(params), self._span(meta))

    def dh(self, meta, items):
        fit, *rows = items
        return ast.DH(tuple(rows), fit is not None, self._span(meta))

    def library(self, meta, items):
        t = items[0]
        if t.type == "STRING":
            return ast.Library(str(t)[1:-1], True, self._span(meta))
        return ast.Library(str(t), False, self._span(meta))

    def at(self, meta, items):
        return ("at", items[0])

    def rpy(self, meta, items):
        return ("rpy", items[0])

    def _placement(self, keyword, meta, items):
        parts = dict(items)
        return ast.Placement(keyword, parts.get("at"), parts.get("rpy"), self._span(meta))

    def base(self, meta, items):
        return self._placement("base", meta, items)

    def tool(self, meta, items):
        return self._placement("tool", meta, items)

    def payload(self, meta, items):
        at = items[1][1] if len(items) > 1 else None
        return ast.Payload(items[0], at, self._span(meta))

    def pose(self, meta, items):
        return ast.Pose(self._name(items[0]), items[1], self._span(meta))

    def limit(self, meta, items):
        return ast.Limit(self._name(items[0]), items[1], self._span(meta))

    def box(self, meta, items):
        rest = dict(items[2:])
        return ast.Box(self._name(items[0]), items[1], rest["at"], rest.get("rpy"), self._span(meta))

    def sphere(self, meta, items):
        return ast.Sphere(self._name(items[0]), items[1], items[2][1], self._span(meta))

    def cylinder(self, meta, items):
        rest = dict(items[3:])
        return ast.Cylinder(self._name(items[0]), items[1], items[2], rest["at"], rest.get("rpy"), self._span(meta))

    def target(self, meta, items):
        rest = dict(items[2:])
        return ast.Target(self._name(items[0]), items[1][1], self._span(meta), rest.get("rpy"), rest.get("within"),
                          rest.get("pointing"))

    def pointing(self, meta, items):
        return ("pointing", items[0])

    def allow(self, meta, items):
        return ast.Allow(tuple(self._name(t) for t in items), self._span(meta))

    def point_index(self, meta, items):
        return tuple(self._count(t) for t in items)

    def point_ref(self, meta, items):
        return ast.PointRef(self._name(items[0]), items[1] if len(items) > 1 else None, self._span(meta))

    def turned(self, meta, items):
        return ("turned", items[0])

    def region(self, meta, items):
        name, size, at, *rest = items
        turned = rest.pop(0)[1] if isinstance(rest[0], tuple) and rest[0][0] == "turned" else None
        nx, ny, nz, *rest = rest
        opt = dict(rest)
        grid = (self._count(nx), self._count(ny), self._count(nz))
        return ast.Region(self._name(name), size, at[1], grid, self._span(meta), opt.get("rpy"), opt.get("within"),
                          opt.get("pointing"), turned)

    def task(self, meta, items):
        return ast.Task(self._name(items[0]), tuple(items[1:]), self._span(meta))

    def path(self, meta, items):
        return ast.StraightPath(self._name(items[0]), items[1], items[2], self._span(meta))

    def yaw(self, meta, items):
        return ("yaw", ast.Range(items[0], items[1], items[2], self._span(meta)))

    def base_within(self, meta, items):
        size, at, step, *rest = items
        return ast.BaseWithin(size, at[1], step, self._span(meta), dict(rest).get("yaw"))
