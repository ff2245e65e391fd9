"""A content-addressed disk cache for results that are pure functions of their inputs
(meshes of a part, the collision matrix of an emitted URDF). Keys hash every input, so a hit
is byte-for-byte what a fresh computation would give; a read-only or missing home just
means no cache."""
from __future__ import annotations

import hashlib
import os
from pathlib import Path


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


def get(kind: str, name: str) -> bytes | None:
    if os.environ.get("MODC_NO_CACHE"):
        return None
    path = root() / kind / name
    try:
        return path.read_bytes()
    except OSError:
        return None


def put(kind: str, name: str, data: bytes) -> None:
    if os.environ.get("MODC_NO_CACHE"):
        return
    path = root() / kind / name
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f"{path.name}.{os.getpid()}.tmp")
        tmp.write_bytes(data)
        os.replace(tmp, path)
    except OSError:
        pass
