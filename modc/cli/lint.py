"""`modc lint` and `modc fmt`: checking and formatting .mod files, for CI and editors."""

from __future__ import annotations

import click

from .app import (
    EXIT_ERRORS,
    EXIT_OK,
    EXIT_USAGE,
    _err,
    _expand,
    _print_diagnostics,
    app,
    argument,
    library_option,
)
from .lint_run import FORMATS


@app.command("lint")
@argument("files", nargs=-1, required=True, help=".mod files or directories")
@click.option("-f", "--format", type=click.Choice(list(FORMATS)), default="text",
              help="output format")
@library_option
@click.option("-q", "--quiet", is_flag=True, help="print errors only")
@click.option(
    "--sarif-root",
    metavar="DIR",
    default=".",
    help="with --format sarif: the repository root that paths are relative to (files outside it get absolute "
    "file: URIs)",
)
def lint_cmd(files: tuple[str, ...], format: str, library: str | None, quiet: bool, sarif_root: str) -> None:
    """Check files without writing anything."""
    from .lint_run import run

    run(files, format, library, quiet, sarif_root)


@app.command("fmt")
@argument("files", nargs=-1, required=True, help=".mod files or directories")
@click.option("--check", is_flag=True, help="write nothing; list the files that would change and exit 1 if any")
def fmt_cmd(files: tuple[str, ...], check: bool) -> None:
    """Rewrite .mod files in the canonical layout (comments kept, meaning unchanged)."""
    from ..compiler import YAML_SUFFIXES, InputError, SourceError, read_source
    from ..files import read_bounded
    from ..syntax.format import ChangedOnDisk, FormatterBug, format_text, rewrite_file
    from ..syntax.parser import MAX_BYTES

    diags, sources, io_error, changed = [], {}, False, []
    for path in _expand(files, "modc fmt"):
        if path.endswith(YAML_SUFFIXES):
            _err(f"modc fmt: {path}: only .mod files are formatted")
            io_error = True
            continue
        try:
            # the bytes first: the rewrite happens only if the file still holds them (a save meanwhile wins)
            raw: bytes | None = read_bounded(path, MAX_BYTES)[0]
        except OSError:
            raw = None  # read_source says why
        try:
            text = read_source(path)
        except SourceError as e:  # an error in the file: reported like a syntax error
            diags.append(e.diagnostic)
            if e.text is not None:
                sources[path] = e.text
            continue
        except InputError as e:
            diags.append(e.diagnostic)
            io_error = True
            continue
        try:
            out, errors = format_text(text, path)
        except FormatterBug as e:
            _err(f"modc fmt: internal error: {e}")
            io_error = True
            continue
        if out is None:  # does not parse: reported, never touched
            diags += errors
            sources[path] = text
            continue
        if raw == out.encode("utf-8"):  # (a BOM or CRLF line ends count as a change)
            continue
        changed.append(path)
        if not check:
            try:
                if raw is None:  # unreadable a moment ago, readable now: someone is writing it
                    raise ChangedOnDisk(path)
                rewrite_file(path, out, raw)
            except ChangedOnDisk:
                _err(f"modc fmt: {path}: changed on disk while being formatted; left as saved (run modc fmt again)")
                io_error = True
                continue
            except OSError as e:
                _err(f"modc fmt: {path}: {e.strerror or e}")
                io_error = True
                continue
        print(path)
    _print_diagnostics(diags, sources)
    if io_error:
        raise SystemExit(EXIT_USAGE)
    raise SystemExit(EXIT_ERRORS if diags or (check and changed) else EXIT_OK)
