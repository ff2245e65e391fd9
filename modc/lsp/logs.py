"""The language server's error log (stderr, which editors keep in a file or panel), bounded
whatever the client sends: 150 s of garbage input used to write 79 MB, a pygls traceback for
every bad frame.

- a message kind (logger, message template, exception type) is written in full the first
  time, traceback included; its next REPEATS - 1 times as one line without the traceback;
  after that only at counts 10, 100, 1000, ... with the count;
- one record is cut to MAX_RECORD characters;
- past BUDGET characters in all, one last line says so and the log stays quiet.
"""
from __future__ import annotations

import logging
import threading
from typing import TextIO

BUDGET = 1_000_000  # characters written in the server's life
MAX_RECORD = 8_000  # characters of one record (a first traceback fits)
REPEATS = 3  # times a kind is written before it is only counted
MAX_KINDS = 1_000  # kinds remembered; later new kinds share one count
FORMAT = "modc lsp: %(message)s"
NOTICE_ROOM = 120  # characters kept for the line saying the log is full


def _kind(record: logging.LogRecord) -> tuple[str, str, str]:
    exc = record.exc_info[0].__name__ if record.exc_info and record.exc_info[0] else ""
    template = record.msg if isinstance(record.msg, str) else type(record.msg).__name__
    return (record.name, template.split("\n", 1)[0][:200], exc)


def _one_line(record: logging.LogRecord) -> logging.LogRecord:
    """The record without its traceback, its message's first line (plus the exception's own)."""
    copy = logging.makeLogRecord(record.__dict__)
    text = record.getMessage().split("\n", 1)[0]
    if record.exc_info and record.exc_info[1] is not None:
        exc = record.exc_info[1]
        text += f" ({type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''})"[:300]
    copy.msg, copy.args, copy.exc_info, copy.exc_text, copy.stack_info = text, None, None, None, None
    return copy


class BoundedHandler(logging.StreamHandler):
    def __init__(self, stream: TextIO | None = None, budget: int = BUDGET):
        super().__init__(stream)
        self.setFormatter(logging.Formatter(FORMAT))
        self.budget = budget
        self.written = 0
        self.counts: dict[tuple[str, str, str], int] = {}
        self.full = False
        self._guard = threading.Lock()

    def emit(self, record: logging.LogRecord) -> None:
        with self._guard:
            key = _kind(record)
            if key not in self.counts and len(self.counts) >= MAX_KINDS:
                key = ("", "other messages", "")
            n = self.counts[key] = self.counts.get(key, 0) + 1
            if n > REPEATS and not _milestone(n):
                return
            if n > 1:
                record = _one_line(record)
                if n > REPEATS:
                    record.msg = f"{record.msg} [{n} times so far; repeats are counted, not written]"
            text = self.format(record)
            if len(text) > MAX_RECORD:
                text = text[:MAX_RECORD] + f" … [{len(text) - MAX_RECORD} characters cut]"
            if self.full:
                return
            if self.written + len(text) + 1 > self.budget - NOTICE_ROOM:
                self.full = True
                text = f"modc lsp: the log has reached {self.budget:,} characters; further messages are dropped"
            self.written += len(text) + 1
            try:
                self.stream.write(text + "\n")
                self.flush()
            except (OSError, ValueError):  # stderr closed by the editor: nothing to tell
                pass


def _milestone(n: int) -> bool:
    """10, 100, 1000, ..."""
    while n % 10 == 0 and n > 1:
        n //= 10
    return n == 1


def configure(stream: TextIO | None = None) -> BoundedHandler:
    """Route every logger of the server process (modc's, pygls') through one bounded handler."""
    handler = BoundedHandler(stream)
    logging.basicConfig(level=logging.WARNING, handlers=[handler], force=True)
    return handler
