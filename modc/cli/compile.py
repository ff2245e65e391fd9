"""`modc FILE -o OUT`: check, build every backend, write OUT atomically."""
from __future__ import annotations

from typing import Annotated, Optional

import typer

from .app import (
    EXIT_ERRORS,
    EXIT_USAGE,
    LibraryOpt,
    TorqueLevel,
    Verbosity,
    _err,
    _print_diagnostics,
    app,
    usage_errors,
)


@app.command("compile")
def compile_cmd(
    file: Annotated[str, typer.Argument(help=".mod file (or its YAML form)")],
    out: Annotated[str, typer.Option("-o", "--out", help="output directory (replaced atomically on success)")],
    library: LibraryOpt = None,
    only: Annotated[Optional[str], typer.Option(help="comma-separated backends to run (default: all); see `modc backends`")] = None,
    force: Annotated[bool, typer.Option(help="replace OUT whatever it holds (deletes files modc did not write)")] = False,
    collision_samples: Annotated[int, typer.Option(min=0, help="random poses for the SRDF collision matrix (MoveIt's default)")] = 10_000,
    seed: Annotated[int, typer.Option(min=0, help="seed of those poses: same file and seed, same SRDF on any machine")] = 0,
    smoke: Annotated[bool, typer.Option("--smoke", help="also run `modc sim` (PyBullet) before writing OUT")] = False,
    torque: Annotated[Optional[TorqueLevel], typer.Option(help="how a joint that cannot hold the arm at peak torque is reported")] = None,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="print errors only")] = False,
    verbose: Annotated[bool, typer.Option("--verbose", "-v", help="list the files written")] = False,
):
    """Check FILE and write URDF, meshes and a report into OUT."""
    from ..compiler import COMPILE_ANALYSES, InputError, build, check_file, write_tree

    Verbosity.quiet, Verbosity.verbose = quiet, verbose
    try:
        checked = check_file(file, library, analyses=COMPILE_ANALYSES, torque_severity=(torque or TorqueLevel.error).value)
    except InputError as e:
        _print_diagnostics([e.diagnostic], {})
        raise typer.Exit(EXIT_USAGE)
    _print_diagnostics(checked.diagnostics, checked.sources)
    if not checked.ok:
        from ..diagnostics.render import summary

        _err(f"modc: {summary(checked.diagnostics)}; nothing written to {out}")
        raise typer.Exit(EXIT_ERRORS)
    selected = None
    if only:
        from ..backends import load_all

        selected = [s.strip() for s in only.split(",") if s.strip()]
        unknown = [s for s in selected if s not in load_all()]
        if unknown:
            _err(f"modc: unknown backend(s) {', '.join(unknown)}; available: {', '.join(load_all())}")
            raise typer.Exit(EXIT_USAGE)
    if smoke:  # before anything is written: a failed smoke test leaves OUT as it was
        from ..sim.smoke import run_sim

        ok, lines, _ = run_sim(file, library=library)
        for line in lines:
            _err(line)
        if not ok:
            _err(f"modc: smoke test failed; nothing written to {out}")
            raise typer.Exit(EXIT_ERRORS)
    files = build(checked, selected, collision_samples=collision_samples, seed=seed)
    with usage_errors("compile", writing=out):
        write_tree(files, out, force=force, inputs=[file])
    if verbose:
        for rel in files:
            _err(f"  wrote {out.rstrip('/')}/{rel}")
    if not quiet:
        robots = ", ".join(f"{r.file_stem} ({r.sequence})" for r in checked.design.robots)
        _err(f"modc: {len(files)} files written to {out}: {robots}")
