"""The one output-safety rule, for every command that writes (compile, design, render, play
--record, the caches; fmt rewrites only its inputs, see modc.syntax.format.rewrite_file).

A command knows its inputs (the source file, every library file it uses, a trajectory file).
Whatever the options, --force included, modc never replaces or deletes:
  - an input, also when OUT reaches it through a symbolic link or a `..` path;
  - a folder that holds an input anywhere inside it;
  - the working directory or one of its parents;
  - a plain file where an output folder is asked for (-o names the folder modc creates).
Paths are compared both as written (made absolute, `..` folded) and as the file system resolves
them (symbolic links followed), and existing files by identity (device and inode), so a second
name for the same file is still that file. Refusals are `output-unsafe` diagnostics: the path
and what it is, never file content; the same with and without --force.
"""
from __future__ import annotations

import os
import sys
from collections.abc import Callable, Iterable, Mapping, Sequence
from pathlib import Path

PathLike = str | os.PathLike
DIR_HINT = "write the output into a new directory, e.g. -o build/out"
_protected: list[str] = []  # the inputs of the running command (for the caches)


def _forms(path: PathLike) -> set[str]:
    """The path as written (absolute, `..` folded) and as resolved (links followed)."""
    p = os.fspath(path)
    return {os.path.abspath(p), os.path.realpath(p)}


def _same(a: PathLike, b: PathLike) -> bool:
    if _forms(a) & _forms(b):
        return True
    try:
        return os.path.samefile(a, b)
    except (OSError, ValueError):
        return False


def _ancestors(path: PathLike) -> list[str]:
    """path itself and every folder above it, in both of its forms."""
    out: list[str] = []
    for form in _forms(path):
        p = Path(form)
        out += [str(p), *map(str, p.parents)]
    return out


def holds(directory: PathLike, path: PathLike) -> bool:
    """directory is path, or a folder path lies in (by name or by identity)."""
    mine = _forms(directory)
    try:
        st = os.stat(directory)
    except (OSError, ValueError):
        st = None
    for a in _ancestors(path):
        if a in mine:
            return True
        if st is not None:
            try:
                sa = os.stat(a)
            except (OSError, ValueError):
                continue
            if (sa.st_dev, sa.st_ino) == (st.st_dev, st.st_ino):
                return True
    return False


def _unsafe(out: PathLike, what: str, hint: str):
    from .diagnostics import Span, codes  # here: the records' code cache (modc.cache) reads this module
    from .diagnostics.errors import InputError

    shown = os.fspath(out)
    return InputError(codes.OUTPUT_UNSAFE.at(Span.point(shown), path=shown, what=what, hint=hint))


def _never_replaced(out: PathLike, inputs: Sequence[PathLike]) -> str | None:
    """What out is when it may never be replaced, deleted or written through; else None."""
    for src in inputs:
        if _same(out, src):
            return f"the input {os.fspath(src)}"
    for src in inputs:
        if holds(out, src):
            return f"a directory holding the input {os.fspath(src)}"
    try:
        cwd = os.getcwd()
    except OSError:  # the working directory was removed: nothing there to protect
        return None
    if holds(out, cwd):
        return "the current directory or one of its parents"
    return None


def check_output_dir(out: PathLike, inputs: Sequence[PathLike] = (), force: bool = False) -> None:
    """Raise modc.compiler.InputError with the diagnostic writing a tree to OUT would give
    (output-unsafe, output-not-modc), before any work is done; return when OUT may be written.
    The same check runs again in write_tree, which is what makes it hold."""
    from .files import foreign_now

    _check_rule(out, inputs, force)
    if not force and Path(out).is_dir() and not Path(out).is_symlink():
        _refuse_foreign(out, foreign_now(Path(os.path.abspath(out))))
    _check_writable(out)


def _check_writable(out: PathLike) -> None:
    """OUT's folder may be created and written (the tree is written beside OUT, then renamed):
    tried with an empty folder made and removed in the nearest folder that exists, so a search of
    minutes is not lost to a read-only disk, an immutable folder or a file on the way."""
    from . import names
    from .diagnostics import Span, codes
    from .diagnostics.errors import InputError

    where = os.fspath(out)
    parent = Path(os.path.abspath(out)).parent
    while not parent.exists() and parent != parent.parent:
        parent = parent.parent
    if not parent.is_dir():
        why = f"'{names.shown(parent.name, 60)}' on its way is not a directory"
        raise InputError(codes.OUTPUT_UNWRITABLE.at(Span.point(where), path=where, why=why))
    try:
        probe = parent / f".modc-probe-{os.getpid()}-{id(parent):x}"  # (tempfile's import costs start-up)
        os.mkdir(probe, 0o700)
        os.rmdir(probe)
    except FileExistsError:  # (another modc's probe, this instant): the folder is writable
        pass
    except OSError as e:
        raise InputError(codes.OUTPUT_UNWRITABLE.at(Span.point(where), path=where,
                                                    why=e.strerror or type(e).__name__)) from None


def _check_rule(out: PathLike, inputs: Sequence[PathLike], force: bool) -> None:
    """check_output_dir but what is in OUT (which replace_tree checks under its lock)."""
    protect(inputs)
    path = Path(out)
    why = _never_replaced(path, inputs)
    if why is not None:
        raise _unsafe(out, why, DIR_HINT)
    if path.exists() and not path.is_dir():
        # never replaced by a folder, even with --force: -o names the folder to create, not a file
        raise _unsafe(out, "a file, not a directory", f"-o names the directory modc creates; {DIR_HINT}")
    if not force and path.is_symlink():
        _refuse_foreign(out, ["(OUT itself is a symbolic link)"])


def _refuse_foreign(out: PathLike, entries: list[str]) -> None:
    from .diagnostics import Span, codes  # here: the records' code cache (modc.cache) reads this module
    from .diagnostics.errors import InputError

    if not entries:
        return
    shown = ", ".join(entries[:5]) + (f" and {len(entries) - 5} more" if len(entries) > 5 else "")
    where = os.fspath(out)
    raise InputError(codes.OUTPUT_NOT_MODC.at(Span.point(where), path=where, found=f"it holds {shown}"))


def check_output_file(out: PathLike, inputs: Sequence[PathLike] = (), option: str = "-o",
                      example: str = "out.png") -> None:
    """The rule for a command writing one file (render -o, play --record): raise InputError
    (output-unsafe) when OUT is an input, reaches one through a link, or is a directory."""
    protect(inputs)
    hint = f"write to a new file, e.g. {option} {example}"
    why = _never_replaced(out, inputs)
    if why is not None:
        raise _unsafe(out, why, hint)
    if os.path.isdir(out):
        raise _unsafe(out, "a directory", hint)


def write_tree(files: Mapping[str, str | bytes], out: PathLike, force: bool = False,
               inputs: Sequence[PathLike] = ()) -> None:
    """Check OUT (check_output_dir), then write files there atomically (modc.files.replace_tree):
    OUT is either the old tree or the complete new one, never half-written or missing."""
    from .files import ForeignOutput, replace_tree

    _check_rule(out, inputs, force)
    target = Path(os.path.abspath(out))
    try:
        replace_tree(files, target, force, keep=lambda p: any(holds(p, src) for src in inputs))
    except ForeignOutput as e:
        _refuse_foreign(out, e.entries)


def replace_file(path: PathLike, data: bytes, *, mode: int | None = None,
                 before_rename: Callable[[], None] | None = None, durable: bool = False) -> None:
    """Replace one file's contents atomically: data goes to a fresh temporary file in the same
    directory (mkstemp: created exclusively, never a planted link), which one rename puts in
    place, so a reader sees the old file or the whole new one, and a link named like the file
    is replaced, never what it points to. mode: the new file's permission bits (default
    mkstemp's 0600); durable: fsync before the rename; before_rename runs just before it and
    may raise to keep the old file (fmt's compare-and-swap). The temporary file never stays."""
    import tempfile  # not at import: `modc lint` loads this module and writes nothing

    directory, name = os.path.split(os.fspath(path))
    fd, tmp = tempfile.mkstemp(prefix=f".{name}.", suffix=".tmp", dir=directory or ".")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            if durable:
                f.flush()
                os.fsync(f.fileno())
        if mode is not None:
            os.chmod(tmp, mode)
        if before_rename is not None:
            before_rename()
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


# --- the caches --------------------------------------------------------------------------------


def protect(inputs: Iterable[PathLike]) -> None:
    """Declare the running command's inputs: a cache directory that is one or holds one is not
    written to (modc.cache)."""
    _protected.extend(os.fspath(p) for p in inputs if os.fspath(p) not in _protected)


_verdicts: dict[tuple[str, int], bool] = {}  # (directory, inputs declared so far): the list only grows


def cache_dir_ok(directory: PathLike) -> bool:
    """False (once saying why on stderr) when the cache directory is, or holds, an input."""
    key = (os.fspath(directory), len(_protected))
    if key not in _verdicts:
        bad = next((src for src in _protected if holds(directory, src)), None)
        if bad is not None and not any(k[0] == key[0] and not ok for k, ok in _verdicts.items()):
            sys.stderr.write(f"modc: not caching in {key[0]}: it is or holds the input {bad}\n")
        _verdicts[key] = bad is None
    return _verdicts[key]
