"""Output trees held in memory ({relative path: text or bytes}, as backends produce them)."""
from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

REPORT = "report.json"  # written by the report backend into every output tree; its presence marks a tree modc wrote


def write_files(files: Mapping[str, str | bytes], root: Path) -> None:
    """Write a tree under root exactly as `modc FILE -o OUT` does (UTF-8, '\\n' line ends)."""
    for rel, content in files.items():
        target = root / rel
        target.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(content, bytes):
            target.write_bytes(content)
        else:
            target.write_text(content, encoding="utf-8", newline="\n")
