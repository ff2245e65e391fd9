"""The import layers (pyproject.toml's [tool.importlinter] contracts, docs/ARCHITECTURE.md) hold,
and every exception is marked as a debt to pay, with what fixes it."""
from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def test_the_import_contracts_are_kept():
    pytest.importorskip("importlinter")
    exe = shutil.which("lint-imports", path=str(Path(sys.executable).parent)) or "lint-imports"
    r = subprocess.run([exe, "--no-cache"], cwd=ROOT, capture_output=True, text=True,
                       env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr
    assert "Contracts: 3 kept, 0 broken." in r.stdout


def test_every_ignored_import_says_how_it_will_be_fixed():
    text = (ROOT / "pyproject.toml").read_text(encoding="utf-8")
    section = text[text.index("[tool.importlinter]"):]
    lines = section.splitlines()
    for i, line in enumerate(lines):
        if re.match(r'\s*"modc[\w.]* -> modc[\w.]*",', line):
            before = "\n".join(lines[max(0, i - 6): i + 1])
            assert "TODO(issue 25)" in before, line


def test_a_pass_never_imports_the_physics_itself():
    """The torque pass runs the analysis the compiler hands in; without one it refuses loudly."""
    from modc.compiler import check_file
    from modc.passes import Context, check_torque

    checked = check_file(ROOT / "examples" / "farm.mod")
    with pytest.raises(RuntimeError, match="torque_analysis"):
        check_torque.run(checked.design, Context(analyses=frozenset({"torque"})))
    calls = []

    def analyse(robot, payload):
        calls.append(robot.name)
        return []

    check_torque.run(checked.design, Context(analyses=frozenset({"torque"}), torque_analysis=analyse))
    assert calls == ["farm"]


MAX_COMPLEXITY = 25


def test_no_function_is_more_complex_than_the_limit():
    """radon's cyclomatic complexity (it counts boolean operators too, which ruff's C901 does
    not): every function and method of the package at most MAX_COMPLEXITY."""
    from radon.complexity import cc_visit

    over = set()
    for path in sorted((ROOT / "modc").rglob("*.py")):
        for block in cc_visit(path.read_text(encoding="utf-8")):
            for f in (block, *getattr(block, "methods", ())):  # a class's methods are listed again alone
                if f.complexity > MAX_COMPLEXITY:
                    over.add(f"{path.relative_to(ROOT)}:{f.lineno} {f.fullname} {f.complexity}")
    assert not over, "split these functions:\n" + "\n".join(sorted(over))


# Not in a layer on purpose: the package's entry points (they import the API and the CLI lazily or
# are run as a script) and the Pygments plugin, which imports nothing of modc and nothing imports.
OUTSIDE_THE_LAYERS = {"modc.__init__", "modc.__main__", "modc.pygments_lexer"}


def test_every_top_level_module_is_in_a_layer():
    """A module in no layer is checked by no contract (modc.records was, though the AST, the
    model and the objectives import it)."""
    import tomllib

    contracts = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["importlinter"]
    layers = next(c for c in contracts["contracts"] if c["type"] == "layers")["layers"]
    placed = set(re.findall(r"modc\.\w+", " ".join(layers)))
    modules = {f"modc.{p.stem}" for p in (ROOT / "modc").glob("*.py")}
    modules |= {f"modc.{p.parent.name}" for p in (ROOT / "modc").glob("*/__init__.py")}
    assert sorted(modules - placed - OUTSIDE_THE_LAYERS) == []
