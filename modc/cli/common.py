"""What every command shares and what needs no click: exit codes, output, file arguments,
usage errors (the `modc lint` fast path, modc.cli.lint_run, runs on these alone)."""

from __future__ import annotations

import sys
from collections.abc import Callable, Sequence
from contextlib import contextmanager
from pathlib import Path

EXIT_OK, EXIT_ERRORS, EXIT_USAGE = 0, 1, 2

# Each command and the module of modc.cli that registers it, in the order `modc --help` lists them
# (not alphabetically). A command's module is imported when the command runs: `modc lint` builds
# no other command's options (benchmarks/bench_startup.py).
COMMANDS = {
    "check": "analysis", "dh2mod": "analysis", "dh": "analysis", "compile": "compile", "design": "design_cmd",
    "lsp": "info", "schema": "info", "codes": "info", "backends": "info", "lint": "lint", "fmt": "lint",
    "sim": "motion", "render": "motion", "play": "motion", "plan": "motion", "view": "view",
}
SOURCE_SUFFIXES = (".mod", ".yaml", ".yml")


def looks_like_path(word: str) -> bool:
    """A first word that is no command is a file to compile (`modc FILE -o OUT`) when it looks like
    one: it exists, or has a source suffix or a path separator."""
    return Path(word).exists() or word.lower().endswith(SOURCE_SUFFIXES) or any(c in word for c in "/\\.*?")


class Verbosity:
    quiet = False
    verbose = False


def _err(text: str) -> None:
    print(text, file=sys.stderr)


def _print_diagnostics(diags, sources) -> None:
    from ..diagnostics.render import render_text

    shown = [d for d in diags if not (Verbosity.quiet and not d.is_error)]
    if shown:
        _err(render_text(shown, sources))


def _expand(paths: Sequence[str], prog: str = "modc") -> list[str]:
    """Files as given; directories searched for *.mod; glob patterns (also '**') expanded here,
    so quoted patterns work in CI shells. Sorted and de-duplicated, for stable output. A directory
    without .mod files or a pattern matching no file ends the command (exit 2): a mistyped CI
    glob must not pass as "0 files, no errors"."""
    import glob

    out: list[str] = []
    for p in paths:
        if Path(p).is_dir():
            found = sorted(str(f) for f in Path(p).rglob("*.mod"))
            what = "directory holds no .mod file"
        elif glob.has_magic(p):
            found = sorted(f for f in glob.glob(p, recursive=True) if Path(f).is_file())
            what = "pattern matches no file"
        else:
            found, what = [p], ""
        if not found:
            _err(f"{prog}: {p}: the {what}")
            raise SystemExit(EXIT_USAGE)
        out += found
    return list(dict.fromkeys(out))


@contextmanager
def usage_errors(prog: str, usage: tuple[type[Exception], ...] = (), writing: str | None = None):
    """Unreadable input, an unknown robot, a bad name on the command line (`usage`) or a failed
    write (`writing`) end the command with exit 2 and a diagnostic or one plain line — never a
    traceback."""
    from ..compiler import InputError
    from ..model.select import RobotChoiceError

    try:
        yield
    except (InputError, RobotChoiceError) as e:
        _print_diagnostics([e.diagnostic], {})
        raise SystemExit(EXIT_USAGE) from None
    except usage as e:
        _err(f"modc {prog}: {e}")
        raise SystemExit(EXIT_USAGE) from None
    except OSError as e:
        if writing is None:
            raise
        _err(f"modc {prog}: cannot write {writing}: {e.strerror or e}")
        raise SystemExit(EXIT_USAGE) from None


# Modules of the `full` extra, by the pip package that provides them.
HEAVY = {
    "pinocchio": "pin",
    "coal": "pin",
    "pybullet": "pybullet",
    "pybullet_data": "pybullet",
    "ompl": "ompl",
    "PIL": "pillow",
    "mujoco": "mujoco",
    "viser": "viser",
    "cma": "cma",
    "dask": "dask",
    "distributed": "distributed",
    "toppra": "toppra",
}


def missing_extra(e: ModuleNotFoundError, command: str) -> str | None:
    """One line for a command that needs a module of the `full` extra; None for any other module
    (a real bug, which keeps its traceback)."""
    root = (e.name or "").split(".")[0]
    if root not in HEAVY:
        return None
    package = f"{root} (pip package {HEAVY[root]})" if HEAVY[root] != root.lower() else root
    # modc is not on PyPI: the extra is installed from the checkout (or the wheel) modc came from
    return (f"modc {command}: needs {package}, which the light install leaves out: "
            "pip install 'CHECKOUT[full]' (or the wheel, 'modc-VERSION-py3-none-any.whl[full]')")


def run_like_click(run, options: dict, command: str) -> None:
    """run(**options) for a command line read without click, ending as the click group ends a
    command: Ctrl-C prints "Aborted!" (exit 1), a closed pipe on stdout exits 1 quietly, a module
    of the `full` extra that is missing is one line (exit 2)."""
    import errno

    try:
        run(**options)
    except (EOFError, KeyboardInterrupt):
        _err("Aborted!")
        raise SystemExit(1) from None
    except ModuleNotFoundError as e:
        line = missing_extra(e, command)
        if line is None:
            raise
        _err(line)
        raise SystemExit(EXIT_USAGE) from None
    except OSError as e:
        if e.errno != errno.EPIPE:
            raise
        import os

        sys.stdout = open(os.devnull, "w")  # noqa: SIM115 - nothing more reaches the closed pipe
        raise SystemExit(1) from None


def read_plain(args: list[str], table: dict, positional: Callable[[dict, str], bool]) -> dict | None:
    """A plain command line read without click (lint_run, compile_run): every word an option of
    table (option -> (its name in the command's run(), the values it takes or None for any, or
    the flag's value when a bool)) given at most once, or a positional word positional() takes;
    None for anything else (click reads it then)."""
    options: dict = {}
    words = iter(args)
    for word in words:
        if not word.startswith("-"):
            if not positional(options, word):
                return None
            continue
        name, _, inline = word.partition("=") if word.startswith("--") else (word, "", "")
        spec = table.get(name)
        if spec is None or spec[0] in options:
            return None
        key, values = spec
        if isinstance(values, bool):
            if "=" in word:
                return None
            options[key] = values
            continue
        value = inline if "=" in word else next(words, None)
        if value is None or value.startswith("-") or (values is not None and value not in values):
            return None
        options[key] = value
    return options


@contextmanager
def ticking(every: float, tick: Callable[[], None], name: str):
    """tick() every `every` seconds on a daemon thread while the block runs (the plain progress
    lines of `modc plan` and `modc design` in a CI log)."""
    import threading

    stop = threading.Event()

    def loop() -> None:
        while not stop.wait(every):
            tick()

    thread = threading.Thread(target=loop, name=name, daemon=True)
    thread.start()
    try:
        yield
    finally:
        stop.set()
        thread.join(timeout=max(1.0, every))
