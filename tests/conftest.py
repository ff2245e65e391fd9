"""Shared test helpers: compile .mod text or files into a temporary output tree."""
from __future__ import annotations

import resource
import subprocess
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


def run_cpu(cmd: list[str], *, timeout: float = 600, **kw) -> tuple[subprocess.CompletedProcess, float]:
    """subprocess.run(cmd, capture_output=True, text=True) and the CPU seconds the child (with its own
    children) used. CPU time, unlike wall-clock time, does not grow with the rest of the machine's
    load: a bound on it is a bound on the work done. `timeout` is a guard against hangs only."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, **kw)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r, (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)


def pytest_addoption(parser):
    parser.addoption("--update-golden", action="store_true", help="rewrite tests/golden from the current output")


@pytest.fixture
def update_golden(request) -> bool:
    import os

    return bool(request.config.getoption("--update-golden") or os.environ.get("MODC_UPDATE_GOLDEN"))
