"""A content-addressed disk cache for results that are pure functions of their inputs
(meshes of a part, the collision matrix of an emitted URDF). Keys hash every input, so a hit
is byte-for-byte what a fresh computation would give; a read-only or missing home just
means no cache.

The cache writes only inside its directory (ROOT/KIND/NAME, no link leading out of it) and
never into a directory that is, or holds, an input of the running command (modc.outputs'
rule): then there is simply no cache, and a note says why once."""
from __future__ import annotations

import hashlib
import os
import re
from pathlib import Path

READ_LIMIT = 256 << 20  # bytes: a cache entry larger than this is not one modc wrote
_PART = re.compile(r"[A-Za-z0-9][A-Za-z0-9_.-]*")


def root() -> Path:
    base = os.environ.get("MODC_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache"), "modc")
    return Path(base)


def key(*parts: str | bytes) -> str:
    h = hashlib.sha256()
    for p in parts:
        data = p.encode() if isinstance(p, str) else p
        h.update(len(data).to_bytes(8, "little"))
        h.update(data)
    return h.hexdigest()[:32]


def directory(kind: str, create: bool = True) -> Path | None:
    """ROOT/KIND, made if needed, when the cache may be used there; else None (no cache): caching
    off, a root that is or holds an input, a KIND that is a link or leads out of the root."""
    if os.environ.get("MODC_NO_CACHE") or not _PART.fullmatch(kind):
        return None
    from .outputs import cache_dir_ok

    base = root()
    if not cache_dir_ok(base):
        return None
    path = base / kind
    try:
        if create:
            path.mkdir(parents=True, exist_ok=True)
        if path.is_symlink() or not path.is_dir():
            return None
        real_base = os.path.realpath(base)
        if os.path.dirname(os.path.realpath(path)) != real_base:
            return None
    except (OSError, ValueError):
        return None
    return path


def get(kind: str, name: str) -> bytes | None:
    from .files import read_bounded

    where = directory(kind, create=False)
    if where is None or not _PART.fullmatch(name):
        return None
    try:
        # a regular file only: a FIFO or a device planted in the cache never blocks or floods a run
        data, size = read_bounded(where / name, READ_LIMIT)
    except (OSError, ValueError):
        return None
    return data if size <= READ_LIMIT else None


def put(kind: str, name: str, data: bytes) -> None:
    where = directory(kind)
    if where is None or not _PART.fullmatch(name):
        return
    try:
        from .outputs import replace_file

        replace_file(where / name, data)  # replaces a link named like the entry, never what it points to
    except OSError:
        pass


def get_checked(kind: str, name: str) -> bytes | None:
    """An entry written by put_checked, or None when it is missing or its digest does not match
    (a damaged or foreign file is rebuilt, never trusted)."""
    blob = get(kind, name)
    if blob is None:
        return None
    digest, _, payload = blob.partition(b"\n")
    return payload if hashlib.sha256(payload).hexdigest().encode() == digest else None


def put_checked(kind: str, name: str, payload: bytes) -> None:
    """put(), the payload preceded by its sha256 (get_checked's test)."""
    put(kind, name, hashlib.sha256(payload).hexdigest().encode() + b"\n" + payload)



def prune(kind: str, suffix: str, keep: int) -> None:
    """Keep the `keep` newest entries of KIND named *suffix; remove the older ones (only regular
    files modc names so, inside its own directory: never a link, never anything else)."""
    where = directory(kind, create=False)
    if where is None:
        return
    try:
        entries = [e for e in os.scandir(where)
                   if e.name.endswith(suffix) and _PART.fullmatch(e.name) and e.is_file(follow_symlinks=False)]
        entries.sort(key=lambda e: e.stat(follow_symlinks=False).st_mtime_ns, reverse=True)
        for e in entries[keep:]:
            os.unlink(e.path)
    except OSError:
        pass
