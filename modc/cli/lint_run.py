"""`modc lint`'s work, and its command line read without click when that is plain: a pre-commit
hook or a CI check runs `modc lint FILES [-f FORMAT] [-q] [--library L] [--sarif-root DIR]`
many times, and click's import was a fifth of the command's start-up (benchmarks/bench_startup.py).
Anything else (--help, a mistake, an unusual spelling) goes to the click command in
modc.cli.lint, which reads it as before.
"""
from __future__ import annotations

from .. import __version__
from .common import (
    EXIT_ERRORS,
    EXIT_OK,
    EXIT_USAGE,
    Verbosity,
    _err,
    _expand,
    _print_diagnostics,
    read_plain,
    run_like_click,
)

FORMATS = ("text", "json", "github", "sarif")
# option -> (its name in run(), the values it takes or None for any, or the flag's value): common.read_plain
_OPTIONS = {"-f": ("format", FORMATS), "--format": ("format", FORMATS), "--library": ("library", None),
            "--sarif-root": ("sarif_root", None), "-q": ("quiet", True), "--quiet": ("quiet", True)}


def plain_args(args: list[str]) -> dict | None:
    """run()'s arguments when args are a plain lint command line (every word an option spelled
    as in `modc lint --help` or a file, each option at most once, at least one file); else None."""
    def files(options: dict, word: str) -> bool:
        options.setdefault("files", []).append(word)
        return True

    options = read_plain(args, _OPTIONS, files)
    return options if options is not None and options.get("files") else None


def run(files, format: str = "text", library: str | None = None, quiet: bool = False,
        sarif_root: str = ".") -> None:
    """Check files without writing anything; always ends in SystemExit (0, 1 errors, 2 I/O)."""
    from ..compiler import InputError, check_file
    from ..diagnostics.render import render_github, render_json, render_sarif, summary

    Verbosity.quiet = quiet
    diags, sources, io_error = [], {}, False
    paths = _expand(files, "modc lint")
    for path in paths:
        try:
            c = check_file(path, library)
        except InputError as e:
            diags.append(e.diagnostic)
            io_error = True
            continue
        diags += c.diagnostics
        sources.update(c.sources)
    shown = [d for d in diags if not (quiet and not d.is_error)]
    if format == "json":
        print(render_json(shown))
    elif format == "github":
        if shown:
            print(render_github(shown))
    elif format == "sarif":
        print(render_sarif(shown, __version__, root=sarif_root, sources=sources))
    else:
        _print_diagnostics(diags, sources)
        if not quiet:
            _err(f"modc lint: {len(paths)} file{'s' * (len(paths) != 1)}, {summary(diags)}")
    if io_error:
        raise SystemExit(EXIT_USAGE)
    raise SystemExit(EXIT_ERRORS if any(d.is_error for d in diags) else EXIT_OK)


def run_plain(options: dict) -> None:
    """run(), ending as click ends a command (common.run_like_click)."""
    run_like_click(run, options, "lint")
