"""`modc design FILE -o DIR`: ranked module chains for the `design` blocks of FILE."""
from __future__ import annotations

import sys
from contextlib import contextmanager, nullcontext

import click

from .. import names
from .app import EXIT_ERRORS, EXIT_USAGE, _err, _print_diagnostics, app, argument, library_option, usage_errors

RENDERED = 3  # pictures of the top designs in report.html


def _cap_workers(_ctx: click.Context, _param: click.Parameter, value: int) -> int:
    """More processes than CPUs only add memory and switching: cap at the CPUs this process may use."""
    import os

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

        with ProcessPoolExecutor(max_workers=workers) as pool:
            yield pool
    else:
        yield None


@contextmanager
def _progress(enabled: bool, name: str):
    """A rich progress line on stderr (a TTY only): twist settings screened per second, the best design so far."""
    if not enabled:
        yield None
        return
    from rich.progress import Progress, SpinnerColumn, TextColumn, TimeElapsedColumn

    with Progress(SpinnerColumn(), TextColumn("{task.description}"), TimeElapsedColumn(), transient=True,
                  console=__import__("rich.console", fromlist=["Console"]).Console(stderr=True)) as bar:
        import time

        task = bar.add_task(f"design {name}", total=None)
        start = time.perf_counter()

        def update(evaluated: int, shapes: int, best: str) -> None:
            rate = evaluated / max(time.perf_counter() - start, 1e-9)
            bar.update(task, description=f"{name}: {evaluated:,} screened ({rate:,.0f}/s), {shapes} shapes; "
                                         f"best {best or '—'}")
        yield update


def _renders(files: dict, names: list[str]) -> dict[str, bytes]:
    """PNG pictures of the given design files, each at its first target's pose."""
    import tempfile
    from pathlib import Path

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
    library: str | None,
    force: bool,
) -> None:
    """Find the best module chains for the cells and targets of FILE's design blocks."""
    import json

    from ..compiler import InputError, check_file, inputs_of
    from ..design import run as search
    from ..design.write import files as design_files
    from ..design.write import ranking, summary_line
    from ..diagnostics import codes
    from ..outputs import check_output_dir, write_tree

    try:
        checked = check_file(file, library)
    except InputError as e:
        _print_diagnostics([e.diagnostic], {})
        raise SystemExit(EXIT_USAGE) from None
    _print_diagnostics(checked.diagnostics, checked.sources)
    if not checked.ok:
        raise SystemExit(EXIT_ERRORS)
    problems = checked.design.problems
    if not problems:
        _err(f"modc design: {file} has no `design NAME {{ … }}` block")
        raise SystemExit(EXIT_USAGE)
    inputs = inputs_of(file, library, checked)
    with usage_errors("design", writing=out):  # before the search: a refused DIR costs no minutes
        check_output_dir(out, inputs, force)
    outcomes, failed = [], []
    tty = sys.stderr.isatty()
    with usage_errors("design", usage=(ValueError, OSError)), _executor(workers, scheduler) as executor:
        for p in problems:
            with _progress(tty, p.name) if tty else nullcontext() as bar:
                o = search.design(p, max_units=max_units, top=top, seed=seed, executor=executor, progress=bar)
            if not o.designs:
                assert p.cell.library is not None
                hi = min(max_units or p.max_units, p.cell.library.rules.max_dof)
                units = f"{p.min_units} to {hi}" if hi > p.min_units else f"{hi}"
                failed.append(codes.NO_DESIGN.at(p.name_span, units=units, name=p.name, closest=o.why_none()))
            outcomes.append(o)
    if failed:
        _print_diagnostics(failed, checked.sources)
        _err(f"modc design: no design found; nothing written to {out}")
        raise SystemExit(EXIT_ERRORS)
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
