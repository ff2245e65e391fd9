"""The compiled position-only IK (modc.design.reach_jit, numba) returns bit for bit what the numpy
path of modc.design.reach.solve returns - the same joint vectors and errors for every run, so
every screen decision, kept setting and ranking is the same with numba or without it."""
from __future__ import annotations

import numpy as np
import pytest

from modc.compiler import check_text
from modc.design import reach, settings
from modc.design.batch import geometry
from modc.design.evaluate import Spec
from modc.design.space import Shape

pytest.importorskip("numba")
reach_jit = pytest.importorskip("modc.design.reach_jit")
if not reach_jit.matches_numpy():
    pytest.skip("numpy's einsum sums three terms in another order here: the numpy path runs",
                allow_module_level=True)

CELL = """design three {
    payload 100 g
    box shelf size (0.6, 0.4, 0.02) m at (0.3, 0, 0.05) m
    target a at (0.30, 0.10, 0.25) m
    target b at (0.25, -0.15, 0.30) m within 0.5 mm
    target c at (0.10, 0.30, 0.45) m
    target far at (0.9, 0.9, 0.9) m
    units 1 to 6
}
"""


@pytest.fixture(scope="module")
def spec():
    c = check_text(CELL, "cell.mod")
    assert c.ok, c.diagnostics
    return Spec.of(c.design.problems[0])


def _solve(monkeypatch, jit: bool, *args, **kw):
    monkeypatch.setenv("MODC_JIT", "1" if jit else "0")
    assert reach.jit() is jit
    return reach.solve(*args, **kw)


@pytest.mark.parametrize("kinds", [(4,), (2, 3), (1, 4, 3), (4, 4, 3), (4, 3, 4, 3), (1, 2, 3, 4, 4),
                                   (4, 3, 4, 3, 4, 3)])
@pytest.mark.parametrize("per_candidate", [False, True])
def test_compiled_runs_equal_the_numpy_runs_bit_for_bit(monkeypatch, spec, kinds, per_candidate):
    lib = spec.problem.cell.library
    n = len(kinds)
    shape = Shape(kinds, (None,) * n)
    ax = settings.axes(spec, shape)
    rng = np.random.default_rng(n)
    idx = np.sort(rng.choice(min(ax.count, 10 ** 9), size=min(200, ax.count), replace=False)).astype(np.int64)
    piv, por = settings.settings_at(ax, n, idx)
    types = [lib.units[k] for k in kinds]
    tool = spec.problem.cell.tool
    g = geometry(types, piv, por, [t.x23 for t in types], tool.xyz, tool.rpy)
    lo, hi = np.full(n, spec.lower), np.full(n, spec.upper)
    q0 = reach.seeds(n, 4, lo, hi, 7)
    if per_candidate:  # a warm start per candidate (C, 1, n), as the screen passes it
        q0 = np.clip(rng.normal(size=(len(idx), 1, n)), lo, hi)
    a = _solve(monkeypatch, False, g, spec.targets, q0, lo, hi)
    b = _solve(monkeypatch, True, g, spec.targets, q0, lo, hi)
    for x, y in zip(a, b, strict=True):
        assert x.shape == y.shape
        assert np.array_equal(x, y)
    # the case is not trivial: some runs reach a target, some stall, the far target none
    hit = a[1] <= spec.targets.tol_p[None, :, None]
    assert hit.any() or n < 3
    assert not hit[:, 3].any()


def test_few_iterations_and_one_run_equal_too(monkeypatch, spec):
    lib = spec.problem.cell.library
    kinds = (1, 4, 3)
    types = [lib.units[k] for k in kinds]
    tool = spec.problem.cell.tool
    g = geometry(types, np.array([[0.0, 0.5, -0.3]]), np.array([[0.0, 0.0, 0.0]]), [t.x23 for t in types],
                 tool.xyz, tool.rpy)
    lo, hi = np.full(3, spec.lower), np.full(3, spec.upper)
    for it in (0, 1, 7, 12):
        a = _solve(monkeypatch, False, g, spec.targets.take(slice(0, 1)), np.zeros((1, 3)), lo, hi, it)
        b = _solve(monkeypatch, True, g, spec.targets.take(slice(0, 1)), np.zeros((1, 3)), lo, hi, it)
        assert all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))


def test_a_process_loads_the_compiled_path_only_after_enough_runs(monkeypatch):
    monkeypatch.delenv("MODC_JIT", raising=False)
    monkeypatch.setattr(reach, "_NUMPY_RUNS", [0])
    assert not reach.jit(reach.JIT_AFTER - 1)
    assert not reach.jit(1)
    assert reach.jit(1)
    monkeypatch.setenv("MODC_JIT", "0")
    assert not reach.jit(1)
    monkeypatch.setattr(reach, "_JIT", [False])  # numba missing: the numpy path, whatever is asked
    monkeypatch.setenv("MODC_JIT", "1")
    assert not reach.jit(1)


def test_a_design_run_ranks_the_same_with_either_path(monkeypatch):
    """End to end on a small cell: the designs, their joint vectors (the candidates' solutions, to
    the bit) and the search's counts."""
    from conftest import SMALL_CELL

    from modc.design import run

    c = check_text(SMALL_CELL, "small.mod")
    assert c.ok, c.diagnostics
    out = {}
    for mode in ("0", "1"):
        monkeypatch.setenv("MODC_JIT", mode)
        o = run.design(c.design.problems[0], top=3, seed=0)
        out[mode] = ([(d.chain(), d.mass, d.margin, d.candidate.solutions) for d in o.designs], o.evaluated,
                     o.excluded, o.complete)
    assert out["0"][0]
    assert out["0"] == out["1"]


def test_numpy_summing_in_another_order_keeps_the_numpy_path(monkeypatch):
    monkeypatch.setattr(reach, "_JIT", [])
    monkeypatch.setattr(reach_jit, "matches_numpy", lambda: False)
    monkeypatch.setenv("MODC_JIT", "1")
    assert not reach.jit(1)


@pytest.mark.slow
def test_the_compiled_kernel_is_cached_outside_the_source_tree(tmp_path):
    """numba's default cache is a __pycache__ beside the source (the checkout, or site-packages):
    modc's kernel goes to the user's cache (XDG_CACHE_HOME) instead, and the tree stays as it was."""
    import os
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parent.parent
    before = sorted(str(p) for p in (root / "modc").rglob("*.nb[ic]"))
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env.update(XDG_CACHE_HOME=str(tmp_path), PYTHONPATH=str(root))
    r = subprocess.run([sys.executable, "-c", "from modc.design import reach_jit; reach_jit._s3(1.0, 2.0, 3.0, False)"],
                       env=env, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    assert list((tmp_path / "modc-numba").rglob("*.nbi"))  # compiled once, kept for the next process
    assert sorted(str(p) for p in (root / "modc").rglob("*.nb[ic]")) == before
