"""Who may open the page: only a browser that was given this run's secret token, and on the
websocket only the page itself (its Origin is the address modc serves), as Jupyter guards its
notebooks. Without this any web page the user visits could open ws://127.0.0.1:8080 and read the
robot, the file's name, its targets and its diagnostics.

    http://127.0.0.1:PORT/?token=T   the page; its answer sets a cookie holding T (HttpOnly,
                                     SameSite=Strict) that the page's websocket then carries
    anything else                    403, for the page, its assets and the websocket alike
"""
from __future__ import annotations

import contextlib
import hmac
import http
import logging
import secrets
import threading
from collections.abc import Callable, Iterator
from http.cookies import CookieError, SimpleCookie
from typing import Any
from urllib.parse import parse_qs, urlsplit

TOKEN_PARAM = "token"
_SERVE_LOCK = threading.Lock()  # one viser server starts at a time while its serve() call is wrapped
MESSAGE_CAP = 200  # characters of an exception kept when a connection sends a malformed message


class Guard:
    """This run's token and the one origin the websocket accepts (host as served; the port is
    the one the request came in on, known only once viser has bound it)."""

    def __init__(self, host: str = "127.0.0.1", token: str | None = None):
        self.host = host
        self.token = token or secrets.token_urlsafe(32)

    def url(self, port: int) -> str:
        return f"http://{self.host}:{port}/?{TOKEN_PARAM}={self.token}"

    def origin(self, port: int) -> str:
        return f"http://{self.host}:{port}"

    def cookie_name(self, port: int) -> str:
        return f"modc-view-{port}"  # cookies ignore the port: one name per server on this host

    def _given(self, request, port: int) -> tuple[str | None, bool]:
        """The token the request carries (URL query first, else the cookie) and whether it came in the URL."""
        query = parse_qs(urlsplit(request.path).query)
        if query.get(TOKEN_PARAM):
            return query[TOKEN_PARAM][0], True
        jar: SimpleCookie = SimpleCookie()
        try:
            jar.load(request.headers.get("Cookie", ""))
        except CookieError:
            return None, False
        morsel = jar.get(self.cookie_name(port))
        return (morsel.value if morsel is not None else None), False

    def refusal(self, request, port: int) -> str | None:
        """Why the request is refused, or None to let it through."""
        given, _ = self._given(request, port)
        if given is None or not hmac.compare_digest(given.encode(), self.token.encode()):
            return "this page needs the address modc view printed, with its token"
        if request.headers.get("Upgrade", "").lower() == "websocket" and \
                request.headers.get("Origin") != self.origin(port):
            return "the websocket only accepts the page modc view serves"
        return None

    def wrap(self, inner: Callable | None) -> Callable:
        """viser's process_request, run only for requests that pass; the page's answer sets the cookie."""

        def process_request(connection, request):
            port = connection.local_address[1]
            why = self.refusal(request, port)
            if why is not None:
                return connection.respond(http.HTTPStatus.FORBIDDEN, f"modc view: {why}\n")
            response = inner(connection, request) if inner is not None else None
            if response is not None and response.status_code == http.HTTPStatus.OK and self._given(request, port)[1]:
                response.headers["Set-Cookie"] = (f"{self.cookie_name(port)}={self.token}; Path=/; HttpOnly; "
                                                  "SameSite=Strict")
            return response

        return process_request


@contextlib.contextmanager
def guarding(guard: Guard) -> Iterator[list[bool]]:
    """viser (1.1) has no public hook on the requests it serves: it hands its own process_request
    to websockets.asyncio.server.serve while ViserServer() starts. This wraps that one call so
    every request passes the guard first; the list it yields gets True once viser's serve() went
    through the wrap, and the caller refuses to serve if it did not (a changed viser fails closed)."""
    import websockets.asyncio.server as wss

    used: list[bool] = []
    original = wss.serve

    def serve(handler: Any, *args: Any, process_request: Callable | None = None, **kwargs: Any):
        used.append(True)
        return original(handler, *args, process_request=guard.wrap(process_request), **kwargs)

    with _SERVE_LOCK:
        wss.serve = serve  # type: ignore[misc, assignment]
        try:
            yield used
        finally:
            wss.serve = original  # type: ignore[misc]


class OneLineErrors(logging.Filter):
    """A connection that sends a malformed message is closed by viser's handler raising; websockets
    then logs "connection handler failed" with a full traceback. Keep one line per connection."""

    def filter(self, record: logging.LogRecord) -> bool:
        if record.getMessage() == "connection handler failed" and record.exc_info:
            exc = record.exc_info[1]
            what = f"{type(exc).__name__}: {exc}"[:MESSAGE_CAP] if exc is not None else "unknown error"
            record.msg, record.args = "modc view: closed a connection that sent a malformed message (%s)", (what,)
            record.exc_info, record.exc_text = None, None
        return True


class OneLineHandlerErrors(logging.Filter):
    """A well-formed frame with values viser cannot apply (a GUI update of a missing property, a
    null slider value) fails in viser's message task; asyncio then logs "Task exception was never
    retrieved" with a full traceback per frame. Keep one line per kind of error."""

    def __init__(self) -> None:
        super().__init__()
        self.seen: set[str] = set()

    def filter(self, record: logging.LogRecord) -> bool:
        text = record.getMessage()
        if not (text.startswith("Task exception was never retrieved") and "_handle_incoming_message" in text):
            return True
        exc = record.exc_info[1] if record.exc_info else None
        what = f"{type(exc).__name__}: {exc}"[:MESSAGE_CAP] if exc is not None else "unknown error"
        if what in self.seen:
            return False
        self.seen.add(what)
        record.msg, record.args = "modc view: ignored a message the page cannot apply (%s)", (what,)
        record.exc_info, record.exc_text = None, None
        return True


def quiet_malformed_messages() -> None:
    logger = logging.getLogger("websockets.server")
    if not any(isinstance(f, OneLineErrors) for f in logger.filters):
        logger.addFilter(OneLineErrors())
    tasks = logging.getLogger("asyncio")
    if not any(isinstance(f, OneLineHandlerErrors) for f in tasks.filters):
        tasks.addFilter(OneLineHandlerErrors())
