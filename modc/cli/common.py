"""What every command shares and what needs no click: exit codes, output, file arguments,
usage errors (the `modc lint` fast path, modc.cli.lint_run, runs on these alone)."""

from __future__ import annotations

import sys
from collections.abc import Sequence
from contextlib import contextmanager
from pathlib import Path

EXIT_OK, EXIT_ERRORS, EXIT_USAGE = 0, 1, 2


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
