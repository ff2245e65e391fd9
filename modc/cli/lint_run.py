"""`modc lint`'s work, and its command line read without click when that is plain: a pre-commit
hook or a CI check runs `modc lint FILES [-f FORMAT] [-q] [--library L] [--sarif-root DIR]`
many times, and click's import was a fifth of the command's start-up (benchmarks/bench_startup.py).
Anything else (--help, a mistake, an unusual spelling) goes to the click command in
modc.cli.lint, which reads it as before.
"""
from __future__ import annotations

from .. import __version__
from .common import EXIT_ERRORS, EXIT_OK, EXIT_USAGE, Verbosity, _err, _expand, _print_diagnostics, run_like_click

FORMATS = ("text", "json", "github", "sarif")
# option -> (its name in run(), the values it takes or None for any, or "flag")
_OPTIONS = {"-f": ("format", FORMATS), "--format": ("format", FORMATS), "--library": ("library", None),
            "--sarif-root": ("sarif_root", None), "-q": ("quiet", "flag"), "--quiet": ("quiet", "flag")}


def plain_args(args: list[str]) -> dict | None:
    """run()'s arguments when args are a plain lint command line (every word an option spelled
    as in `modc lint --help` or a file, each option at most once, at least one file); else None."""
    options: dict = {"files": []}
    words = iter(args)
    for word in words:
        if not word.startswith("-"):
            options["files"].append(word)
            continue
        name, _, inline = word.partition("=") if word.startswith("--") else (word, "", "")
        spec = _OPTIONS.get(name)
        if spec is None or spec[0] in options:
            return None
        key, values = spec
        if values == "flag":
            if inline or "=" in word:
                return None
            options[key] = True
            continue
        value = inline if "=" in word else next(words, None)
        if value is None or value.startswith("-") or (values is not None and value not in values):
            return None
        options[key] = value
    return options if options["files"] else None


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
