"""Parse .mod text into AST nodes, turning every Lark error into a Diagnostic."""
from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from functools import cache

from ..diagnostics import Diagnostic, Span, codes
from ..resources import data_dir
from . import ast
from .errors import EXAMPLES, HINTS, TERMINAL_NAMES

MAX_BYTES = 256_000  # a real .mod file is a few kB; beyond this, checking would take seconds


def normalize_newlines(text: str) -> str:
    """A lone CR (old Mac line ends) as LF: one character for one, so offsets do not move and a
    comment ends at the end of its line. CRLF is left alone (the grammar treats CR as space)."""
    import re

    return re.sub(r"\r(?!\n)", "\n", text) if "\r" in text else text


def too_large(text: str, file: str) -> Diagnostic | None:
    """input-too-large when text is more than MAX_BYTES bytes of UTF-8 (not characters: 200k 'é' is 400 kB)."""
    size = len(text) if len(text) > MAX_BYTES else len(text.encode("utf-8", "surrogatepass"))
    if size <= MAX_BYTES:
        return None
    shown = f"{size:,} bytes" if len(text) <= MAX_BYTES else f"{len(text):,} characters"
    return codes.INPUT_TOO_LARGE.at(Span.point(file), what="the file", size=shown, limit=f"{MAX_BYTES:,} bytes")


_OPTIONS = {"parser": "lalr", "propagate_positions": True, "maybe_placeholders": True,
            "start": ["start", "unit_text", "quantity_text", "vector_text"]}


@cache
def _lark():
    text = (data_dir("grammar") / "modc.lark").read_text(encoding="utf-8")
    return cached_lark(text, _OPTIONS)


@cache
def _runtime():
    """The lint parse without importing lark (modc.syntax.lalr): its data exported from Lark's
    parser once and kept in modc's cache (so only the first lint on a machine imports lark);
    None when the cache is off (Lark parses then)."""
    from .. import cache as store
    from . import lalr

    text = (data_dir("grammar") / "modc.lark").read_text(encoding="utf-8")
    name = _runtime_name(text)
    if name is None or store.directory(_TABLES) is None:
        return None
    payload = store.get_checked(_TABLES, name)
    if payload is not None:
        import marshal

        try:
            return lalr.Parser(marshal.loads(payload))
        except Exception:  # an entry of another format, or not ours: export it again
            pass
    return _export_runtime(name)


def _export_runtime(name: str):
    import marshal

    from .. import cache as store
    from . import lalr

    data = lalr.export(_lark(), "start")
    if data is None:
        return None
    try:
        store.put_checked(_TABLES, name, marshal.dumps(data))
    except ValueError:
        return None
    return lalr.Parser(data)


def lark_version() -> str | None:
    """The installed lark's version, read from its package without importing it (~35 ms)."""
    import importlib.util
    import re

    spec = importlib.util.find_spec("lark")
    if spec is None or spec.origin is None:
        return None
    try:
        with open(spec.origin, encoding="utf-8") as f:
            m = re.search(r"""^__version__\s*(?::\s*str\s*)?=\s*["']([^"']+)["']""", f.read(), re.M)
    except (OSError, UnicodeDecodeError):
        return None
    return m.group(1) if m else None


def _runtime_name(text: str) -> str | None:
    """The runtime data's cache entry: keyed by the grammar, the options, the runtime's format,
    Python's version and the installed lark's version (read without importing lark)."""
    import sys

    from ..cache import key
    from .lalr import FORMAT

    version = lark_version()
    if version is None:
        return None
    return key(text, repr(sorted(_OPTIONS.items())), version, repr(sys.version_info[:2]), str(FORMAT)) + ".lalr-rt"


def cached_lark(text: str, options: dict):
    """Lark's LALR parser of the grammar text with these options, its tables from modc's cache
    when they are there (else built and stored)."""
    import lark

    name = _tables_name(text, options, lark.__version__)
    parser = _load_tables(name, options)
    if parser is None:
        parser = lark.Lark(text, **options)
        _save_tables(name, parser)
    return parser


def _tables_name(text: str, options: dict, lark_version: str) -> str:
    """The cache entry of the grammar's LALR tables: keyed by the grammar, the options, lark's
    version and Python's (marshal's format is Python's)."""
    import sys

    from ..cache import key

    return key(text, repr(sorted(options.items())), lark_version, repr(sys.version_info[:2])) + ".lalr"


# Building the LALR tables is most of a cold `modc lint` (benchmarks/bench_startup.py). They are
# kept in modc's cache as marshal data (lists, dicts, strings: never pickle, which runs code), each
# entry led by a digest of its payload: a torn or altered entry is rebuilt, never used.
_TABLES = "grammar"


def _load_tables(name: str, options: dict):
    import marshal

    from .. import cache

    payload = cache.get_checked(_TABLES, name)
    if payload is None:
        return None
    from lark import Lark

    try:
        data, memo = marshal.loads(payload)
        return Lark._load_from_dict(data, memo, propagate_positions=options.get("propagate_positions", False))
    except Exception:  # an entry of another lark, or not ours: build the tables instead
        return None


def _plain(v) -> bool:
    if isinstance(v, list | tuple):
        return all(_plain(x) for x in v)
    if isinstance(v, dict):
        return all(_plain(x) for x in v.values())
    return v is None or isinstance(v, str | int | float)


def _save_tables(name: str, parser) -> None:
    import marshal

    from lark.grammar import Rule
    from lark.lexer import TerminalDef

    from .. import cache

    if cache.directory(_TABLES) is None:
        return
    data, memo = parser.memo_serialize([TerminalDef, Rule])
    # options that are not data (callbacks, classes) take their defaults at load, as in lark's own cache
    data["options"] = {k: v for k, v in data["options"].items() if _plain(v)}
    try:
        payload = marshal.dumps((data, memo))
    except ValueError:  # a lark whose tables hold more than plain data: no cache
        return
    cache.put_checked(_TABLES, name, payload)


def grammar_keywords() -> set[str]:
    """The keywords of the grammar (used by editors' grammars and their tests)."""
    import re

    return {
        t.pattern.value
        for t in _lark().terminals
        if t.pattern.type == "str" and re.fullmatch(r"[a-z]+(?:-[a-z]+)*", t.pattern.value)
    }


@contextmanager
def collector_paused() -> Iterator[None]:
    """The cycle collector off while parsing or formatting: its passes over the parse tree's many
    live objects made the time per unit grow with the file (fmt of 8,000 units: 1.7x the per-unit
    time of 1,000; benchmarks/bench_fmt.py). Parsing makes no cycles worth collecting."""
    import gc

    was = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was:
            gc.enable()


def parse(text: str, file: str = "<string>") -> tuple[ast.File, list[Diagnostic]]:
    """Parse one file. On a syntax error returns no robots and one diagnostic."""
    big = too_large(text, file)
    if big is not None:
        return ast.File(file, ()), [big]
    from .transform import ToAst

    with collector_paused():
        tree = None
        runtime = _runtime()
        if runtime is not None:
            try:
                tree = runtime.parse(text)
            except Exception:  # a syntax error (lalr.ParseError), whose diagnostic Lark's exception makes,
                tree = None  # or data that passed its digest yet is not the runtime's: Lark decides
        if tree is None:
            from lark.exceptions import UnexpectedInput

            try:
                tree = _lark().parse(text, start="start")
            except UnexpectedInput as e:
                return ast.File(file, ()), [_diagnose(e, text, file)]
        blocks = ToAst(file).transform(tree)
    robots = tuple(b for b in blocks if isinstance(b, ast.Robot))
    designs = tuple(b for b in blocks if isinstance(b, ast.DesignBlock))
    diags = []
    if not blocks:
        diags.append(codes.EMPTY_FILE.at(Span.point(file)))
    return ast.File(file, robots, designs), diags


def _describe(name: str) -> str:
    if name in TERMINAL_NAMES:
        return TERMINAL_NAMES[name]
    try:
        pattern = _lark().get_terminal(name).pattern
    except KeyError:
        return name
    return f"'{pattern.value}'" if pattern.type == "str" else name.lower()


def _expected(names) -> str:
    items = sorted({_describe(n) for n in names})
    if len(items) > 6:
        items = items[:6] + ["…"]
    return ", ".join(items) if items else "nothing more"


def _label(e, text: str) -> str | None:
    try:
        return e.match_examples(lambda t: _lark().parse(t, start="start"), EXAMPLES, use_accepts=True,
                                token_type_match_fallback=True)
    except Exception:  # a label is a nicety; the generic message is still right
        return None


def _diagnose(e, text: str, file: str) -> Diagnostic:
    from lark.exceptions import UnexpectedCharacters, UnexpectedEOF, UnexpectedToken

    line, col = max(1, e.line if e.line != -1 else 1), max(1, e.column if e.column != -1 else 1)
    if isinstance(e, UnexpectedCharacters):
        pos = e.pos_in_stream or 0
        span = Span(file, line, col, line, col + 1, pos, pos + 1)
        label = _label(e, text)
        if label == "missing-equals":
            return codes.MISSING_EQUALS.at(span, found=repr(text[pos]))
        return codes.UNEXPECTED_CHARACTER.at(span, char=text[pos])

    token = getattr(e, "token", None)
    if isinstance(e, UnexpectedEOF) or (token is not None and token.type == "$END"):
        name = _open_robot(text)
        span = _eof_span(text, file)
        if name is not None:
            return codes.UNCLOSED_BLOCK.at(span, name=name)
        return codes.SYNTAX_ERROR.at(
            span, found="end of file", expected=_expected(getattr(e, "expected", ())), hint="the file ends too early"
        )

    assert isinstance(e, UnexpectedToken) and token is not None
    return _unexpected_token(e, token, text, file, line, col)


def _unexpected_token(e, token, text: str, file: str, line: int, col: int) -> Diagnostic:
    """A token the grammar does not allow here: the commonest mistakes by name, else a syntax
    error listing what was expected."""
    found = f"'{token}'"
    span = Span(
        file, line, col, token.end_line or line, token.end_column or col + 1, token.start_pos or 0, token.end_pos or 0
    )
    label = _rule_label(e) or _label(e, text)
    if label == "missing-dash":
        return codes.MISSING_DASH.at(span, found=found)
    if label == "missing-equals":
        return codes.MISSING_EQUALS.at(span, found=found)
    if label == "expected-statement":
        from .keywords import block_statement_terminals

        allowed = [w for t, w in block_statement_terminals().items() if t in set(e.accepts or e.expected)]
        return codes.EXPECTED_STATEMENT.at(span, found=found, statements=", ".join(allowed))
    if label == "expected-robot":
        return codes.EXPECTED_ROBOT.at(span, found=found)
    expected = e.accepts or e.expected
    hint = next((HINTS[n] for n in sorted(expected) if n in HINTS), "see the .mod language guide, docs/language.md")
    return codes.SYNTAX_ERROR.at(span, found=found, expected=_expected(expected), hint=hint)


WORDS = {"NAME", "CODE_NAME", "UNIT_NAME", "MEASURE", "LIBRARY_REF"}


def _rule_label(e) -> str | None:
    """The two commonest mistakes, decided from what the parser expected (examples cover the rest)."""
    import re

    accepts = set(e.accepts or e.expected)
    # token types are the lexer's fallback guess here, so look at the text itself
    if "MINUS" in accepts and re.fullmatch(r"[A-Za-z]+[0-9]+", str(e.token)):
        return "missing-dash"
    from .keywords import block_statement_terminals

    if e.token.type in WORDS and accepts & set(block_statement_terminals()):
        return "expected-statement"
    return None


def _open_robot(text: str) -> str | None:
    """Name of the robot block left open at end of file, if any (comments ignored)."""
    import re

    depth, name = 0, None
    for m in re.finditer(r"#[^\n]*|\"[^\"\n]*\"|\b(?:robot|design)\s+([A-Za-z_]\w*)|[{}]", text):
        s = m.group(0)
        if s.startswith(("#", '"')):
            continue
        if m.group(1):
            name = m.group(1)
        elif s == "{":
            depth += 1
        elif s == "}":
            depth = max(0, depth - 1)
    return name if depth > 0 else None


def _eof_span(text: str, file: str) -> Span:
    lines = text.split("\n")
    line = len(lines)
    col = len(lines[-1]) + 1
    return Span(file, line, col, line, col + 1, len(text), len(text) + 1)
