"""The language server's input, checked before pygls sees it.

pygls reads `Content-Length: N` and then N bytes, trusting N: `Content-Length:
99999999999999999999` killed the server, and a header it could not read made it skip to the
next blank line, swallowing the following message. FramedReader sits in front of it (pygls
reads through its readline() and read(n)) and hands on only well-formed frames, re-written
canonically: header lines of bounded length, a Content-Length of at most MAX_BODY bytes. A frame
that breaks these rules is dropped with a log line, and reading resumes at the next
`Content-Length:` header, so the message after a bad one is still served. Memory stays bounded
by MAX_BODY whatever arrives.
"""
from __future__ import annotations

import logging
import re
from typing import BinaryIO

log = logging.getLogger("modc.lsp")

MAX_HEADER_LINE = 1024  # bytes; real headers are ~50
MAX_HEADERS = 16  # lines in one header block (LSP defines two)
MAX_BODY = 64 * 1024 * 1024  # bytes; a .mod file is at most 256 kB, JSON-escaped a few times that
_LENGTH = re.compile(rb"Content-Length:[ \t]*([0-9]{1,12})[ \t]*\r?\n\Z", re.I)
_RESYNC = re.compile(rb"Content-Length:", re.I)


class FramedReader:
    """A binary reader (readline(), read(n)) giving pygls only valid frames from `raw`."""

    def __init__(self, raw: BinaryIO):
        self.raw = raw
        self.pending = b""  # canonical frames not yet handed on
        self.carry = b""  # input read ahead while resynchronising
        self.dropped = 0  # frames refused, for tests and logs

    # --- pygls' side ---------------------------------------------------------------------------
    def readline(self, limit: int = -1) -> bytes:
        if not self.pending:
            self.pending = self._frame()
        end = self.pending.find(b"\n") + 1 or len(self.pending)
        line, self.pending = self.pending[:end], self.pending[end:]
        return line

    def read(self, n: int = -1) -> bytes:
        if n < 0:
            n = len(self.pending)
        out, self.pending = self.pending[:n], self.pending[n:]
        return out

    # --- the raw side ----------------------------------------------------------------------------
    def _line(self) -> bytes:
        """One input line of at most MAX_HEADER_LINE bytes (longer: its rest is read and dropped)."""
        if self.carry:
            end = self.carry.find(b"\n") + 1 or len(self.carry)
            line, self.carry = self.carry[:end], self.carry[end:]
            if line.endswith(b"\n") or not line:
                return line
            return line + self.raw.readline(MAX_HEADER_LINE + 1)
        return self.raw.readline(MAX_HEADER_LINE + 1)

    def _frame(self) -> bytes:
        """The next valid frame, canonical (`Content-Length: N\\r\\n\\r\\n` + body); b'' at end of input."""
        while True:
            length, ok, count = None, True, 0
            while True:
                line = self._line()
                if not line:
                    return b""
                count += 1
                if not line.strip():
                    break
                later = _RESYNC.search(line, 1)
                if later is not None:  # garbage, then a header: drop the garbage, start there
                    self.carry = line[later.start():] + self.carry
                    ok, length = False, None
                    break
                if len(line) > MAX_HEADER_LINE or not line.endswith(b"\n") or count > MAX_HEADERS:
                    ok = False
                    continue
                m = _LENGTH.match(line)
                if m is not None:
                    length = int(m.group(1))
                elif line[:15].lower() == b"content-length:" or b":" not in line:
                    ok = False  # an unreadable length, or not a header at all
            if ok and length is not None and 0 < length <= MAX_BODY:
                body = self._read_body(length)
                if len(body) < length:
                    return b""  # the input ended inside the body
                return b"Content-Length: %d\r\n\r\n" % length + body
            self.dropped += 1
            log.warning("dropped a message with an unusable header (Content-Length %s)",
                        "missing" if length is None else f"{length:,}" if length <= MAX_BODY else "too large")
            if not _RESYNC.match(self.carry) and not self._resync():
                return b""

    def _read_body(self, n: int) -> bytes:
        out = self.carry[:n]
        self.carry = self.carry[n:]
        while len(out) < n:
            chunk = self.raw.read(n - len(out))
            if not chunk:
                break
            out += chunk
        return out

    def _resync(self) -> bool:
        """Skip the body of a refused frame: read on to the next `Content-Length:` header (the
        body has no length we can trust). False at end of input."""
        tail = b""  # the end of the previous piece: a header may straddle two pieces of a long line
        while True:
            line = self._line()
            if not line:
                return False
            text = tail + line
            m = _RESYNC.search(text)
            if m is not None:
                self.carry = text[m.start():] + self.carry
                return True
            tail = b"" if line.endswith(b"\n") else text[-14:]
