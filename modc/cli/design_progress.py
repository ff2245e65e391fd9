"""Progress of `modc design` on stderr: a live rich display on a terminal, a plain line at least
every PLAIN_EVERY seconds otherwise (CI logs), nothing with -q."""
from __future__ import annotations

import sys
import time
from contextlib import contextmanager

PLAIN_EVERY = 10.0  # s between plain lines (at most; the first comes at once)


def _duration(s: float | None) -> str:
    if s is None:
        return "—"
    s = int(round(s))
    return f"{s // 3600}h{s % 3600 // 60:02d}m" if s >= 3600 else f"{s // 60}m{s % 60:02d}s" if s >= 60 else f"{s}s"


def line(name: str, st) -> str:
    return (f"{name}: {st.shapes_done}/{st.shapes_total} shapes, {st.screened:,} settings screened or excluded, "
            f"{st.feasible} feasible, best {st.best or '—'}, ETA {_duration(st.eta)}")


@contextmanager
def progress(mode: str, name: str):
    """mode: 'live' (rich, a terminal), 'plain' or 'off'. Yields the callback run.design calls."""
    if mode == "off":
        yield None
        return
    if mode == "plain":
        last = [-1e9]

        def plain(st, force: bool = False) -> None:
            now = time.monotonic()
            if force or now - last[0] >= PLAIN_EVERY:
                last[0] = now
                print(f"modc design: {line(name, st)}", file=sys.stderr, flush=True)

        yield plain
        return
    from rich.console import Console
    from rich.live import Live

    with Live("", console=Console(stderr=True), refresh_per_second=4, transient=True) as live:
        def update(st, force: bool = False) -> None:
            live.update(line(name, st))

        yield update
