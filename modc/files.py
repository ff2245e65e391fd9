"""Output trees: held in memory ({relative path: text or bytes}, as backends produce them), and
put on disk so that nothing of the user's is lost and OUT is never half-written. (Which OUT a
command may write at all — never an input, a folder holding one, the working directory — is
modc.outputs' rule; this module is the mechanics.)

Every tree modc writes holds MANIFEST: each file's relative path and SHA-256. A directory is
modc's output only if everything in it is listed there, unchanged; that is what may be replaced
without --force. The new tree is written into `.OUT.modc-new-XXXX/tree`, a sibling of OUT, and
exchanged with OUT in one renameat2(RENAME_EXCHANGE) call, so at every instant OUT is the
complete old tree or the complete new one; the old tree, now under the sibling's name, is then
removed. Each sibling holds TEMP_MARKER, written before anything else goes in: a run killed midway
leaves a sibling the next run for the same OUT removes (under an flock on the parent directory,
so two concurrent runs never remove each other's work) — recognised by that marker, never by
its name alone: a folder of the user's named like one is left alone.
"""
from __future__ import annotations

import errno
import hashlib
import json
import math
import os
import re
import shutil
import tempfile
from collections.abc import Callable, Mapping
from pathlib import Path

REPORT = "report.json"  # written by the report backend into every output tree
MANIFEST = ".modc-manifest.json"  # written by write_tree into every output tree: what modc wrote there
MANIFEST_LIMIT = 16_000_000  # bytes: a manifest larger than this is not one modc wrote
TEMP_MARKER = ".modc-temporary"  # inside every sibling directory modc makes, and only there
_SIBLING = "modc-new", "modc-old"


def _encode(content: str | bytes) -> bytes:
    return content if isinstance(content, bytes) else content.encode("utf-8")


def manifest_text(files: Mapping[str, str | bytes]) -> str:
    """The manifest of a tree (sorted, so the same tree gives the same bytes)."""
    listing = {rel: hashlib.sha256(_encode(c)).hexdigest() for rel, c in sorted(files.items())}
    return json.dumps({"modc-manifest": 1, "files": listing}, indent=2, sort_keys=True) + "\n"


def write_files(files: Mapping[str, str | bytes], root: Path) -> None:
    """Write a tree under root exactly as `modc FILE -o OUT` does (UTF-8, '\\n' line ends)."""
    made: set[Path] = set()  # folders made (or found) already: a mkdir is a system call per file otherwise
    for rel, content in files.items():
        parts = Path(rel).parts
        if not parts or Path(rel).is_absolute() or ".." in parts or MANIFEST in parts[:1]:
            # a backend bug, never the user's input (names pass the identifier rule): refuse to leave OUT
            raise ValueError(f"refusing to write {rel!r}: not a relative path inside OUT")
        target = root / rel
        if target.parent not in made:
            target.parent.mkdir(parents=True, exist_ok=True)
            made.add(target.parent)
        target.write_bytes(_encode(content))


def _hash_file(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _read_manifest(out: Path) -> dict[str, str] | None:
    path = out / MANIFEST
    try:
        if path.is_symlink() or not path.is_file() or path.stat().st_size > MANIFEST_LIMIT:
            return None
        doc = json.loads(path.read_bytes())
    except (OSError, ValueError):
        return None
    listing = doc.get("files") if isinstance(doc, dict) else None
    if not isinstance(listing, dict) or not all(isinstance(k, str) and isinstance(v, str) for k, v in listing.items()):
        return None
    return listing


def foreign_entries(out: Path) -> list[str]:
    """What in directory `out` modc did not write, or changed since: paths relative to out
    ("name (modified)" for a changed file). Empty: out is empty or exactly modc's output.
    Symbolic links are never followed: a link is itself foreign."""
    entries: list[tuple[str, Path]] = []
    for dirpath, dirnames, filenames in os.walk(out):
        base = Path(dirpath)
        for name in sorted(dirnames):
            if (base / name).is_symlink():
                filenames.append(name)  # a link to a directory: an entry, not a place to walk into
        dirnames[:] = sorted(d for d in dirnames if not (base / d).is_symlink())
        entries += [((base / f).relative_to(out).as_posix(), base / f) for f in sorted(filenames)]
    if not entries:
        return []
    listing = _read_manifest(out)
    if listing is None:
        return sorted(rel for rel, _ in entries)
    bad = []
    for rel, path in sorted(entries):
        if rel == MANIFEST:
            continue
        if rel not in listing or path.is_symlink() or not path.is_file():
            bad.append(rel)
        elif _hash_file(path) != listing[rel]:
            bad.append(f"{rel} (modified)")
    return bad


def _sibling_pattern(name: str) -> re.Pattern[str]:
    return re.compile(rf"\.{re.escape(name)}\.(?:{'|'.join(_SIBLING)})-[A-Za-z0-9_]+")


def _marker_text(out_name: str) -> str:
    return json.dumps({"modc-temporary": 1, "for": out_name}) + "\n"


def _marked(path: Path, out_name: str) -> bool:
    """path is a sibling modc made for OUT named out_name: a real directory holding modc's marker
    (a regular file, not a link) that names that OUT."""
    marker = path / TEMP_MARKER
    try:
        if path.is_symlink() or not path.is_dir() or marker.is_symlink() or not marker.is_file():
            return False
        if marker.stat().st_size > 4096:
            return False
        # a prefix: a run killed while writing the marker (microseconds) leaves part of it
        return _marker_text(out_name).startswith(marker.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False


def _sibling(out: Path, kind: str) -> Path:
    """A fresh marked sibling directory of out (kind: "modc-new" or "modc-old")."""
    path = Path(tempfile.mkdtemp(prefix=f".{out.name}.{kind}-", dir=out.parent))
    # a run killed before this line leaves an empty folder without marker: never removed, nothing lost
    (path / TEMP_MARKER).write_text(_marker_text(out.name), encoding="utf-8")
    return path


def remove_leftovers(out: Path, keep: Callable[[Path], bool] = lambda p: False) -> list[Path]:
    """Remove the siblings a killed run left next to out: directories with modc's names AND its
    marker inside, except those keep() says hold something to keep (an input of the command)."""
    removed: list[Path] = []
    pattern = _sibling_pattern(out.name)
    try:
        names = os.listdir(out.parent)
    except OSError:
        return removed
    for name in names:
        path = out.parent / name
        if pattern.fullmatch(name) and _marked(path, out.name) and not keep(path):
            shutil.rmtree(path, ignore_errors=True)
            removed.append(path)
    return removed


def _renameat2():
    import ctypes

    try:
        libc = ctypes.CDLL(None, use_errno=True)
        fn = libc.renameat2
    except (OSError, AttributeError):
        return None
    fn.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    fn.restype = ctypes.c_int
    return fn


AT_FDCWD, RENAME_EXCHANGE = -100, 2


def exchange(a: Path, b: Path) -> bool:
    """Swap two directories atomically (Linux renameat2(RENAME_EXCHANGE)). False when the
    system or file system does not support it; raises OSError for any other failure."""
    import ctypes

    fn = _renameat2()
    if fn is None:
        return False
    if fn(AT_FDCWD, os.fsencode(a), AT_FDCWD, os.fsencode(b), RENAME_EXCHANGE) == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.ENOSYS, errno.EINVAL, errno.ENOTSUP):
        return False
    raise OSError(err, os.strerror(err), str(b))


def _lock(directory: Path) -> int:
    """An exclusive flock on the directory (released when the fd is closed or the process dies).
    Where the file system has no locks (some network mounts) runs are simply not serialised."""
    import fcntl

    fd = os.open(directory, os.O_RDONLY | os.O_DIRECTORY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
    except OSError:
        pass
    return fd


def foreign_now(out: Path) -> list[str]:
    """foreign_entries(out) under the lock a writer of out holds: never a tree seen mid-exchange."""
    fd = _lock(out.parent)
    try:
        return foreign_entries(out)
    finally:
        os.close(fd)


def replace_tree(files: Mapping[str, str | bytes], out: Path, force: bool,
                 keep: Callable[[Path], bool] = lambda p: False) -> None:
    """Put files (and their manifest) at out. The caller has decided that out may be replaced
    (it is missing, empty, modc's own output, or force is set; never an input: modc.outputs);
    this re-checks foreign files under the lock and raises ForeignOutput. keep: leftovers that
    hold something to keep (see remove_leftovers)."""
    parent = out.parent
    parent.mkdir(parents=True, exist_ok=True)
    fd = _lock(parent)
    try:
        remove_leftovers(out, keep)
        if not force and out.is_dir() and not out.is_symlink():
            bad = foreign_entries(out)
            if bad:
                raise ForeignOutput(bad)
        wrapper = _sibling(out, _SIBLING[0])
        new = wrapper / "tree"
        try:
            new.mkdir()
            # the manifest first: a run killed while writing leaves a tree whose every file is listed
            (new / MANIFEST).write_text(manifest_text(files), encoding="utf-8")
            write_files(files, new)
            os.chmod(new, 0o777 & ~_umask())
            if not os.path.lexists(out):
                os.rename(new, out)
            elif not exchange(new, out):  # no RENAME_EXCHANGE (old kernel, some network file systems)
                old = _sibling(out, _SIBLING[1])
                os.rename(out, old / "tree")
                try:
                    os.rename(new, out)
                except BaseException:
                    os.rename(old / "tree", out)  # the old tree back in place: OUT is never left missing
                    shutil.rmtree(old, ignore_errors=True)
                    raise
                shutil.rmtree(wrapper, ignore_errors=True)
                wrapper = old
        except BaseException:
            shutil.rmtree(wrapper, ignore_errors=True)
            raise
        # the old tree (or link, or nothing) is now wrapper/tree: rmtree never follows a link in it
        shutil.rmtree(wrapper, ignore_errors=True)
    finally:
        os.close(fd)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


class ForeignOutput(Exception):
    """out holds files modc did not write (or changed since)."""

    def __init__(self, entries: list[str]):
        super().__init__(", ".join(entries))
        self.entries = entries


class NotAFile(OSError):
    """An input path that is not a regular file (a device, a FIFO, a socket, a directory)."""


def read_bounded(path: str | os.PathLike, limit: int) -> tuple[bytes, int]:
    """At most limit + 1 bytes of a regular file, and its size. Devices (a link to /dev/zero),
    FIFOs and sockets are refused before anything is read, and opening never blocks."""
    import stat

    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            kind = "a directory" if stat.S_ISDIR(st.st_mode) else "not a regular file"
            raise NotAFile(errno.EINVAL, kind, str(path))
        chunks, got = [], 0
        while got <= limit:
            block = os.read(fd, min(1 << 20, limit + 1 - got))
            if not block:
                break
            chunks.append(block)
            got += len(block)
        return b"".join(chunks), max(st.st_size, got)
    finally:
        os.close(fd)


# --- reading JSON inputs (trajectory files, ranking.json) under the limits of .mod files -------

MAX_JSON_BYTES = 16_000_000  # a planned trajectory is tens of kB; a ranking.json a few
MAX_JSON_DEPTH = 32  # a trajectory nests 3 levels, a ranking.json 4


class InputProblem(ValueError):
    """Bytes of an input file modc will not take (too large, not UTF-8, not JSON, nested too
    deeply). The message quotes none of the file; line and col (1-based) say where, if known."""

    def __init__(self, message: str, line: int = 1, col: int = 1, offset: int = 0):
        super().__init__(message)
        self.line, self.col, self.offset = line, col, offset


def _position(text: str, offset: int) -> tuple[int, int]:
    line = text.count("\n", 0, offset) + 1
    return line, offset - (text.rfind("\n", 0, offset) + 1) + 1


def read_text(path: str | os.PathLike, limit: int) -> str:
    """A regular file's UTF-8 text (a BOM dropped). OSError when it cannot be read or is not a
    regular file (a FIFO, a device, a directory: refused before anything is read);
    InputProblem when it is larger than limit bytes or not UTF-8."""
    data, size = read_bounded(path, limit)
    if size > limit:
        raise InputProblem(f"the file is too large ({size:,} bytes; the limit is {limit:,} bytes)")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as e:
        before = data[: e.start].decode("utf-8-sig")
        line, col = _position(before, len(before))
        raise InputProblem(f"the file is not UTF-8 text (byte 0x{data[e.start]:02x} at line {line}, column {col})",
                           line, col, len(before)) from None


_JSON_TOKEN = re.compile(r'"(?:[^"\\]|\\.)*"?|[\[\]{}]')


def _check_depth(text: str, limit: int) -> None:
    """InputProblem at the first bracket nested deeper than limit (Python's json recurses)."""
    if text.count("[") + text.count("{") <= limit:
        return
    depth = 0
    for m in _JSON_TOKEN.finditer(text):
        c = m.group()
        if c in "[{":
            depth += 1
            if depth > limit:
                line, col = _position(text, m.start())
                raise InputProblem(f"nested more than {limit} levels deep at line {line}, column {col}",
                                   line, col, m.start())
        elif c in "]}":
            depth -= 1


def _json_int(text: str) -> int | float:
    if len(text.lstrip("-")) <= 15:
        return int(text)
    value = float(text)
    if math.isinf(value):  # wider than any float: read_json says so (ValueError)
        raise ValueError("integer too large")
    return value


def read_json(path: str | os.PathLike, limit: int = MAX_JSON_BYTES, depth: int = MAX_JSON_DEPTH):
    """A JSON input file, read as .mod files are (read_text) and at most depth levels deep.
    OSError when it cannot be read; InputProblem when its content is not acceptable JSON."""
    text = read_text(path, limit)
    _check_depth(text, depth)
    try:
        # integers only as wide as a float: a 400-digit one overflowed every float check downstream
        return json.loads(text, parse_int=_json_int)
    except json.JSONDecodeError as e:
        where = f"at line {e.lineno}, column {e.colno}"
        raise InputProblem(f"not JSON: {e.msg} {where}", e.lineno, e.colno, e.pos) from None
    except (ValueError, RecursionError):  # an integer of more than 4,300 digits
        raise InputProblem("not JSON modc can read: a number with too many digits") from None
