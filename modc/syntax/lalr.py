"""A small LALR(1) runtime for the parse `modc lint` does: Lark's own tables, lexer patterns and
tree-shaping rules exported once as plain data (kept in modc's cache), run here without
importing lark, which costs a cold lint more than everything else in the parse
(benchmarks/bench_startup.py).

It gives the tree Lark gives (same rule names, children, tokens and positions; the contextual
lexer, keyword "unless" retyping, `[optional]` placeholders, inlined `_rules` and
propagate_positions done as lark 1.x does them: tests/test_lalr_runtime.py compares the two on
every example and corpus file). Anything it cannot parse raises ParseError and the caller asks
Lark, whose exception the syntax diagnostics are made from: errors are always Lark's.
"""
from __future__ import annotations

import re
from typing import Any

FORMAT = 2  # of the exported data; part of its cache key


class ParseError(Exception):
    """The input is not in the language (or not in what this runtime does): ask Lark."""


class Token(str):
    """lark.Token's fields: a str with its type and position."""

    type: str
    value: str
    start_pos: int
    line: int
    column: int
    end_line: int | None
    end_column: int | None
    end_pos: int | None

    def __new__(cls, type: str, value: str, start_pos: int, line: int, column: int, end_line: int | None = None,
                end_column: int | None = None, end_pos: int | None = None) -> Token:
        t: Any = str.__new__(cls, value)
        t.type, t.value, t.start_pos, t.line, t.column = type, value, start_pos, line, column
        t.end_line, t.end_column, t.end_pos = end_line, end_column, end_pos
        return t

    def __repr__(self) -> str:
        return f"Token({self.type!r}, {self.value!r})"


class Meta:
    """lark.tree.Meta: positions, set by propagate_positions."""

    def __init__(self) -> None:
        self.empty = True


class Tree:
    """lark.Tree's data, children and meta."""

    __slots__ = ("data", "children", "_meta")

    def __init__(self, data: str, children: list, meta: Meta | None = None) -> None:
        self.data, self.children, self._meta = data, children, meta

    @property
    def meta(self) -> Meta:
        if self._meta is None:
            self._meta = Meta()
        return self._meta

    def __repr__(self) -> str:
        return f"Tree({self.data!r}, {self.children!r})"


def export(parser: Any, start: str) -> dict | None:
    """The runtime's data for a lark.Lark LALR parser (contextual lexer, no callbacks), or None
    when it uses something this runtime does not do."""
    from lark.lexer import ContextualLexer
    from lark.parse_tree_builder import ChildFilterLALR, ChildFilterLALR_NoPlaceholders, maybe_create_child_filter
    from lark.parsers.lalr_analysis import Shift

    o = parser.options
    if (o.parser != "lalr" or o.postlex is not None or o.lexer_callbacks or o.regex or o.use_bytes
            or o.propagate_positions not in (True, False) or o.ambiguity not in ("auto", "resolve")
            or parser.lexer_conf.g_regex_flags or not isinstance(parser.parser.lexer, ContextualLexer)):
        return None
    table = parser.parser.parser.parser.parse_table
    rule_index: dict[Any, int] = {}
    rules: list[tuple] = []
    states: dict[int, dict[str, tuple[int, int]]] = {}
    # names as plain str (a freshly built Lark's are its Tokens, which marshal refuses)
    for state, actions in table.states.items():
        row = states[state] = {}
        for token, (action, arg) in actions.items():
            token = str(token)
            if action is Shift:
                row[token] = (0, arg)
                continue
            if arg not in rule_index:
                rule_index[arg] = len(rules)
                keep = arg.options.keep_all_tokens
                empty: Any = arg.options.empty_indices if o.maybe_placeholders else None
                f = maybe_create_child_filter(arg.expansion, keep, False, empty)
                if f is None:
                    include, append = None, 0
                elif f.func is ChildFilterLALR:
                    include, append = [list(x) for x in f.args[0]], f.args[1]
                elif f.func is ChildFilterLALR_NoPlaceholders:
                    include, append = [[i, x, 0] for i, x in f.args[0]], 0
                else:
                    return None
                name = arg.alias or arg.options.template_source or arg.origin.name
                expand1 = bool(arg.options.expand1 and not arg.alias)
                rules.append((str(name), str(arg.origin.name), len(arg.expansion), expand1, include, append))
            row[token] = (1, rule_index[arg])
    lexing = _export_lexers(parser.parser.lexer)
    if lexing is None:
        return None
    lexers, terminals, lexer_of = lexing
    return {"format": FORMAT, "states": states, "start": table.start_states[start], "end": table.end_states[start],
            "rules": rules, "lexers": lexers, "terminals": terminals, "lexer_of": lexer_of,
            "positions": bool(o.propagate_positions)}


def _export_lexers(contextual: Any) -> tuple[list, dict, dict] | None:
    """Each distinct state lexer of Lark's contextual lexer: its union pattern, its terminals in
    Lark's order, the keywords its name-like terminals are retyped to, the terminals that may
    hold a line break and those ignored; every terminal's literal or pattern; each state's lexer."""
    from lark.lexer import PatternStr, UnlessCallback

    lexers: list = []
    terminals: dict[str, tuple[str | None, str]] = {}
    by_id: dict[int, int] = {}
    lexer_of = {}
    basic: Any
    for state, basic in contextual.lexers.items():
        if id(basic) not in by_id:
            if basic.user_callbacks:
                return None
            scanner = basic.scanner  # builds the union pattern and the keyword callbacks, as Lark lexes
            unless = {}
            for name, callback in basic.callback.items():
                if not isinstance(callback, UnlessCallback):
                    return None
                words = callback.scanner.terminals
                if any(not isinstance(t.pattern, PatternStr) or t.pattern.flags for t in words):
                    return None
                unless[str(name)] = {str(t.pattern.value): str(t.name) for t in words}
            for t in scanner.terminals:
                literal = isinstance(t.pattern, PatternStr) and not t.pattern.flags
                terminals[str(t.name)] = (str(t.pattern.value) if literal else None, str(t.pattern.to_regexp()))
            by_id[id(basic)] = len(lexers)
            lexers.append(([str(m.pattern) for m in scanner._mres], [str(t.name) for t in scanner.terminals], unless,
                           sorted(map(str, basic.newline_types)), sorted(map(str, basic.ignore_types))))
        lexer_of[state] = by_id[id(basic)]
    return lexers, terminals, lexer_of


# A state's lexer tries its terminals one by one, in Lark's order, first match winning (what the
# union pattern `(?P<A>…)|(?P<B>…)` Lark compiles for the state does), until it has lexed this
# many tokens; then it compiles that union, ~10% faster per token. A lint of one file thus
# compiles a few small patterns, not a union for each of the ~25 states it visits (farm.mod's
# first parse: 2.8 ms instead of 8.6).
UNION_AFTER = 64


class _Lexer:
    __slots__ = ("patterns", "order", "mres", "unless", "newline", "ignore", "uses")

    def __init__(self, patterns: list[str], order: list[str], unless: dict, newline: list[str],
                 ignore: list[str]) -> None:
        self.patterns, self.order = patterns, order
        self.mres: list[re.Pattern] | None = None
        self.unless, self.newline, self.ignore = unless, frozenset(newline), frozenset(ignore)
        self.uses = 0


class Parser:
    """Parses text with exported data (export()); a state's lexer pattern is compiled when first used."""

    def __init__(self, data: dict) -> None:
        if data.get("format") != FORMAT:
            raise ValueError("exported by another version of this runtime")
        self.states, self.start, self.end = data["states"], data["start"], data["end"]
        self.rules, self.positions = data["rules"], data["positions"]
        self._specs, self._lexer_of = data["lexers"], data["lexer_of"]
        self._lexers: dict[int, _Lexer] = {}
        self._literals = {name: literal for name, (literal, _) in data["terminals"].items() if literal is not None}
        self._regexps = {name: regexp for name, (literal, regexp) in data["terminals"].items() if literal is None}
        self._compiled: dict[str, re.Pattern] = {}
        self.union_after = UNION_AFTER

    def _match(self, lexer: _Lexer, text: str, pos: int) -> tuple[str, str] | None:
        """The first of the state's terminals that matches at pos: (text, terminal)."""
        lexer.uses += 1
        if lexer.mres is None and lexer.uses > self.union_after:
            lexer.mres = [re.compile(p) for p in lexer.patterns]
        if lexer.mres is not None:
            for mre in lexer.mres:
                m = mre.match(text, pos)
                if m:
                    return m.group(0), m.lastgroup or ""
            return None
        literals, compiled = self._literals, self._compiled
        for name in lexer.order:
            literal = literals.get(name)
            if literal is not None:
                if text.startswith(literal, pos):
                    return literal, name
                continue
            pattern = compiled.get(name)
            if pattern is None:
                pattern = compiled[name] = re.compile(self._regexps[name])
            m = pattern.match(text, pos)
            if m:
                return m.group(0), name
        return None

    def _lexer(self, state: int) -> _Lexer:
        i = self._lexer_of[state]
        lexer = self._lexers.get(i)
        if lexer is None:
            lexer = self._lexers[i] = _Lexer(*self._specs[i])
        return lexer

    def parse(self, text: str) -> Tree:
        state_stack: list[int] = [self.start]
        value_stack: list[Any] = []
        pos, line, line_start, end = 0, 1, 0, len(text)
        last = None
        while True:
            token = None
            lexer = self._lexer(state_stack[-1])
            while pos < end:
                found = self._match(lexer, text, pos)
                if found is None:
                    raise ParseError(pos)
                value, kind = found
                start_pos, start_line, column = pos, line, pos - line_start + 1
                if kind in lexer.newline:
                    n = value.count("\n")
                    if n:
                        line += n
                        line_start = pos + value.rindex("\n") + 1
                pos += len(value)
                if kind in lexer.ignore:
                    continue
                words = lexer.unless.get(kind)
                if words is not None:
                    kind = words.get(value, kind)
                token = Token(kind, value, start_pos, start_line, column, line, pos - line_start + 1, pos)
                break
            if token is None:  # the end: reduce until the start rule is complete
                if last is None:
                    end_token = Token("$END", "", 0, 1, 1)
                else:
                    end_token = Token("$END", "", last.start_pos, last.line, last.column, last.end_line,
                                      last.end_column, last.end_pos)
                return self._feed(end_token, state_stack, value_stack, True)
            self._feed(token, state_stack, value_stack, False)
            last = token

    def _feed(self, token: Token, state_stack: list, value_stack: list, is_end: bool) -> Any:
        states = self.states
        while True:
            action = states[state_stack[-1]].get(token.type)
            if action is None:
                raise ParseError(token.start_pos)
            if action[0] == 0:
                if is_end:
                    raise ParseError(token.start_pos)
                state_stack.append(action[1])
                value_stack.append(token)
                return None
            name, origin, size, expand1, include, append = self.rules[action[1]]
            if size:
                children = value_stack[-size:]
                del state_stack[-size:]
                del value_stack[-size:]
            else:
                children = []
            value = self._build(name, expand1, include, append, children)
            goto = states[state_stack[-1]][origin]
            state_stack.append(goto[1])
            value_stack.append(value)
            if is_end and goto[1] == self.end:
                return value

    def _build(self, name: str, expand1: bool, include: list | None, append: int, children: list) -> Any:
        # lark.parse_tree_builder's chain for LALR: child filter (with placeholders), single-child
        # expansion, then positions from the unfiltered children
        if include is None:
            filtered = children
        else:
            filtered = []
            for i, expand, nones in include:
                if nones:
                    filtered += [None] * nones
                if expand:
                    if filtered:
                        filtered += children[i].children
                    else:  # lark's shortcut for left recursion: the inlined child's own list
                        filtered = children[i].children
                else:
                    filtered.append(children[i])
            if append:
                filtered += [None] * append
        res = filtered[0] if expand1 and len(filtered) == 1 else Tree(name, filtered)
        if self.positions and isinstance(res, Tree):
            _propagate(res.meta, children)
        return res


def _first_meta(children) -> Any:
    for c in children:
        if isinstance(c, Tree):
            if not c.meta.empty:
                return c.meta
        elif isinstance(c, Token):
            return c
    return None


def _propagate(meta: Any, children: list) -> None:
    """lark.parse_tree_builder.PropagatePositions: a node spans from its first child's container
    to its last's (containers: nodes inlined into it, which take up text)."""
    first = _first_meta(children)
    if first is not None:
        _take(meta, first, ("line", "column", "start_pos"))
    last = _first_meta(reversed(children))
    if last is not None:
        _take(meta, last, ("end_line", "end_column", "end_pos"))


def _take(meta: Any, child: Any, keys: tuple[str, str, str]) -> None:
    """One end of the node's span (and of its container's) from a child's."""
    values = [getattr(child, "container_" + k, getattr(child, k)) for k in keys]
    if not hasattr(meta, keys[0]):
        for k, v in zip(keys, values, strict=True):
            setattr(meta, k, v)
        meta.empty = False
    for k, v in zip(keys, values, strict=True):
        setattr(meta, "container_" + k, v)
