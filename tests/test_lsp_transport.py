"""The language server's framing (modc.lsp.transport): hostile headers never kill the server
or swallow the next message, and memory stays bounded."""
from __future__ import annotations

import io
import sys
from pathlib import Path

from modc.lsp.client import Client
from modc.lsp.transport import MAX_BODY, FramedReader

ROOT = Path(__file__).resolve().parent.parent


def frame(body: bytes, header: bytes | None = None) -> bytes:
    return (header if header is not None else b"Content-Length: %d\r\n" % len(body)) + b"\r\n" + body


def frames_read(data: bytes) -> list[bytes]:
    """The bodies pygls would get, read the way pygls reads (readline, then read(n))."""
    r = FramedReader(io.BytesIO(data))
    out = []
    while True:
        head = r.readline()
        if not head:
            return out
        assert head.startswith(b"Content-Length: ") and r.readline() == b"\r\n"
        n = int(head.split(b":")[1])
        out.append(r.read(n))


def test_good_frames_pass_unchanged():
    bodies = [b'{"a":1}', b'{"b":"x\\r\\ny"}', b"{}" * 1000]
    typed = b"Content-Type: application/vscode-jsonrpc; charset=utf-8\r\nContent-Length: 7\r\n"
    data = b"".join(frame(b) for b in bodies) + frame(b'{"c":2}', typed)
    assert frames_read(data) == [*bodies, b'{"c":2}']


def test_bad_headers_are_dropped_and_the_next_message_survives():
    good = b'{"id":2}'
    for bad in (b"Content-Length: 99999999999999999999\r\n", b"Content-Length: %d\r\n" % (MAX_BODY + 1),
                b"Content-Length: abc\r\n", b"Content-Length: -5\r\n", b"X-Nothing\r\n", b"",
                b"Content-Type: x\r\n", b"Content-Length: " + b"9" * 5000 + b"\r\n", b"A: b\r\n" * 40):
        data = frame(b'{"id":1,"junk":"' + b"z" * 3000 + b'"}', bad) + frame(good)
        assert frames_read(data) == [good], bad[:40]
    # a body without any header in front of a good frame, and a header split across long-line pieces
    assert frames_read(b"x" * 5000 + frame(good)) == [good]
    assert frames_read(b"garbage\r\n\r\n" + b"y" * 1020 + frame(good)) == [good]


def test_a_body_cut_short_ends_the_stream():
    assert frames_read(b"Content-Length: 100\r\n\r\n{}") == []


def test_the_server_survives_a_huge_content_length():
    c = Client([sys.executable, "-m", "modc.lsp"], cwd=str(ROOT))
    try:
        c.initialize()
        for bad in (b"Content-Length: 99999999999999999999\r\n", b"Content-Length: nope\r\n"):
            c.send_bytes(frame(b'{"jsonrpc":"2.0","id":77,"method":"shutdown"}', bad))
        rid = c.request_async("textDocument/documentSymbol", {"textDocument": {"uri": "file:///none.mod"}})
        assert c.response(rid)["result"] == []
        assert c.proc.poll() is None
        assert c.shutdown() == 0
    finally:
        c.close()


def _garbage(n: int, seed: int = 1) -> bytes:
    """n frames of the kinds that made pygls write a traceback each: bytes that are not UTF-8 or
    not JSON, JSON that is not JSON-RPC, requests whose params do not fit, headers without a length."""
    import random

    rnd = random.Random(seed)
    kinds = [
        lambda: frame(bytes(rnd.randrange(256) for _ in range(rnd.randrange(1, 200)))),
        lambda: frame(b'{"jsonrpc":"2.0","id":%d,"method":"textDocument/hover","params":{}}' % rnd.randrange(9999)),
        lambda: frame(b"[1,2,3]"),
        lambda: frame(b'{"jsonrpc":"2.0","method":"textDocument/didOpen","params":{"textDocument":{"uri":5}}}'),
        lambda: frame(b"[" * 3000 + b"]" * 3000),
        lambda: b"garbage\r\n" * rnd.randrange(1, 20),
    ]
    return b"".join(rnd.choice(kinds)() for _ in range(n))


def test_a_burst_of_garbage_keeps_the_log_small():
    """Each bad frame used to log a full pygls traceback (79 MB in 150 s); now every kind of
    message is written in full once, then counted."""
    c = Client([sys.executable, "-m", "modc.lsp"], cwd=str(ROOT))
    try:
        c.initialize()
        c.send_bytes(_garbage(3000))
        rid = c.request_async("textDocument/documentSymbol", {"textDocument": {"uri": "file:///none.mod"}})
        assert c.response(rid, timeout=120)["result"] == []  # every frame before it has been read
        assert c.shutdown(timeout=60) == 0
    finally:
        c.close()
    log = b"".join(c.stderr).decode("utf-8", "replace")
    assert len(log) < 64_000, f"{len(log):,} characters of log for 3000 bad frames"
    assert "Traceback" in log and log.count("Traceback") <= 10  # the first of each kind, in full
    assert "times so far" in log


def test_the_log_stops_at_its_budget():
    import logging

    from modc.lsp.logs import BoundedHandler

    out = io.StringIO()
    handler = BoundedHandler(out, budget=20_000)
    logger = logging.getLogger("modc.test.bounded")
    logger.addHandler(handler)
    logger.propagate = False
    try:
        for k in range(5000):  # every message a kind of its own, so no dedupe helps
            try:
                raise ValueError("x" * 50)
            except ValueError:
                logger.exception(f"failure number {k}")
        logger.error("y" * 100_000)
    finally:
        logger.removeHandler(handler)
    text = out.getvalue()
    assert len(text) <= 20_000 and text.endswith("further messages are dropped\n")
    assert "failure number 0" in text and "failure number 4999" not in text
