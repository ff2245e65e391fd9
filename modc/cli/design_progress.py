"""Progress of `modc design` on stderr: a live rich display on a terminal, a plain line at least
every PLAIN_EVERY seconds otherwise (CI logs), nothing with -q."""
from __future__ import annotations

import sys
import time
from contextlib import contextmanager
from typing import Any

PLAIN_EVERY = 10.0  # s between plain lines (at most; the first comes at once)


def _duration(s: float | None) -> str:
    if s is None:
        return "—"
    s = int(round(s))
    return f"{s // 3600}h{s % 3600 // 60:02d}m" if s >= 3600 else f"{s // 60}m{s % 60:02d}s" if s >= 60 else f"{s}s"


def line(name: str, st) -> str:
    if st.doing:
        return f"{name}: {st.doing} ({st.best}); {st.shapes_done} shapes searched"
    return (f"{name}: {st.shapes_done}/{st.shapes_total} shapes, {st.screened:,} settings screened or excluded, "
            f"{st.feasible} feasible, best {st.best or '—'}, ETA {_duration(st.eta)}")


@contextmanager
def _plain(name: str):
    """Plain lines: each status when PLAIN_EVERY has passed since the last line, and the last
    status again (with the time spent on it) when nothing new came for PLAIN_EVERY - a design's
    planning or a large block of settings can take longer - so a CI log never goes quiet."""
    import threading

    from .common import ticking

    lock = threading.Lock()
    last: dict[str, Any] = {"at": -1e9, "text": "", "since": time.monotonic()}

    def say(text: str, status: str) -> None:
        print(f"modc design: {text}", file=sys.stderr, flush=True)
        last["at"], last["said"] = time.monotonic(), status

    def plain(st, force: bool = False) -> None:
        with lock:
            text = line(name, st)
            if text != last["text"]:
                last["text"], last["since"] = text, time.monotonic()
            if force or time.monotonic() - last["at"] >= PLAIN_EVERY:
                say(text, text)

    def heartbeat() -> None:
        # the status as it is now; "still at it" only when it has not changed since the last line
        with lock:
            now = time.monotonic()
            text = last["text"]
            if text and now - last["at"] >= PLAIN_EVERY:
                say(text if text != last.get("said") else f"{text} (still at it, {_duration(now - last['since'])})",
                    text)

    with ticking(min(1.0, PLAIN_EVERY / 4), heartbeat, "modc-design-progress"):
        yield plain


@contextmanager
def progress(mode: str, name: str):
    """mode: 'live' (rich, a terminal), 'plain' or 'off'. Yields the callback run.design calls."""
    if mode == "off":
        yield None
        return
    if mode == "plain":
        with _plain(name) as plain:
            yield plain
        return
    from rich.console import Console
    from rich.live import Live

    with Live("", console=Console(stderr=True), refresh_per_second=4, transient=True) as live:
        def update(st, force: bool = False) -> None:
            live.update(line(name, st))

        yield update
