"""The language server (`python -m modc.lsp`, i.e. `modc lsp`), driven as a real process over
stdio by modc.lsp.client (JSON-RPC with Content-Length framing over pipes), plus in-process
tests of the position conversions and the completion heuristics."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import pytest

from modc.compiler import check_text
from modc.diagnostics import REGISTRY
from modc.lsp import convert
from modc.lsp.client import Client
from modc.lsp.completion import complete
from modc.lsp.document import Analysis
from modc.lsp.formatting import formatting
from modc.lsp.hover import hover
from modc.lsp.language import keyword_doc, statements
from modc.lsp.symbols import definition, symbols
from modc.syntax.parser import normalize_newlines

ROOT = Path(__file__).resolve().parent.parent
CORPUS = ROOT / "tests" / "diagnostics"

FARM = """\
robot farm {
    chain H1 - L4(pivot=-90deg, port=45deg) - L3(link=180mm)
    library mark2
    tool at (0.06, 0, 0) m
    pose ready (90, -45, -90) deg
    limit joint_2 (-90, 90) deg
    box floor size (0.30, 0.50, 0.02) m at (0.37, 0, 0.11) m
    target plant at (0.35, 0, 0.20) m
}
robot wrist {
    chain L1 - L4 - L1
    allow first-variant
    pose ready (0, 0, 0) deg
}
"""


def pos(text: str, needle: str, nth: int = 0, delta: int = 0) -> tuple[int, int]:
    """(line, character) of the nth occurrence of needle (+ delta characters), ASCII text."""
    i = -1
    for _ in range(nth + 1):
        i = text.index(needle, i + 1)
    i += delta
    line = text.count("\n", 0, i)
    return line, i - (text.rfind("\n", 0, i) + 1)


def labels(items) -> list[str]:
    if isinstance(items, dict):
        items = items["items"]
    return [i["label"] for i in items or []]


def start_server() -> Client:
    c = Client([sys.executable, "-m", "modc.lsp"], cwd=str(ROOT))
    c.initialize()
    return c


@pytest.fixture(scope="module")
def server():
    c = start_server()
    yield c
    code = c.shutdown()
    errors = [
        m
        for _, m in c.notifications
        if m.get("method") in ("window/logMessage", "window/showMessage")
        and m["params"]["type"] == 1
        and "modc:" in m["params"]["message"]
        and not m["params"]["message"].startswith("modc: checking")
    ]  # compiler bugs: see the corpus test
    assert code == 0
    assert not errors, errors  # no handler of ours failed during the whole module


_n = 0


LAST_DIAGS: dict[int, list[dict]] = {}  # the first diagnostics open_doc saw, by client


def open_doc(server: Client, text: str, name: str = "t.mod", directory: Path | None = None) -> str:
    """Open text under a fresh URI and wait for its first diagnostics; returns the URI."""
    global _n
    _n += 1
    uri = convert.path_to_uri(str((directory or Path("/tmp/modc-lsp-test")) / f"{_n}" / name))
    server.open(uri, text)
    LAST_DIAGS[id(server)] = server.diagnostics(uri, version=1)
    return uri


# --- lifecycle and capabilities ----------------------------------------------------------------------


def test_initialize_advertises_features():
    with Client([sys.executable, "-m", "modc.lsp"], cwd=str(ROOT)) as c:
        caps = c.initialize()["capabilities"]
        assert caps["hoverProvider"] and caps["definitionProvider"] and caps["documentSymbolProvider"]
        assert caps["documentFormattingProvider"]
        assert "(" in caps["completionProvider"]["triggerCharacters"]
        assert caps["textDocumentSync"]["openClose"] and caps["textDocumentSync"]["change"] == 2  # incremental
        assert c.shutdown() == 0


def test_exit_without_shutdown_and_closed_stdin_end_the_process():
    c = Client([sys.executable, "-m", "modc.lsp"], cwd=str(ROOT))
    c.initialize()
    c.notify("exit")
    assert c.proc.wait(10) == 1  # the LSP spec: exit without shutdown -> 1
    c.close()
    c = Client([sys.executable, "-m", "modc.lsp"], cwd=str(ROOT))
    c.initialize()
    c.stdin.close()
    c.proc.wait(10)
    c.close()


# --- diagnostics ------------------------------------------------------------------------------------


def test_diagnostics_on_open_and_cleared_by_a_fix(server):
    text = "robot a {\n    chain H1 - L4(port=40deg) - L1\n}\n"
    uri = open_doc(server, text)
    [d] = LAST_DIAGS[id(server)]
    assert d["code"] == "twist-not-realisable" and d["source"] == "modc" and d["severity"] == 1
    line, col = pos(text, "port=40deg")
    assert d["range"] == {
        "start": {"line": line, "character": col},
        "end": {"line": line, "character": col + len("port=40deg")},
    }
    assert (
        d["message"].startswith("L4 port 40deg cannot be set")
        and "\nhint: nearest realisable value: 45deg" in d["message"]
    )
    assert d["data"]["hint"] == "nearest realisable value: 45deg"
    # an incremental edit: 40 -> 45
    line, col = pos(text, "40deg")
    server.change(
        uri, 2, rng={"start": {"line": line, "character": col}, "end": {"line": line, "character": col + 2}}, new="45"
    )
    assert server.diagnostics(uri, version=2) == []
    # and breaking it again with a full-text change
    server.change(uri, 3, text="robot a {\n    chain H1 L4\n}\n")
    [d] = server.diagnostics(uri, version=3)
    assert d["code"] == "missing-dash" and d["range"]["start"] == {"line": 1, "character": 13}


def test_close_clears_diagnostics(server):
    uri = open_doc(server, "robot a { chain L1 }")
    assert [d["code"] for d in LAST_DIAGS[id(server)]] == ["first-variant"]
    server.notify("textDocument/didClose", {"textDocument": {"uri": uri}})
    assert server.diagnostics(uri) == []


def _corpus():
    return sorted(p for p in CORPUS.glob("*") if p.suffix in (".mod", ".yaml")) if CORPUS.is_dir() else []


def test_diagnostics_are_the_cli_diagnostics(server):
    """Every file of the diagnostics corpus: the server publishes exactly check_text's
    diagnostics (lint level), code, severity, message, hint and span."""
    files = _corpus()
    if not files:
        pytest.skip("no diagnostics corpus")
    seen = set()
    for path in files:
        try:
            text = path.read_bytes().decode("utf-8")
        except UnicodeDecodeError:
            continue  # bad-encoding: an editor never sends undecodable text
        uri = path.as_uri()
        server.open(uri, text)
        got = server.diagnostics(uri, version=1)
        server.notify("textDocument/didClose", {"textDocument": {"uri": uri}})
        server.diagnostics(uri)
        try:
            want = check_text(text, str(path)).diagnostics
        except Exception as e:  # a compiler bug: the editor says so instead of going quiet
            assert len(got) == 1 and "internal error" in got[0]["message"] and type(e).__name__ in got[0]["message"], (
                path.name
            )
            continue
        assert [d["code"] for d in got] == [d.code for d in want], path.name
        for g, w in zip(got, want, strict=True):
            sev = {"error": 1, "warning": 2, "note": 3}[w.severity.value]
            assert g["severity"] == sev and g["message"].split("\nhint: ")[0].endswith(w.message), path.name
            assert g["data"]["hint"] == w.hint
            if w.span.file == str(path) and text.isascii():
                lines = normalize_newlines(text).split("\n")  # a lone CR ends a line too
                line = w.span.line - 1
                assert g["range"]["start"] == {
                    "line": line,
                    "character": min(w.span.col - 1, len(lines[line]) if line < len(lines) else 0),
                }, path.name
            seen.add(w.code)
    assert len(seen) > 30  # the corpus covers most codes


def test_yaml_documents_get_diagnostics(server):
    good = (ROOT / "examples" / "quickstart.yaml").read_text()
    open_doc(server, good, "q.yaml")
    assert LAST_DIAGS[id(server)] == []
    bad = "robots:\n  - name: a\n    chain: [L1, {unit: L4, port: 40deg}]\n"
    open_doc(server, bad, "b.yml")
    assert {d["code"] for d in LAST_DIAGS[id(server)]} == {"first-variant", "twist-not-realisable"}


def test_no_torque_analysis_in_the_editor(server):
    # an arm that cannot hold itself: compile reports torque-over-peak, the editor (lint level) does not
    text = "robot weak {\n    chain H1 - L4(link=500mm) - L4(link=500mm) - L4(link=500mm)\n    payload 3 kg\n}\n"
    open_doc(server, text)
    assert "torque-over-peak" not in {d["code"] for d in LAST_DIAGS[id(server)]}


# --- hover ------------------------------------------------------------------------------------------


def hover_text(server, uri, text, needle, nth=0, delta=1):
    h = server.at("textDocument/hover", uri, *pos(text, needle, nth, delta))
    return None if h is None else h["contents"]["value"]


def test_hover_on_units_parameters_keywords_and_names(server):
    uri = open_doc(server, FARM)
    h4 = hover_text(server, uri, FARM, "H1")
    assert "KA-75+" in h4 and "30.5" in h4 and "Ip1" in h4 and "ε = 3" in h4
    l4 = hover_text(server, uri, FARM, "L4")
    assert "KA-58" in l4 and "6.8" in l4 and "Ip2" in l4 and "x23 = 0.22" in l4 and "port 45°" in l4
    assert "about y" in hover_text(server, uri, FARM, "pivot")
    assert "about x" in hover_text(server, uri, FARM, "port=")
    assert "tool0" in hover_text(server, uri, FARM, "tool")
    assert "obstacle" in hover_text(server, uri, FARM, "box")
    assert "pose ready (90, -45, -90) deg" in hover_text(server, uri, FARM, "ready")
    assert "unit 2 (L4)" in hover_text(server, uri, FARM, "joint_2")
    assert "first-variant" in hover_text(server, uri, FARM, "first-variant")
    assert "millimetres" in hover_text(server, uri, FARM, "mm")
    assert "H1-L4-L3" in hover_text(server, uri, FARM, "farm")
    assert hover_text(server, uri, FARM, "    chain", delta=1) is None  # whitespace
    assert hover_text(server, uri, FARM, "(0.06", delta=2) is None  # a number


def test_hover_on_h4_anywhere(server):
    text = "robot a { chain H1 - H4 - L4 }"
    uri = open_doc(server, text)
    h = hover_text(server, uri, text, "H4", delta=2)  # cursor right after the word
    assert "KA-75+" in h and "30.5" in h and "type 4" in h and "link module **yes**" in h
    # also in a half-typed file, from the raw text
    text = "robot a { chain H1 - H4("
    uri = open_doc(server, text)
    assert "KA-75+" in hover_text(server, uri, text, "H4")


def test_every_keyword_has_a_hover():
    from modc.syntax import grammar_keywords

    assert all(keyword_doc(k) for k in grammar_keywords())
    assert set(statements()) <= grammar_keywords()


# --- completion -------------------------------------------------------------------------------------


def complete_at_end(server, text, name="t.mod"):
    uri = open_doc(server, text, name)
    lines = text.split("\n")
    return server.at("textDocument/completion", uri, len(lines) - 1, len(lines[-1]))


def test_completion_of_units(server):
    items = complete_at_end(server, "robot a {\n    chain H1 - ")
    assert set(labels(items)) == {"H1", "H2", "H3", "H4", "L1", "L2", "L3", "L4"}
    l4 = next(i for i in items if i["label"] == "L4")
    assert "KA-58" in l4["detail"] and l4["textEdit"]["newText"] == "L4"
    # after an L unit the rules allow only L: those sort first
    items = complete_at_end(server, "robot a {\n    chain H1 - L4 - ")
    ranked = [i["label"] for i in sorted(items, key=lambda i: i["sortText"])]
    assert ranked[:4] == ["L1", "L2", "L3", "L4"]


def test_completion_of_allowable_codes(server):
    want = {c.name for c in REGISTRY.values() if c.allowable}
    assert set(labels(complete_at_end(server, "robot a {\n    chain L1\n    allow "))) == want
    assert "first-variant" in want
    got = labels(complete_at_end(server, "robot a {\n    chain L1\n    allow first-variant, "))
    assert set(got) == want - {"first-variant"}
    # a half-typed code is replaced whole (codes contain '-')
    text = "robot a {\n    chain L1\n    allow first-v"
    items = complete_at_end(server, text)
    edit = next(i for i in items if i["label"] == "first-variant")["textEdit"]
    assert edit["range"]["start"] == {"line": 2, "character": 10} and edit["range"]["end"] == {
        "line": 2,
        "character": 17,
    }


def test_completion_of_parameters_and_measures(server):
    assert labels(complete_at_end(server, "robot a { chain H1 - L4(piv")) == ["pivot", "port", "link"]
    assert labels(complete_at_end(server, "robot a { chain H1 - L2(")) == ["pivot"]  # no link module
    assert labels(complete_at_end(server, "robot a { chain H1 - L4(pivot=15deg, ")) == ["port", "link"]
    assert labels(complete_at_end(server, "robot a { chain H1 - L4(pivot=15")) == ["deg", "rad"]
    assert labels(complete_at_end(server, "robot a { chain H1 - L4(link=180")) == ["m", "cm", "mm"]
    assert labels(complete_at_end(server, "robot a { chain H1 - L1\n    payload 2")) == ["kg", "g"]
    assert labels(complete_at_end(server, "robot a { chain H1 - L1\n    pose p (0, 0) ")) == ["deg", "rad"]
    assert labels(complete_at_end(server, "robot a { chain H1 - L1\n    tool at (0, 0, 0.1) ")) == ["m", "cm", "mm"]
    assert labels(complete_at_end(server, "robot a { dh {\n        row a=0.3 m, ")) == ["alpha", "d", "theta"]


def test_completion_of_statements_and_clauses(server):
    got = labels(complete_at_end(server, "robot a {\n    chain H1 - L1\n    "))
    assert got == list(statements())
    assert "chain" in labels(complete_at_end(server, "robot a {\n    cha"))
    assert labels(complete_at_end(server, "")) == ["design", "robot"]
    assert labels(complete_at_end(server, "robot a { chain H1 - L1\n    box shelf ")) == ["size"]
    assert labels(complete_at_end(server, "robot a { chain H1 - L1\n    box shelf size (1, 1, 1) m ")) == ["at"]
    assert labels(complete_at_end(server, "robot a { chain H1 - L1\n    library ")) == ["mark2", "mark2-strict"]
    assert labels(complete_at_end(server, "robot a { chain H1 - L4(port=45deg) - L1\n    limit ")) == [
        "joint_1",
        "joint_2",
        "joint_3",
    ]
    assert labels(complete_at_end(server, "robot a { chain H1 - L4 - L1\n    pose ")) == ["home"]
    # every registered objective, task objectives included
    assert labels(complete_at_end(server, "design d {\n    target t at (0.3, 0, 0.2) m\n    rank ")) == [
        "modules", "mass", "margin", "cycle_time", "energy", "coverage"]
    assert labels(complete_at_end(server, "robot a { chain H1 - L4 - L1\n    pose home (0,0,0) deg\n    pose ")) == []
    assert labels(complete_at_end(server, "robot a { chain H1 - L4 - L1\n    pose ready ")) == ["(0, 0, 0) deg"]
    assert labels(complete_at_end(server, "robot a { chain H1 - L1 # a comment ")) == []


def test_completion_in_yaml(server):
    assert "L4" in labels(complete_at_end(server, "robots:\n  - name: a\n    chain:\n      - H1\n      - ", "a.yaml"))
    assert "first-variant" in labels(
        complete_at_end(server, "robots:\n  - name: a\n    chain: [L1]\n    allow: [", "a.yaml")
    )
    items = complete_at_end(server, "robots:\n  - name: a\n    chain:\n      - H1\n      - L", "a.yaml")
    edit = next(i for i in items if i["label"] == "L4")["textEdit"]  # the typed "L" is replaced
    assert edit["range"] == {"start": {"line": 4, "character": 8}, "end": {"line": 4, "character": 9}}


# --- symbols, definition, formatting ----------------------------------------------------------------


def test_document_symbols(server):
    uri = open_doc(server, FARM)
    syms = server.result("textDocument/documentSymbol", {"textDocument": {"uri": uri}})
    assert [s["name"] for s in syms] == ["farm", "wrist"]
    farm = syms[0]
    kids = {(c["name"], c["detail"]) for c in farm["children"]}
    assert {("chain", "H1-L4-L3"), ("ready", "pose"), ("floor", "box"), ("plant", "target")} <= kids
    chain = next(c for c in farm["children"] if c["name"] == "chain")
    assert [(u["name"], u["detail"]) for u in chain["children"]] == [
        ("H1", "joint_1"),
        ("L4", "joint_2"),
        ("L3", "joint_3"),
    ]
    assert farm["selectionRange"]["start"] == {"line": 0, "character": 6}


def test_document_symbols_of_a_half_typed_file(server):
    text = "robot a {\n    chain H1 - L4(piv\n    pose p (0, 0) deg\nrobot b {\n    target t at (0"
    uri = open_doc(server, text)
    assert LAST_DIAGS[id(server)] and LAST_DIAGS[id(server)][0]["severity"] == 1
    syms = server.result("textDocument/documentSymbol", {"textDocument": {"uri": uri}})
    assert [s["name"] for s in syms] == ["a", "b"]
    assert [c["name"] for c in syms[1]["children"]] == ["t"]


def test_document_symbols_of_yaml(server):
    uri = open_doc(server, (ROOT / "examples" / "quickstart.yaml").read_text(), "q.yaml")
    [robot] = server.result("textDocument/documentSymbol", {"textDocument": {"uri": uri}})
    assert robot["name"] == "farm" and robot["children"][0]["detail"] == "H1-L4-L1"


def test_definition(server):
    uri = open_doc(server, FARM)

    def where(needle, nth=0, delta=1):
        return [
            (loc["uri"], loc["range"]["start"]["line"], loc["range"]["start"]["character"])
            for loc in server.at("textDocument/definition", uri, *pos(FARM, needle, nth, delta))
        ]

    # joint_2 in `limit` -> the second unit of the chain
    assert where("joint_2") == [(uri, *pos(FARM, "L4(pivot"))]
    # a pose name -> its declaration in the same robot (wrist's `ready` is another pose)
    assert where("ready", 1) == [(uri, *pos(FARM, "ready", 1))]
    assert where("ready", 0) == [(uri, *pos(FARM, "ready", 0))]
    # robot, target and obstacle names -> their declaration
    assert where("farm") == [(uri, 0, 6)]
    assert where("plant") == [(uri, *pos(FARM, "plant"))]
    assert where("floor") == [(uri, *pos(FARM, "floor"))]
    # the library -> its file
    [(lib_uri, line, col)] = where("mark2")
    assert lib_uri.endswith("/mark2.yaml") and Path(convert.uri_to_path(lib_uri)).is_file()
    # nothing to find
    assert where("chain") == [] and where("(0.06", delta=2) == []


def test_definition_in_a_half_typed_file(server):
    text = "robot a {\n    chain H1 - L4 - L1\n    pose p (0, 0, 0) deg\n    limit joint_3 (0, 1"
    uri = open_doc(server, text)
    [loc] = server.at("textDocument/definition", uri, *pos(text, "joint_3", delta=3))
    assert loc["range"]["start"] == {"line": 1, "character": 20}


def test_formatting(server):
    text = "robot a {\nchain H1 -   L1\n}\n"
    uri = open_doc(server, text)
    edits = server.result(
        "textDocument/formatting", {"textDocument": {"uri": uri}, "options": {"tabSize": 4, "insertSpaces": True}}
    )
    try:
        from modc.syntax.format import format_text
    except ImportError:
        assert edits == []  # no formatter yet: no edits
        return
    want, _ = format_text(text, convert.uri_to_path(uri))
    assert want == "robot a {\n    chain H1 - L1\n}\n"
    if want == text:
        assert edits == []
    else:
        [edit] = edits
        assert edit["newText"] == want and edit["range"]["start"] == {"line": 0, "character": 0}
        assert edit["range"]["end"] == {"line": 3, "character": 0}


def test_formatting_calls_format_text(monkeypatch):
    import types as pytypes

    fake: Any = pytypes.ModuleType("modc.syntax.format")
    fake.format_text = lambda text, path: (text.replace("-   ", "- "), [])
    monkeypatch.setitem(sys.modules, "modc.syntax.format", fake)
    an = Analysis("robot a {\n    chain H1 -   L1\n}", "/x/a.mod")
    [edit] = formatting(an)
    assert edit.new_text == "robot a {\n    chain H1 - L1\n}"
    assert (edit.range.end.line, edit.range.end.character) == (2, 1)
    fake.format_text = lambda text, path: (None, ["a syntax error"])  # does not parse: no edits
    assert formatting(an) == []
    assert formatting(Analysis("robots: []", "/x/a.yaml")) == []  # YAML: not formatted
    monkeypatch.setitem(sys.modules, "modc.syntax.format", None)  # no formatter: no edits
    assert formatting(an) == []


# --- robustness -------------------------------------------------------------------------------------


def test_malformed_requests_get_errors_and_the_server_keeps_answering(server):
    uri = open_doc(server, FARM)

    def alive():
        h = server.at("textDocument/hover", uri, *pos(FARM, "H1", delta=1))
        assert "KA-75+" in h["contents"]["value"]

    # unknown method -> MethodNotFound
    r = server.request("modc/noSuchMethod", {})
    assert r["error"]["code"] == -32601
    alive()
    # bad params -> an error response (invalid params), not a crash
    bad: tuple[object, ...] = (
        {"textDocument": 5},
        {"position": {"line": "x"}},
        [],
        None,
        {"textDocument": {"uri": uri}, "position": {"line": -1, "character": 0}},
    )
    for params in bad:
        r = server.request("textDocument/hover", params)
        assert "error" in r or r.get("result") is None
        alive()
    r = server.request("textDocument/completion", {"textDocument": {"uri": uri}})
    assert "error" in r or r.get("result") in (None, [])
    alive()
    # positions out of range are clamped: no error
    for line, col in ((1000, 0), (0, 10_000), (10_000, 10_000)):
        assert "result" in server.request(
            "textDocument/hover", {"textDocument": {"uri": uri}, "position": {"line": line, "character": col}}
        )
        assert "result" in server.request(
            "textDocument/completion", {"textDocument": {"uri": uri}, "position": {"line": line, "character": col}}
        )
        assert "result" in server.request(
            "textDocument/definition", {"textDocument": {"uri": uri}, "position": {"line": line, "character": col}}
        )
    alive()
    # a document that was never opened: empty answers, and the file is not read
    other = "file:///dev/zero"
    assert server.at("textDocument/hover", other, 0, 0) is None
    assert server.at("textDocument/completion", other, 0, 0) in (None, [])
    assert server.result("textDocument/documentSymbol", {"textDocument": {"uri": other}}) in (None, [])
    server.change("file:///never/opened.mod", 2, text="robot a {}")
    alive()
    # not JSON at all, a JSON array, a notification with garbage
    body = b"{this is not json"
    server.send_bytes(b"Content-Length: %d\r\n\r\n" % len(body) + body)
    body = b"[1, 2, 3]"
    server.send_bytes(b"Content-Length: %d\r\n\r\n" % len(body) + body)
    server.notify("textDocument/didOpen", {"textDocument": "nope"})
    server.notify("$/cancelRequest", {"id": 999999})
    alive()


HALF_TYPED = [
    "robot a { chain H1 - L4(piv",
    "robot",
    "robot a",
    "robot a {",
    "robot a { chain",
    "robot a { chain H1 -",
    "robot a { chain H1 - L4(pivot=",
    "robot a { chain H1 - L4(pivot=-9",
    "robot a { chain H1 - L4(pivot=-90deg,",
    "robot a { chain H1 - L4 } }",
    "robot a { dh { row a=",
    'robot a { library "unterminated',
    "robot a { pose",
    "robot a { allow",
    "}}}}((((",
    "robot a { chain H1 - L4 box b size (1, 1, 1) m at (",
    "robot 1 { chain ℍ1 - L4 }",
    "robot a { chain H1 - L4 # 🤖 comment\n    pose p (0, 0",
    "\x00\x01 robot",
]


def test_half_typed_files_never_break_a_feature(server):
    """Each half-typed text, and every prefix of a real file: diagnostics arrive, and every
    feature answers at every tested position (a result, never an error)."""
    texts = list(HALF_TYPED) + [FARM[:n] for n in range(0, len(FARM) + 1, 7)]
    uri = open_doc(server, "")
    version = 1
    for text in texts:
        version += 1
        server.change(uri, version, text=text)
        server.diagnostics(uri, version=version)
        lines = text.split("\n")
        points = {(len(lines) - 1, len(lines[-1])), (0, 0), (0, min(3, len(lines[0])))}
        for line, col in points:
            for method in ("textDocument/hover", "textDocument/completion", "textDocument/definition"):
                r = server.request(method, {"textDocument": {"uri": uri}, "position": {"line": line, "character": col}})
                assert "result" in r, (method, text, r)
        for method, extra in (
            ("textDocument/documentSymbol", {}),
            ("textDocument/formatting", {"options": {"tabSize": 4, "insertSpaces": True}}),
        ):
            r = server.request(method, {"textDocument": {"uri": uri}, **extra})
            assert "result" in r, (method, text, r)
    # one error per unparsable text, as the CLI
    server.change(uri, version + 1, text="robot a { chain H1 - L4(piv")
    [d] = server.diagnostics(uri, version=version + 1)
    assert d["severity"] == 1


def test_a_burst_of_changes_ends_with_the_newest_diagnostics(server):
    uri = open_doc(server, "robot a { chain H1 - L1 }")
    for v in range(2, 40):
        server.change(uri, v, text=f"robot a {{ chain H1 - L4(port={v}deg) - L1 }}")
    server.change(uri, 40, text="robot a { chain H1 - L4(port=45deg) - L1 }")
    assert server.diagnostics(uri, version=40) == []


def test_every_edit_gets_the_diagnostics_of_its_version(server):
    """Edits one at a time: each is answered with its own version's diagnostics (speed is
    benchmarks/bench_lsp.py's figure, not a test's)."""
    text = (ROOT / "examples" / "example_a.mod").read_text()
    uri = open_doc(server, text)
    for v in range(2, 12):
        broken = v % 3 == 0
        server.change(uri, v, text=text.replace("chain H1", "chain H9") if broken else text + f"\n# edit {v}\n")
        diags = server.diagnostics(uri, version=v)
        assert bool(diags) == broken and all(d["severity"] == 1 for d in diags), (v, diags)


# --- in-process: conversions ------------------------------------------------------------------------


def test_positions_count_utf16_code_units():
    text = "# 🤖 é\nrobot a { chain H1 - L4 }  # ℍ 🤖 x"
    idx = convert.LineIndex(text)
    i = text.index("x")
    p = idx.position(i)
    # line 1: '🤖' is 2 UTF-16 units, 'ℍ' 1
    assert (p.line, p.character) == (1, len(text.split("\n")[1][:-1]) + 1)
    assert idx.offset(p) == i
    for enc, width in ((convert.UTF8, 4), (convert.UTF32, 1), (convert.UTF16, 2)):
        ix = convert.LineIndex(text, enc)
        after_robot = text.index("🤖") + 1
        assert ix.position(after_robot).character == 2 + width
        assert ix.offset(ix.position(after_robot)) == after_robot
    # a position inside a surrogate pair or past the end of a line is clamped
    assert idx.offset(convert.types.Position(line=0, character=3)) == 2
    assert idx.offset(convert.types.Position(line=0, character=999)) == text.index("\n")
    assert idx.offset(convert.types.Position(line=99, character=0)) == len(text)


def test_diagnostic_conversion_uses_utf16_and_clamps():
    text = "# 🤖\nrobot a {\n    chain H1 - L4(port=40deg) - L1 # 🤖🤖\n}"
    [d] = check_text(text, "/x/a.mod").diagnostics
    [ld] = convert.diagnostics([d], text, "/x/a.mod")
    assert ld.range.start.line == 2 and ld.range.start.character == d.span.col - 1
    # a span past the end of the text (end of file) is clamped into it
    from modc.diagnostics import Span, codes

    eof = codes.UNCLOSED_BLOCK.at(Span("/x/a.mod", 4, 2, 4, 3, len(text), len(text) + 1), name="a")
    [ld] = convert.diagnostics([eof], text, "/x/a.mod")
    assert (ld.range.start.line, ld.range.start.character, ld.range.end.character) == (3, 1, 1)
    # a diagnostic about another file is shown at the top of this one, naming the file
    other = codes.UNCLOSED_BLOCK.at(Span("/x/lib.yaml", 3, 1, 3, 2), name="a")
    [ld] = convert.diagnostics([other], text, "/x/a.mod")
    assert ld.range.start.line == 0 and ld.message.startswith("/x/lib.yaml:3:1: ")


def test_uri_paths():
    assert convert.uri_to_path("file:///tmp/a%20b.mod") == "/tmp/a b.mod"
    assert convert.uri_to_path("untitled:Untitled-1") == "untitled:Untitled-1"
    assert convert.uri_to_path(convert.path_to_uri("/tmp/x.yaml")).endswith("x.yaml")


def test_lexer_and_outline_survive_anything():
    for text in HALF_TYPED + ["", "robot a { robot b { chain H1 }", "((((((((", "robot { { } } }"]:
        an = Analysis(text, "/x/a.mod")
        symbols(an)
        for off in range(len(text) + 1):
            complete(an, off)
            hover(an, off)
            definition(an, off, "file:///x/a.mod")


@pytest.mark.parametrize(
    "path, text",
    [
        (
            "/x/a.mod",
            "robot a {\n    chain H1 - L4(port=45deg) - L1\n    pose home (0, 10, 0) deg\n"
            "    target p at (0.2, 0, 0.3) m\n}\n",
        ),
        (
            "/x/a.yaml",
            'robots:\n  - name: a\n    chain: [H1, {unit: L4, port: 45deg}, L1]\n    poses: {home: "(0, 10, 0) deg"}\n',
        ),
    ],
)
def test_each_version_is_parsed_once(monkeypatch, path, text):
    """Diagnostics, symbols, hover, completion and definitions all use the check's own parse."""
    import modc.syntax
    import modc.syntax.yaml_form

    calls = []

    def counting(real):
        def parse(*args):
            calls.append(args)
            return real(*args)

        return parse

    for module, name in ((modc.syntax, "parse"), (modc.syntax.yaml_form, "parse_yaml")):
        monkeypatch.setattr(module, name, counting(getattr(module, name)))
    an = Analysis(text, path)
    an.diagnostics()
    assert an.parsed
    symbols(an)
    for off in range(0, len(text), 7):
        complete(an, off)
        hover(an, off)
        definition(an, off, "file://" + path)
    assert len(calls) == 1


# --- the language described once: read from the grammar ---------------------------------------------


def test_keyword_classes_are_read_from_the_grammar():
    from modc.lsp import language

    assert language.declaration_keywords() == {"robot", "design"}
    assert language.statements() == (
        "chain",
        "dh",
        "library",
        "base",
        "tool",
        "payload",
        "pose",
        "limit",
        "box",
        "sphere",
        "cylinder",
        "target",
        "region",
        "task",
        "path",
        "allow",
    )
    assert language.statements("dh") == ("row",)
    assert language.clause_keywords() == {"at", "rpy", "size", "radius", "length", "fit-links", "within", "to", "step",
                                          "grid", "x", "visit", "from", "straight", "yaw", "with", "pointing",
                                          "turned"}
    assert language.statements("design") == (
        "library", "base", "tool", "payload", "box", "sphere", "cylinder", "target", "allow", "region", "task", "path",
        "units", "modules", "links", "rank", "compare",
    )
    assert language.name_takers() == {"robot", "design", "pose", "limit", "box", "sphere", "cylinder", "target", "rank",
                                      "region", "task", "path"}
    assert language.syntax_of("cylinder") == "cylinder NAME radius QUANTITY length QUANTITY at (…) rpy (…)"


def test_every_value_keyword_has_a_quantity_kind():
    """A keyword followed by a quantity or vector in the grammar needs its kind (length, angle,
    mass) in language.QUANTITY_KINDS, so that completion offers the right units of measure."""
    from modc.lsp import language

    assert language.value_keywords() <= set(language.QUANTITY_KINDS), sorted(
        language.value_keywords() - set(language.QUANTITY_KINDS)
    )


GRAMMAR_PLUS = {
    # a new statement: grammar only
    "     | allow\n": "     | allow\n     | gripper\n",
    'allow: "allow"': 'gripper: "gripper" NAME at\nallow: "allow"',
    # a new top-level block with its own statement
    "start: (robot | design)*": 'start: (robot | design | fixture)*\n'
    'fixture: "fixture" NAME "{" use* "}"\nuse: "use" NAME',
}


@pytest.fixture
def grammar_plus(monkeypatch, tmp_path):
    """The real grammar with a new statement (`gripper NAME at (…)`) and a new top-level block
    (`fixture NAME { use NAME }`): nothing else changed."""
    from lark import Lark

    import modc.syntax.parser as parser
    from modc.lsp import language
    from modc.resources import data_dir

    text = (data_dir("grammar") / "modc.lark").read_text(encoding="utf-8")
    for old, new in GRAMMAR_PLUS.items():
        assert old in text
        text = text.replace(old, new)
    lark = Lark(
        text,
        parser="lalr",
        propagate_positions=True,
        maybe_placeholders=True,
        start=["start", "unit_text", "quantity_text", "vector_text"],
    )
    monkeypatch.setattr(parser, "_lark", lambda: lark)
    language.reset()
    yield
    monkeypatch.undo()
    language.reset()


def _labels(items) -> list[str]:
    return [i.label for i in items]


def test_a_new_statement_needs_no_language_server_change(grammar_plus):
    from modc.lsp import language

    assert "gripper" in language.statements() and "gripper" in language.name_takers()
    assert language.declaration_keywords() == {"robot", "design", "fixture"} and language.statements("fixture") == (
        "use",
    )
    got = _labels(complete(Analysis("robot a {\n    chain H1 - L1\n    ", "/x/a.mod"), 33))
    assert got[-1] == "gripper" and got[:-1] == list(language.statements())[:-1]
    text = "robot a {\n    chain H1 - L1\n    gripper g "
    assert _labels(complete(Analysis(text, "/x/a.mod"), len(text))) == ["at"]
    text += "at (0, 0, 0.1) "
    assert _labels(complete(Analysis(text, "/x/a.mod"), len(text))) == ["m", "cm", "mm"]
    assert set(_labels(complete(Analysis("", "/x/a.mod"), 0))) == {"robot", "design", "fixture"}
    text = "fixture d {\n    "
    assert _labels(complete(Analysis(text, "/x/a.mod"), len(text))) == ["use"]
    # the half-typed outline declares the new statement's name
    an = Analysis("robot a {\n    chain H1 - L1\n    gripper g at (0, 0", "/x/a.mod")
    assert [(d.kind, d.name) for d in an.decls] == [("robot", "a"), ("gripper", "g")]
    assert hover(an, an.text.index("gripper") + 1) is not None


def test_capability_by_dotted_path():
    from lsprotocol import types

    from modc.lsp.server import capability

    path = "text_document.completion.completion_item.snippet_support"
    assert capability(types.ClientCapabilities(), path, False) is False
    caps = types.ClientCapabilities(
        text_document=types.TextDocumentClientCapabilities(
            completion=types.CompletionClientCapabilities(
                completion_item=types.ClientCompletionItemOptions(snippet_support=True)
            )
        )
    )
    assert capability(caps, path, False) is True


@pytest.mark.parametrize(
    "text",
    [
        "robot a { dh {\n    row a=0.3 m, alpha=0deg, d=0 m\nrow\nrow\nrow x",
        "row\nrow\n",
        "chain H1\nchain\n  robot\nrobot a {\n    @@@\n    chain H1 -",
        "robot a {\n    chain H1 H2\n    pose p (0, 0\n    box\n",
    ],
)
def test_tolerant_parse_always_moves_forward(text):
    """Restarts that fail on their own first word move on: every prefix finishes."""
    from modc.lsp import tolerant

    for n in range(len(text) + 1):
        tolerant.stand_at(text[:n])
        tolerant.outline(text[:n])


def test_parameters_are_the_lowerings():
    """Parameter names and kinds come from the lowering (model/lower.py); every one has its words."""
    from modc.lsp import language
    from modc.model import lower

    assert language.UNIT_PARAMS == tuple(lower.UNIT_PARAMS) and language.DH_PARAMS == tuple(lower.DH_PARAMS)
    assert set(language.PARAM_TEXT) == set(lower.UNIT_PARAMS) | set(lower.DH_PARAMS)
    assert all(kind in language.KIND_MEASURES for kind, _ in language.PARAMS.values())


@pytest.mark.parametrize("text", [
    "robot a {\n    chain H1 - L1\n    library nosuchlib\n    limit joint_1 (-90, 90) deg\n}\n",  # no library
    "robot a {\n    chain H1 - Q7\n    limit joint_2 (-90, 90) deg\n}\n",  # a unit the library lacks
])
def test_hover_on_a_joint_of_an_unresolved_robot(text):
    """The joint's range needs the resolved library and the unit's variant; without them the
    hover says which unit it is (it used to fail: an assertion, a KeyError)."""
    an = Analysis(text, "/x/a.mod")
    h = hover(an, text.index("joint_") + 2)
    assert h is not None and "the joint of unit" in h.contents.value and "range" not in h.contents.value


def test_the_library_is_the_checked_robots_not_looked_up_again(monkeypatch):
    """The LSP takes a robot's library from the checked model (resolve_library found it once);
    only a block that does not lower yet reads its `library` statement; a library that did not
    load gives the default (no second lookup of the same name)."""
    from modc.lsp import document

    text = "robot a {\n    chain H1 - L1\n    library mark2-strict\n}\n"
    an = Analysis(text, "/x/a.mod")
    r = an.model_robot("a")
    calls: list[str] = []
    monkeypatch.setattr(document, "load_library", lambda ref, where=None: calls.append(ref))
    assert an.library_for("a") is r.library and r.library.name == "mark2-strict" and calls == []
    bad = Analysis("robot b {\n    chain H1 - L1\n    library nosuchlib\n}\n", "/x/b.mod")
    assert bad.model_robot("b") is not None
    assert bad.library_for("b").name == "mark2" and calls == []


def test_hover_on_the_library_statement_shows_the_checked_robots_library(monkeypatch):
    from modc.lsp import document

    text = "robot a {\n    chain H1 - L1\n    library mark2-strict\n}\n"
    an = Analysis(text, "/x/a.mod")
    assert an.model_robot("a") is not None
    monkeypatch.setattr(document, "load_library", lambda *a, **k: None)  # no second lookup
    h = hover(an, text.index("mark2-strict") + 2)
    assert h is not None and "**library mark2-strict**" in h.contents.value
