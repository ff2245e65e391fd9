"""`modc lsp`: the language server, on pygls. Handlers are thin: they find the document's
Analysis (document.py), turn the LSP position into a character offset and back (convert.py)
and ask the feature's module (hover.py, completion.py, symbols.py, formatting.py).

Diagnostics are published on open and on every change, computed right away (the lint-level
check of a 6-DoF file takes about 2 ms; no torque analysis); changes that arrive in a burst
are coalesced: the check runs once for the newest version that has arrived by the time the
event loop gets to it. A handler that fails logs the error (window/logMessage) and answers
with an empty result; a request whose params do not fit the LSP types gets an InvalidParams
error; a crash of the compiler itself shows as one diagnostic at the top of the file. Only
open documents are served (a request about another URI never reads a file).
"""

from __future__ import annotations

import asyncio
import functools
import logging
import sys
import traceback
from typing import BinaryIO, cast
from urllib.parse import unquote

from lsprotocol import types
from pygls.exceptions import JsonRpcException
from pygls.lsp.server import LanguageServer
from pygls.protocol import LanguageServerProtocol

from .. import __version__
from . import convert
from .completion import complete
from .document import Analysis
from .formatting import formatting as format_document
from .hover import hover as hover_at
from .symbols import definition as definition_at
from .symbols import symbols

log = logging.getLogger("modc.lsp")


_DROPPED = object()


class ModcProtocol(LanguageServerProtocol):
    """pygls, made to answer every request: a request whose params do not fit the LSP types
    gets an InvalidParams error response (pygls would only log it, and the client would wait
    forever), and a message that is not a JSON-RPC object is dropped with a log line."""

    def structure_message(self, data):
        try:
            return super().structure_message(data)
        except JsonRpcException as e:
            if isinstance(data.get("id"), (int, str)) and isinstance(data.get("method"), str):
                self._send_response(
                    data["id"], error=types.ResponseError(code=e.code, message=f"{data['method']}: {e.message}")
                )
            log.warning("dropped a malformed %s message", data.get("method", "?"))
            return _DROPPED

    def handle_message(self, message):
        if message is _DROPPED:
            return
        if not hasattr(message, "jsonrpc"):
            log.warning("dropped a message that is not a JSON-RPC object: %.80r", message)
            return
        super().handle_message(message)


class ModcServer(LanguageServer):
    def __init__(self) -> None:
        super().__init__(
            "modc",
            __version__,
            protocol_cls=ModcProtocol,
            text_document_sync_kind=types.TextDocumentSyncKind.Incremental,
        )
        self.analyses: dict[str, tuple[int | None, str, Analysis]] = {}
        self.pending: set[str] = set()
        self.shut_down = False
        self.exit_code = 0

    # --- documents -----------------------------------------------------------------------------
    def analysis(self, uri: str) -> Analysis | None:
        # Only open documents: a request about any other URI must not read arbitrary files.
        doc = self.workspace.text_documents.get(unquote(uri)) if isinstance(uri, str) else None
        if doc is None:
            return None
        text = doc.source
        cached = self.analyses.get(uri)
        if cached is not None and cached[0] == doc.version and cached[1] is text:
            return cached[2]
        enc = self.workspace.position_encoding
        encoding = getattr(enc, "value", enc) or convert.UTF16
        an = Analysis(text, convert.uri_to_path(uri), encoding)
        self.analyses[uri] = (doc.version, text, an)
        return an

    def publish(self, uri: str) -> None:
        self.pending.discard(uri)
        an = self.analysis(uri)
        if an is None:
            return
        try:
            diags = an.diagnostics()
        except Exception as e:  # a compiler bug: say so in the editor instead of going quiet
            self.report(f"modc: checking {uri} failed")
            diags = [convert.internal_error(e)]
        version = self.analyses.get(uri, (None,))[0]
        self.text_document_publish_diagnostics(
            types.PublishDiagnosticsParams(uri=uri, diagnostics=diags, version=version)
        )

    def schedule(self, uri: str) -> None:
        """Publish on the next turn of the event loop, once per burst of changes."""
        if uri in self.pending:
            return
        self.pending.add(uri)
        try:
            asyncio.get_running_loop().call_soon(self.publish, uri)
        except RuntimeError:  # no loop (called outside the server): publish now
            self.publish(uri)

    def report(self, what: str) -> None:
        message = f"{what}\n{traceback.format_exc()}"
        log.error(message)
        try:
            self.window_log_message(types.LogMessageParams(type=types.MessageType.Error, message=message))
        except Exception:
            pass


server = ModcServer()


def guarded(empty):
    """Run a handler; on an exception log it and answer `empty` instead."""

    def wrap(fn):
        @functools.wraps(fn)
        def run(ls: ModcServer, params):
            try:
                return fn(ls, params)
            except Exception:
                ls.report(f"modc: {fn.__name__} failed")
                return empty

        return run

    return wrap


@server.feature(types.SHUTDOWN)
def on_shutdown(ls: ModcServer, params) -> None:
    ls.shut_down = True


@server.feature(types.EXIT)
def on_exit(ls: ModcServer, params) -> None:
    # The LSP spec: exit after shutdown -> 0, without -> 1 (pygls swallows its own SystemExit).
    ls.exit_code = 0 if ls.shut_down else 1


def _at(ls: ModcServer, params) -> tuple[Analysis | None, int]:
    an = ls.analysis(params.text_document.uri)
    if an is None:
        return None, 0
    return an, an.index.offset(params.position)


@server.feature(types.TEXT_DOCUMENT_DID_OPEN)
@guarded(None)
def did_open(ls: ModcServer, params: types.DidOpenTextDocumentParams):
    ls.publish(params.text_document.uri)


@server.feature(types.TEXT_DOCUMENT_DID_CHANGE)
@guarded(None)
def did_change(ls: ModcServer, params: types.DidChangeTextDocumentParams):
    ls.schedule(params.text_document.uri)


@server.feature(types.TEXT_DOCUMENT_DID_SAVE)
@guarded(None)
def did_save(ls: ModcServer, params: types.DidSaveTextDocumentParams):
    ls.schedule(params.text_document.uri)  # a relative `library "x.yaml"` may have changed


@server.feature(types.TEXT_DOCUMENT_DID_CLOSE)
@guarded(None)
def did_close(ls: ModcServer, params: types.DidCloseTextDocumentParams):
    uri = params.text_document.uri
    ls.analyses.pop(uri, None)
    ls.pending.discard(uri)
    ls.text_document_publish_diagnostics(types.PublishDiagnosticsParams(uri=uri, diagnostics=[]))


@server.feature(types.TEXT_DOCUMENT_HOVER)
@guarded(None)
def hover(ls: ModcServer, params: types.HoverParams):
    an, offset = _at(ls, params)
    return hover_at(an, offset) if an is not None else None


def capability(capabilities: object, dotted: str, default: object = None) -> object:
    """One client capability by its dotted path; default where the client leaves any part out."""
    node = capabilities
    for name in dotted.split("."):
        node = getattr(node, name, None)
        if node is None:
            return default
    return node


@server.feature(types.TEXT_DOCUMENT_COMPLETION, types.CompletionOptions(trigger_characters=["(", ",", "-", "="]))
@guarded([])
def completion(ls: ModcServer, params: types.CompletionParams):
    an, offset = _at(ls, params)
    if an is None:
        return []
    snippets = capability(ls.client_capabilities, "text_document.completion.completion_item.snippet_support", False)
    return complete(an, offset, bool(snippets))


@server.feature(types.TEXT_DOCUMENT_DOCUMENT_SYMBOL)
@guarded([])
def document_symbol(ls: ModcServer, params: types.DocumentSymbolParams):
    an = ls.analysis(params.text_document.uri)
    return symbols(an) if an is not None else []


@server.feature(types.TEXT_DOCUMENT_DEFINITION)
@guarded([])
def definition(ls: ModcServer, params: types.DefinitionParams):
    an, offset = _at(ls, params)
    return definition_at(an, offset, params.text_document.uri) if an is not None else []


@server.feature(types.TEXT_DOCUMENT_FORMATTING)
@guarded([])
def formatting(ls: ModcServer, params: types.DocumentFormattingParams):
    an = ls.analysis(params.text_document.uri)
    return format_document(an) if an is not None else []


def serve() -> None:
    """Run the server on stdin/stdout until the client says exit (or closes the pipe)."""
    from .logs import configure
    from .transport import FramedReader

    configure()  # bounded: a client sending garbage cannot fill the disk with tracebacks
    stdin, stdout = sys.stdin.buffer, sys.stdout.buffer
    sys.stdout = sys.stderr  # a stray print() anywhere must never corrupt the protocol stream
    # only well-formed frames reach pygls (it reads through readline() and read(n), all FramedReader has)
    server.start_io(cast(BinaryIO, FramedReader(stdin)), stdout)
    if server.exit_code:
        sys.exit(server.exit_code)
