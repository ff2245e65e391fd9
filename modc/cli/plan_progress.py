"""Progress of `modc plan --task` on stderr, as `modc design` shows its own (design_progress.py):
a live rich line on a terminal, a plain line at least every PLAIN_EVERY seconds otherwise (one
segment's search can take the whole --timeout, so a ticker thread writes them, not the planner),
nothing with -q."""
from __future__ import annotations

import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager

from .design_progress import PLAIN_EVERY, _duration


class Status:
    """Where the task's planning is: the segment being planned and since when."""

    def __init__(self, task: str):
        self.task = task
        self.start = time.monotonic()
        self.lock = threading.Lock()
        self.number, self.total, self.kind, self.a, self.b = 0, 0, "", "", ""

    def __call__(self, number: int, total: int, kind: str, a: str, b: str) -> None:
        """modc.plan.task's progress hook."""
        with self.lock:
            self.number, self.total, self.kind, self.a, self.b = number, total, kind, a, b

    def line(self) -> str:
        with self.lock:
            number, total, kind, a, b = self.number, self.total, self.kind, self.a, self.b
        spent = _duration(time.monotonic() - self.start)
        if total == 0:
            return f"task '{self.task}': reading the file, {spent}"
        if kind == "done":
            return f"task '{self.task}': {total - 1} segment(s) planned and timed, {spent}"
        what = "approach" if kind == "approach" else f"segment {number} of {total - 1}"
        return f"task '{self.task}': planning the {what} ({a} -> {b}), {spent}"

    def __rich__(self):  # rich's Live redraws this at every refresh: the time ticks on
        from rich.text import Text

        return Text(self.line())  # plain text: a target named tray[1,0,0] is no markup


@contextmanager
def progress(mode: str, task: str) -> Iterator[Status | None]:
    """mode: 'live' (rich, a terminal), 'plain' or 'off'. Yields the hook for plan_task."""
    if mode == "off":
        yield None
        return
    status = Status(task)
    if mode == "plain":
        from .common import ticking

        def say() -> None:
            print(f"modc plan: {status.line()}", file=sys.stderr, flush=True)

        say()
        with ticking(PLAIN_EVERY, say, "modc-plan-progress"):
            yield status
        if status.kind == "done":
            print(f"modc plan: {status.line()}", file=sys.stderr, flush=True)
        return
    from rich.console import Console
    from rich.live import Live

    with Live(status, console=Console(stderr=True), refresh_per_second=4, transient=True):
        yield status
