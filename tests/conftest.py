"""Shared test helpers: compile .mod text or files into a temporary output tree."""
from __future__ import annotations

from pathlib import Path

import pytest

from modc.compiler import Checked, build, check_file, check_text, write_tree

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = sorted((ROOT / "examples").glob("*.mod"))
# examples with at least one arm (farm_cell.mod holds only a `design` problem)
ARM_EXAMPLES = [
    p for p in EXAMPLES if any(ln.startswith("robot ") for ln in p.read_text(encoding="utf-8").splitlines())
]


def checked_ok(text: str, path: str = "t.mod") -> Checked:
    c = check_text(text, path)
    errors = [d for d in c.diagnostics if d.is_error]
    assert not errors, "\n".join(f"{d.code}: {d.message}" for d in errors)
    return c


def compile_text(text: str, out: Path, path: str = "t.mod") -> dict[str, str | bytes]:
    """Check, build and write; returns the files written (relative path -> content)."""
    c = checked_ok(text, path)
    files = build(c)
    write_tree(files, out)
    return files


def compile_file(path: Path, out: Path) -> dict[str, str | bytes]:
    c = check_file(path)
    errors = [d for d in c.diagnostics if d.is_error]
    assert not errors, "\n".join(f"{d.code}: {d.message}" for d in errors)
    files = build(c)
    write_tree(files, out)
    return files


@pytest.fixture(scope="session")
def compiled_examples(tmp_path_factory) -> dict[str, Path]:
    """Every example compiled once per session: example stem -> output directory."""
    out = {}
    for ex in EXAMPLES:
        d = tmp_path_factory.mktemp(ex.stem) / "out"
        compile_file(ex, d)
        out[ex.stem] = d
    return out


def pytest_addoption(parser):
    parser.addoption("--update-golden", action="store_true", help="rewrite tests/golden from the current output")


@pytest.fixture
def update_golden(request) -> bool:
    import os

    return bool(request.config.getoption("--update-golden") or os.environ.get("MODC_UPDATE_GOLDEN"))
