"""`modc design FILE -o DIR`: ranked module chains for the `design` blocks of FILE."""
from __future__ import annotations

import os
import signal
import sys
import time
from contextlib import contextmanager
from pathlib import Path

import click

from .. import names
from .app import EXIT_ERRORS, EXIT_USAGE, _err, _print_diagnostics, app, argument, library_option, usage_errors

RENDERED = 3  # pictures of the top designs in report.html
EXIT_INTERRUPTED = 130


def _budget(text: str | None) -> float | None:
    """'90s', '5m', '1h', '1.5m' or a number of seconds -> seconds."""
    if text is None:
        return None
    t = text.strip().lower()
    scale = {"s": 1.0, "m": 60.0, "h": 3600.0}.get(t[-1:], None)
    try:
        value = float(t[:-1] if scale else t) * (scale or 1.0)
    except ValueError:
        raise click.BadParameter(f"'{text}' is not a duration (e.g. 90s, 5m, 1h)") from None
    if not value > 0 or value == float("inf"):
        raise click.BadParameter(f"'{text}' is not a positive duration")
    return value


@contextmanager
def _sigint_stops():
    """Ctrl-C stops the search where it is (the best designs found are kept); a second one ends
    modc at once."""
    from ..design.search import STOP

    STOP.clear()

    def handler(signum, frame):
        if STOP.is_set():
            raise KeyboardInterrupt
        STOP.set()

    try:
        old = signal.signal(signal.SIGINT, handler)
    except ValueError:  # not the main thread: leave Ctrl-C alone
        old = None
    try:
        yield STOP
    finally:
        if old is not None:
            signal.signal(signal.SIGINT, old)


def _search_all(problems, max_units, top, seed, workers, scheduler, deadline, mode):
    """Every design block searched in turn (until one stops): the outcomes, a no-design diagnostic
    per block without a design, and whether Ctrl-C stopped it."""
    from ..design import run as search
    from ..design.diagnose import blamed_statement
    from ..diagnostics import codes
    from ..formatting import counted
    from .design_progress import progress as show_progress

    outcomes: list[search.Outcome] = []
    failed = []
    with usage_errors("design", usage=(ValueError, OSError)), _executor(workers, scheduler) as executor, \
            _sigint_stops() as stop:
        for p in problems:
            if outcomes and outcomes[-1].stopped:  # out of time or interrupted: said, not searched
                outcomes.append(search.Outcome(p, [], stopped=outcomes[-1].stopped, complete=False, searched=False))
                continue
            with show_progress(mode, p.name) as bar:
                o = search.design(p, max_units=max_units, top=top, seed=seed, executor=executor, progress=bar,
                                  deadline=deadline)
            if not o.designs:
                hi = min(max_units or p.max_units, p.cell.library.rules.max_dof)
                units = f"{p.min_units} to {hi} units" if hi > p.min_units else counted(hi, "unit")
                blamed = blamed_statement(o)  # a task every candidate failed, a region no design reaches
                failed.append(codes.NO_DESIGN.at(p.name_span if blamed is None else blamed.span, units=units,
                                                 name=p.name, closest=o.why_none()))
            outcomes.append(o)
    return outcomes, failed, stop.is_set()


def _cap_workers(_ctx: click.Context, _param: click.Parameter, value: int) -> int:
    """More processes than CPUs only add memory and switching: cap at the CPUs this process may use."""

    cpus = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
    if value > cpus:
        _err(f"modc design: --workers {value} capped at {cpus}, the CPUs this process may use")
    return min(value, cpus)


# what `distributed` connects to without extra packages or TLS settings (inproc: a cluster in
# this same process, as the API and the tests start one)
SCHEDULER_SCHEMES = ("tcp", "inproc")


def _scheduler(_ctx: click.Context, _param: click.Parameter, value: str | None) -> str | None:
    scheme = value.partition("://")[0] if value is not None and "://" in value else "tcp"
    if scheme not in SCHEDULER_SCHEMES:
        raise click.BadParameter(f"the scheme '{names.shown(scheme, 20)}://' is not supported; give tcp://HOST:PORT")
    return value


@contextmanager
def _executor(workers: int, scheduler: str | None):
    """None (this process), a local process pool, or a Dask cluster's executor: one interface."""
    if scheduler:
        from distributed import Client

        with Client(scheduler) as client:
            yield client.get_executor()
    elif workers > 1:
        from concurrent.futures import ProcessPoolExecutor

        from ..design.search import STOP

        # workers ignore Ctrl-C: the main process stops the search and keeps what was found
        pool = ProcessPoolExecutor(max_workers=workers, initializer=signal.signal,
                                   initargs=(signal.SIGINT, signal.SIG_IGN))
        try:
            yield pool
        finally:
            if STOP.is_set():  # Ctrl-C: what the workers are still screening is not wanted
                _end_workers(pool)
            pool.shutdown(wait=True, cancel_futures=True)
    else:
        yield None


def _end_workers(pool) -> None:
    """End a process pool's workers at once: a shutdown waits for the ranges they are screening
    (seconds each), and the pool has no public way to stop them before Python 3.14."""
    end = getattr(pool, "terminate_workers", None)
    if end is not None:
        end()
        return
    for proc in list((getattr(pool, "_processes", None) or {}).values()):
        proc.terminate()


def _renders(files: dict, names: list[str]) -> dict[str, bytes]:
    """PNG pictures of the given design files, each at its first target's pose."""
    import tempfile

    from ..sim.render import render

    out: dict[str, bytes] = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name in names:
            src = Path(tmp) / name
            src.write_text(files[name], encoding="utf-8")
            text = files[name]
            pose = next((ln.split()[1] for ln in text.splitlines() if ln.strip().startswith("pose ")), None)
            png = Path(tmp) / (name + ".png")
            ok, _, _ = render(str(src), str(png), pose=pose, width=400, height=300)
            if ok:
                out[name] = png.read_bytes()
    return out


@app.command("design")
@argument("file", help=".mod file with `design NAME { … }` blocks")
@click.option("-o", "--out", required=True, help="output directory: ranking.json, .mod files, report.html")
@click.option("--max-units", type=click.IntRange(min=1), help="largest chain, over `units`")
@click.option("--top", type=click.IntRange(min=1), default=5, help="designs to keep")
@click.option("--seed", type=click.IntRange(min=0), default=0, help="same file and seed, same ranking")
@click.option("--workers", type=click.IntRange(min=1), default=1, callback=_cap_workers,
              help="local worker processes (at most the CPU count)")
@click.option("--scheduler", callback=_scheduler, help="run on a Dask cluster: tcp://host:8786")
@click.option("--json", "json_out", is_flag=True, help="print ranking.json on stdout")
@click.option("--render/--no-render", default=True, help="pictures of the top designs")
@click.option("--time-budget", "time_budget", metavar="DURATION",
              help="stop after this long (90s, 5m, 1h) with the best designs found")
@click.option("-q", "--quiet", is_flag=True, help="no progress display")
@library_option
@click.option("--force/--no-force", default=False, help="replace DIR even if modc did not create it")
def design_cmd(
    file: str,
    out: str,
    max_units: int | None,
    top: int,
    seed: int,
    workers: int,
    scheduler: str | None,
    json_out: bool,
    render: bool,
    time_budget: str | None,
    quiet: bool,
    library: str | None,
    force: bool,
) -> None:
    """Find the best module chains for the cells and targets of FILE's design blocks."""
    from ..compiler import inputs_of
    from ..outputs import check_output_dir

    checked = _checked(file, library)
    _needs_full()
    problems = checked.design.resolved_problems()
    if not problems:
        _err(f"modc design: {file} has no `design NAME {{ … }}` block")
        raise SystemExit(EXIT_USAGE)
    inputs = inputs_of(file, library, checked)
    with usage_errors("design", writing=out):  # before the search: a refused DIR costs no minutes
        check_output_dir(out, inputs, force)
    budget = _budget(time_budget)
    deadline = None if budget is None else time.time() + budget
    mode = "off" if quiet else "live" if sys.stderr.isatty() else "plain"
    try:
        outcomes, failed, interrupted = _search_all(problems, max_units, top, seed, workers, scheduler, deadline,
                                                    mode)
    except KeyboardInterrupt:  # a second Ctrl-C: at once, nothing written
        _err(f"modc design: interrupted; nothing written to {out}")
        raise SystemExit(EXIT_INTERRUPTED) from None
    for o in outcomes:
        if o.stopped:
            _err(f"modc design: {o.problem.name}: {_stopped_text(o)}")
    if failed or not outcomes or not any(o.designs for o in outcomes):
        _print_diagnostics(failed, checked.sources)
        _err(f"modc design: no design found; nothing written to {out}")
        raise SystemExit(EXIT_INTERRUPTED if interrupted else EXIT_ERRORS)
    _write(outcomes, out, render, json_out, force, inputs)
    if interrupted:
        raise SystemExit(EXIT_INTERRUPTED)


def _needs_full() -> None:
    """The search checks every design with coal's meshes and plans tasks with pinocchio (the full
    extra): say so before the search, not when its first design is checked."""
    from importlib.util import find_spec

    for name in ("coal", "pinocchio"):
        if find_spec(name) is None:
            raise ModuleNotFoundError(f"No module named '{name}'", name=name)


def _checked(file: str, library: str | None):
    """FILE checked, its diagnostics printed; exit here when it has errors."""
    from ..compiler import InputError, check_file

    try:
        checked = check_file(file, library)
    except InputError as e:
        _print_diagnostics([e.diagnostic], {})
        raise SystemExit(EXIT_USAGE) from None
    _print_diagnostics(checked.diagnostics, checked.sources)
    if not checked.ok:
        raise SystemExit(EXIT_ERRORS)
    return checked


def _write(outcomes, out: str, render: bool, json_out: bool, force: bool, inputs) -> None:
    """The designs' files (and pictures) written to DIR by the one output-safety rule."""
    import json

    from ..design.write import files as design_files
    from ..design.write import ranking, summary_line
    from ..outputs import write_tree

    tree = design_files(outcomes)
    if render:
        names = [f for f in tree if f.endswith(".mod")]
        picks = [n for o in outcomes for n in names if n.startswith(f"{o.problem.name}_")][:RENDERED * len(outcomes)]
        tree = design_files(outcomes, _renders(tree, picks))
    with usage_errors("design", writing=out):
        write_tree(tree, out, force=force, inputs=inputs)
    if json_out:
        print(json.dumps(ranking(outcomes), indent=2))
    for o in outcomes:
        _err(f"modc design: {summary_line(o)}")
    _err(f"modc design: {len(tree)} files written to {out}")


def _stopped_text(o) -> str:
    from ..formatting import counted

    why = "the time budget ran out" if o.stopped == "time budget" else "interrupted (Ctrl-C)"
    if not o.searched:
        return f"not searched: {why} before this design block"
    shown = ", ".join(o.unfinished[:8]) + (f" and {len(o.unfinished) - 8:,} more" if len(o.unfinished) > 8 else "")
    said = f"{why}; {counted(len(o.unfinished), 'shape')} not finished" + (f": {shown}" if o.unfinished else "")
    if o.not_planned:
        listed = ", ".join(o.not_planned[:5]) + (f" and {len(o.not_planned) - 5} more" if len(o.not_planned) > 5
                                                 else "")
        said += f"; {counted(len(o.not_planned), 'design')} found but not planned and timed: {listed}"
    return said + f"; best designs so far: {len(o.designs)}"



