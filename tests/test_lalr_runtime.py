"""The lint parse's own LALR runtime (modc.syntax.lalr) gives Lark's tree, token for token and
position for position, on every .mod file of the examples and the tests; and what it cannot
parse it leaves to Lark, whose errors the diagnostics are made from."""
from __future__ import annotations

import marshal

import pytest
from conftest import ROOT

from modc.syntax import lalr, parser

FILES = sorted([*(ROOT / "examples").glob("*.mod"), *(ROOT / "tests").rglob("*.mod")])
POSITIONS = ("line", "column", "end_line", "end_column", "start_pos", "end_pos")


@pytest.fixture(scope="module", params=[("built", 0), ("loaded", 0), ("loaded", lalr.UNION_AFTER), ("loaded", 10**9)])
def runtime(request):
    """Exported from a freshly built Lark and from one loaded from cached tables, each stored
    and read back as the cache does (marshal); lexing with each state's union pattern from the
    first token, after UNION_AFTER tokens, or never (terminal by terminal)."""
    import lark

    from modc.resources import data_dir

    source_kind, union_after = request.param
    if source_kind == "built":
        source = lark.Lark((data_dir("grammar") / "modc.lark").read_text(encoding="utf-8"), **parser._OPTIONS)
    else:
        source = parser._lark()
    data = lalr.export(source, "start")
    assert data is not None
    runtime = lalr.Parser(marshal.loads(marshal.dumps(data)))
    runtime.union_after = union_after
    return runtime


def _same(ours, theirs, where: str) -> None:
    if theirs is None or isinstance(theirs, str):
        assert type(ours) is not lalr.Tree, where
        assert ours == theirs, where
        if theirs is not None:
            assert (ours.type, *(getattr(ours, p) for p in POSITIONS)) == (
                theirs.type, *(getattr(theirs, p) for p in POSITIONS)), where
        return
    assert isinstance(ours, lalr.Tree) and ours.data == theirs.data, where
    assert ours.meta.empty == theirs.meta.empty, where
    if not theirs.meta.empty:
        assert [getattr(ours.meta, p) for p in POSITIONS] == [getattr(theirs.meta, p) for p in POSITIONS], where
    assert len(ours.children) == len(theirs.children), where
    for i, (a, b) in enumerate(zip(ours.children, theirs.children, strict=True)):
        _same(a, b, f"{where}/{theirs.data}[{i}]")


def _texts():
    for path in FILES:
        text = parser.normalize_newlines(path.read_text(encoding="utf-8", errors="replace"))
        yield path.relative_to(ROOT).as_posix(), text
    # hand-made corners: empty input, comments only, CRLF, a keyword used as a name's prefix
    yield "empty", ""
    yield "comments", "# nothing\n# here\n"
    yield "crlf", "robot a {\r\n  chain H1 - L4(link=180mm)\r\n  pose home (0) deg\r\n}\r\n"
    yield "keyword-prefix", "robot robots { chain H1 pose poses (1) deg limit limits (0, 1) deg }"


def test_the_runtime_gives_larks_tree_or_leaves_the_file_to_lark(runtime):
    from lark.exceptions import UnexpectedInput

    lark = parser._lark()
    parsed = failed = 0
    for name, text in _texts():
        try:
            theirs = lark.parse(text, start="start")
        except UnexpectedInput:
            with pytest.raises(lalr.ParseError):
                runtime.parse(text)
            failed += 1
            continue
        _same(runtime.parse(text), theirs, name)
        parsed += 1
    assert parsed >= 20 and failed >= 1  # both kinds of file were really seen


def test_a_syntax_error_gets_larks_diagnostic_through_the_runtime(tmp_path, monkeypatch):
    monkeypatch.setenv("MODC_CACHE_DIR", str(tmp_path))
    monkeypatch.delenv("MODC_NO_CACHE", raising=False)
    parser._runtime.cache_clear()
    try:
        assert parser._runtime() is not None  # exported and stored
        assert list((tmp_path / "grammar").glob("*.lalr-rt"))
        parser._runtime.cache_clear()
        assert parser._runtime() is not None  # loaded back
        _, diags = parser.parse("robot a {\n  chain H1 - \n}\n", "bad.mod")
        assert [d.code for d in diags] and diags[0].span.line == 3
        tree, diags = parser.parse("robot a {\n  chain H1 - L4\n}\n", "good.mod")
        assert not diags and tree.robots[0].name.text == "a"
    finally:
        parser._runtime.cache_clear()



@pytest.mark.parametrize("union_after", [0, 10**9])
def test_overlapping_terminals_are_lexed_in_larks_order(union_after):
    """Where a state accepts terminals that overlap, the first in Lark's order wins (priority,
    then length), and a keyword spelled like a name is retyped: as Lark's union pattern does."""
    import lark

    grammar = """
        start: item+
        item: KW | WORD | NUM | "let" WORD | PAIR
        KW.2: /if|else/
        WORD: /[a-z]+/
        NUM: /[0-9]+/
        PAIR: /[a-z]+=[0-9]+/
        %ignore " "
    """
    source = lark.Lark(grammar, parser="lalr", propagate_positions=True, maybe_placeholders=True)
    data = lalr.export(source, "start")
    assert data is not None
    runtime = lalr.Parser(marshal.loads(marshal.dumps(data)))
    runtime.union_after = union_after
    for text in ("iffy else let x lettuce 42 a=1 if", "let let", "elsewhere x=3y"):
        _same(runtime.parse(text), source.parse(text), text)
    assert [t.type for t in runtime.parse("iffy").children[0].children] == ["KW"]  # 'if' then 'fy'


@pytest.mark.parametrize("damage", ["torn", "foreign", "garbage"])
def test_a_damaged_runtime_entry_is_never_trusted(tmp_path, monkeypatch, damage):
    import hashlib

    monkeypatch.setenv("MODC_CACHE_DIR", str(tmp_path))
    monkeypatch.delenv("MODC_NO_CACHE", raising=False)
    parser._runtime.cache_clear()
    try:
        parser._runtime()
        (entry,) = (tmp_path / "grammar").glob("*.lalr-rt")
        blob = entry.read_bytes()
        if damage == "torn":
            blob = blob[: len(blob) // 2]
        else:  # a valid digest over data that is not (or not wholly) the runtime's
            data = {"format": lalr.FORMAT} if damage == "foreign" else {
                **marshal.loads(blob.partition(b"\n")[2]), "states": {}, "lexers": [], "lexer_of": {}}
            payload = marshal.dumps(data)
            blob = hashlib.sha256(payload).hexdigest().encode() + b"\n" + payload
        entry.write_bytes(blob)
        parser._runtime.cache_clear()
        farm = (ROOT / "examples" / "farm.mod").read_text(encoding="utf-8")
        tree, diags = parser.parse(farm, "farm.mod")
        assert not diags and tree.robots[0].name.text == "farm"
        _, diags = parser.parse("robot a {\n  chain H1 - \n}\n", "bad.mod")
        assert diags and diags[0].span.line == 3
    finally:
        parser._runtime.cache_clear()

