"""Golden files: every example's emitted text files, byte for byte; meshes by SHA-256.

After an intended change of output, refresh them with
    python -m pytest tests/test_golden.py --update-golden      (or MODC_UPDATE_GOLDEN=1)
and review the diff in git.
"""
from __future__ import annotations

import difflib
import hashlib
from pathlib import Path

import pytest
from conftest import EXAMPLES, ROOT

from modc.compiler import COMPILE_ANALYSES, build, check_file

GOLDEN = ROOT / "tests" / "golden"
REFRESH = "refresh with: python -m pytest tests/test_golden.py --update-golden"


def _expected_files(files: dict) -> dict[str, str]:
    """Text outputs as they are; binary meshes folded into one digest list."""
    out = {rel: c for rel, c in files.items() if isinstance(c, str)}
    digests = [f"{hashlib.sha256(c).hexdigest()}  {rel}" for rel, c in files.items() if isinstance(c, bytes)]
    if digests:
        out["meshes.sha256"] = "\n".join(digests) + "\n"
    return out


@pytest.mark.parametrize("example", EXAMPLES, ids=lambda p: p.stem)
def test_golden(example: Path, update_golden: bool, monkeypatch):
    monkeypatch.chdir(ROOT)  # diagnostics in report.json name files relative to the repo
    c = check_file(example.relative_to(ROOT), analyses=COMPILE_ANALYSES)  # what `modc FILE -o OUT` runs
    assert c.ok
    got = _expected_files(build(c))
    folder = GOLDEN / example.stem
    if update_golden:
        if folder.exists():
            for f in sorted(folder.rglob("*"), reverse=True):
                f.unlink() if f.is_file() else f.rmdir()
        for rel, text in got.items():
            (folder / rel).parent.mkdir(parents=True, exist_ok=True)
            (folder / rel).write_text(text, encoding="utf-8", newline="\n")
        return
    want = {str(p.relative_to(folder)): p.read_text(encoding="utf-8") for p in folder.rglob("*") if p.is_file()}
    assert sorted(got) == sorted(want), f"output files changed for {example.name}; {REFRESH}"
    for rel in sorted(got):
        if got[rel] != want[rel]:
            diff = "".join(difflib.unified_diff(
                want[rel].splitlines(True), got[rel].splitlines(True), f"golden/{example.stem}/{rel}", "now", n=2))
            pytest.fail(f"{rel} of {example.name} differs from its golden file ({REFRESH}):\n{diff[:6000]}")
