"""A small synchronous LSP client that drives a real server process over its stdin/stdout:
JSON-RPC with Content-Length framing, a reader thread, arrival times on every message.
Used by tests/test_lsp.py and benchmarks/bench_lsp.py; standard library only.

    with Client([sys.executable, "-m", "modc.lsp"]) as c:
        c.initialize()
        c.open("file:///tmp/a.mod", "robot a { chain H1 - L1 }")
        c.diagnostics("file:///tmp/a.mod")
"""

from __future__ import annotations

import itertools
import json
import subprocess
import sys
import threading
import time
from collections import deque

WAIT = 120.0  # s: a guard against a hung server, not a speed bound (a busy machine answers late)


class ServerGone(Exception):
    pass


class Client:
    def __init__(self, cmd: list[str] | None = None, cwd: str | None = None, env: dict | None = None):
        self.cmd = cmd or [sys.executable, "-m", "modc.lsp"]
        self.proc = subprocess.Popen(
            self.cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE, cwd=cwd, env=env
        )
        # PIPE on all three: the streams exist (Popen types them Optional)
        assert self.proc.stdin is not None and self.proc.stdout is not None and self.proc.stderr is not None
        self.stdin, self.stdout, self.stderr_pipe = self.proc.stdin, self.proc.stdout, self.proc.stderr
        self._ids = itertools.count(1)
        self._cond = threading.Condition()
        self.responses: dict = {}
        self.notifications: deque = deque()  # (arrival time, message)
        self.stderr: list[bytes] = []
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()
        self._err = threading.Thread(target=self._read_stderr, daemon=True)
        self._err.start()
        self.closed = False

    # --- wire -------------------------------------------------------------------------------
    def _read(self) -> None:
        out = self.stdout
        try:
            while True:
                length = None
                while True:
                    line = out.readline()
                    if not line:
                        raise EOFError
                    line = line.strip()
                    if not line:
                        break
                    name, _, value = line.partition(b":")
                    if name.lower() == b"content-length":
                        length = int(value)
                body = out.read(length or 0)
                t = time.perf_counter()
                msg = json.loads(body)
                if "method" in msg and "id" in msg:  # a request from the server: answer null
                    self.send({"jsonrpc": "2.0", "id": msg["id"], "result": None})
                    continue
                with self._cond:
                    if "id" in msg and "method" not in msg:
                        self.responses[msg["id"]] = (t, msg)
                    else:
                        self.notifications.append((t, msg))
                    self._cond.notify_all()
        except (EOFError, ValueError, OSError):
            with self._cond:
                self.closed = True
                self._cond.notify_all()

    def _read_stderr(self) -> None:
        for line in self.stderr_pipe:
            self.stderr.append(line)

    def send_bytes(self, data: bytes) -> None:
        try:
            self.stdin.write(data)
            self.stdin.flush()
        except (BrokenPipeError, ValueError, OSError) as e:
            raise ServerGone(str(e)) from None

    def send(self, msg: dict) -> float:
        body = json.dumps(msg).encode("utf-8")
        t = time.perf_counter()
        self.send_bytes(b"Content-Length: %d\r\n\r\n" % len(body) + body)
        return t

    # --- JSON-RPC ---------------------------------------------------------------------------
    def request_async(self, method: str, params=None) -> int:
        rid = next(self._ids)
        msg = {"jsonrpc": "2.0", "id": rid, "method": method}
        if params is not None:
            msg["params"] = params
        self.send(msg)
        return rid

    def response(self, rid, timeout: float = WAIT) -> dict:
        deadline = time.monotonic() + timeout
        with self._cond:
            while rid not in self.responses:
                if self.closed:
                    raise ServerGone(f"no response to {rid}: the server closed its output")
                left = deadline - time.monotonic()
                if left <= 0:
                    raise TimeoutError(f"no response to request {rid} within {timeout} s")
                self._cond.wait(left)
            return self.responses.pop(rid)[1]

    def request(self, method: str, params=None, timeout: float = WAIT) -> dict:
        """The whole response message ({"result": …} or {"error": …})."""
        return self.response(self.request_async(method, params), timeout)

    def result(self, method: str, params=None, timeout: float = WAIT):
        msg = self.request(method, params, timeout)
        if "error" in msg:
            raise RuntimeError(f"{method}: {msg['error']}")
        return msg.get("result")

    def notify(self, method: str, params=None) -> float:
        msg = {"jsonrpc": "2.0", "method": method}
        if params is not None:
            msg["params"] = params
        return self.send(msg)

    def wait_notification(self, method: str, pred=lambda params: True, timeout: float = WAIT) -> tuple[float, dict]:
        """The first (arrival time, params) of a notification that matches, removed from the queue."""
        deadline = time.monotonic() + timeout
        with self._cond:
            while True:
                for item in list(self.notifications):
                    t, msg = item
                    if msg.get("method") == method and pred(msg.get("params")):
                        self.notifications.remove(item)
                        return t, msg.get("params")
                if self.closed:
                    raise ServerGone(f"no {method}: the server closed its output")
                left = deadline - time.monotonic()
                if left <= 0:
                    raise TimeoutError(f"no {method} within {timeout} s")
                self._cond.wait(left)

    # --- LSP conveniences -------------------------------------------------------------------
    def initialize(self, capabilities: dict | None = None) -> dict:
        caps = (
            capabilities
            if capabilities is not None
            else {
                "textDocument": {
                    "completion": {"completionItem": {"snippetSupport": True}},
                    "hover": {"contentFormat": ["markdown", "plaintext"]},
                    "documentSymbol": {"hierarchicalDocumentSymbolSupport": True},
                }
            }
        )
        result = self.result("initialize", {"processId": None, "rootUri": None, "capabilities": caps})
        self.notify("initialized", {})
        return result

    def open(self, uri: str, text: str, version: int = 1, language: str = "modc") -> float:
        return self.notify(
            "textDocument/didOpen",
            {"textDocument": {"uri": uri, "languageId": language, "version": version, "text": text}},
        )

    def change(self, uri: str, version: int, text: str | None = None, rng: dict | None = None, new: str = "") -> float:
        change = {"text": text} if rng is None else {"range": rng, "text": new}
        return self.notify(
            "textDocument/didChange", {"textDocument": {"uri": uri, "version": version}, "contentChanges": [change]}
        )

    def diagnostics(self, uri: str, version: int | None = None, timeout: float = WAIT) -> list[dict]:
        def match(p):
            return p["uri"] == uri and (version is None or p.get("version") == version)

        return self.wait_notification("textDocument/publishDiagnostics", match, timeout)[1]["diagnostics"]

    def at(self, method: str, uri: str, line: int, character: int, **extra):
        return self.result(
            method, {"textDocument": {"uri": uri}, "position": {"line": line, "character": character}, **extra}
        )

    def shutdown(self, timeout: float = WAIT) -> int:
        """shutdown, exit; the server's exit code."""
        self.result("shutdown", timeout=timeout)
        self.notify("exit")
        try:
            return self.proc.wait(timeout)
        finally:
            self.close()

    def close(self) -> None:
        if self.proc.poll() is None:
            try:
                self.stdin.close()
            except OSError:
                pass
            try:
                self.proc.wait(5)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        for f in (self.stdin, self.stdout, self.stderr_pipe):
            try:
                f.close()
            except OSError:
                pass

    def __enter__(self) -> Client:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
