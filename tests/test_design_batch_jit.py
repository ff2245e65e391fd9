"""The compiled IK (modc.design.reach_jit for position-only batches, reach_jit_pose for batches with
`rpy` or `pointing` targets; numba) returns bit for bit what the numpy path of
modc.design.reach.solve returns - the same joint vectors and errors for every run, so every screen
decision, kept setting and ranking is the same with numba or without it."""
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


# oriented targets: full poses (6 rows), directions only (5), a position-only one among them
ORIENTED = """design posed {
    payload 100 g
    target a at (0.30, 0.10, 0.25) m rpy (0, 90, 0) deg
    target b at (0.25, -0.15, 0.30) m pointing (0, 0, -1) within 0.5 mm, 1 deg
    target c at (0.10, 0.30, 0.45) m
    target d at (0.20, 0.0, 0.35) m pointing (1, 0, 0)
    target e at (0.35, 0.05, 0.15) m rpy (180, 0, 45) deg within 2 mm, 3 deg
    target far at (0.9, 0.9, 0.9) m rpy (0, 0, 30) deg
    units 1 to 6
}
"""
# which of ORIENTED's targets: poses only, directions only, mixed (with a position-only target)
SETS = {"rpy": [0, 4, 5], "pointing": [1, 3], "mixed": [0, 1, 2, 3, 4, 5]}


def _spec(text):
    c = check_text(text, "cell.mod")
    assert c.ok, c.diagnostics
    return Spec.of(c.design.problems[0])


@pytest.fixture(scope="module")
def spec():
    return _spec(CELL)


@pytest.fixture(scope="module")
def posed():
    return _spec(ORIENTED)


def _solve(monkeypatch, jit: bool, *args, **kw):
    monkeypatch.setenv("MODC_JIT", "1" if jit else "0")
    assert reach.jit() is jit
    return reach.solve(*args, **kw)


KINDS = [(4,), (2, 3), (1, 4, 3), (4, 4, 3), (4, 3, 4, 3), (1, 2, 3, 4, 4), (4, 3, 4, 3, 4, 3)]


def _candidates(spec, kinds, count):
    """count candidates of the chain `kinds` (spread over its settings) as a batch.Geometry."""
    lib = spec.problem.cell.library
    n = len(kinds)
    ax = settings.axes(spec, Shape(kinds, (None,) * n))
    rng = np.random.default_rng(n)
    idx = np.sort(rng.choice(min(ax.count, 10 ** 9), size=min(count, ax.count), replace=False)).astype(np.int64)
    piv, por = settings.settings_at(ax, n, idx)
    types = [lib.units[k] for k in kinds]
    tool = spec.problem.cell.tool
    return geometry(types, piv, por, [t.x23 for t in types], tool.xyz, tool.rpy)


def _equal(monkeypatch, *args, **kw):
    """Both paths on one batch; an oriented batch must reach the compiled kernel of poses."""
    from modc.design import reach_jit_pose

    calls = []
    kernel = reach_jit_pose.solve
    monkeypatch.setattr(reach_jit_pose, "solve", lambda *a, **k: calls.append(1) or kernel(*a, **k))
    a = _solve(monkeypatch, False, *args, **kw)
    assert not calls
    b = _solve(monkeypatch, True, *args, **kw)
    assert len(calls) == bool(np.asarray(args[1].oriented).any())
    for x, y in zip(a, b, strict=True):
        assert x.shape == y.shape
        assert np.array_equal(x, y)
    return a


@pytest.mark.parametrize("kinds", KINDS)
@pytest.mark.parametrize("per_candidate", [False, True])
def test_compiled_runs_equal_the_numpy_runs_bit_for_bit(monkeypatch, spec, kinds, per_candidate):
    n = len(kinds)
    g = _candidates(spec, kinds, 200)
    rng = np.random.default_rng(n)
    lo, hi = np.full(n, spec.lower), np.full(n, spec.upper)
    q0 = reach.seeds(n, 4, lo, hi, 7)
    if per_candidate:  # a warm start per candidate (C, 1, n), as the screen passes it
        q0 = np.clip(rng.normal(size=(g.pre.shape[0], 1, n)), lo, hi)
    a = _solve(monkeypatch, False, g, spec.targets, q0, lo, hi)
    b = _solve(monkeypatch, True, g, spec.targets, q0, lo, hi)
    for x, y in zip(a, b, strict=True):
        assert x.shape == y.shape
        assert np.array_equal(x, y)
    # the case is not trivial: some runs reach a target, some stall, the far target none
    hit = a[1] <= spec.targets.tol_p[None, :, None]
    assert hit.any() or n < 3
    assert not hit[:, 3].any()


@pytest.mark.parametrize("kinds", KINDS)
@pytest.mark.parametrize("which", sorted(SETS))
@pytest.mark.parametrize("limits", ["library", "narrow"])
def test_oriented_runs_equal_the_numpy_runs_bit_for_bit(monkeypatch, posed, kinds, which, limits):
    """rpy (6 rows), pointing (5) and mixed batches, all chain lengths, the library's joint limits
    or narrow ones (the clip binds), from several seeds and from a warm start per candidate."""
    n = len(kinds)
    g = _candidates(posed, kinds, 120)
    tg = posed.targets.take(np.array(SETS[which]))
    lo, hi = np.full(n, posed.lower), np.full(n, posed.upper)
    if limits == "narrow":
        lo, hi = np.linspace(-1.2, -0.4, n), np.linspace(0.5, 1.5, n)
    a = _equal(monkeypatch, g, tg, reach.seeds(n, 3, lo, hi, 11), lo, hi)
    rng = np.random.default_rng(n)
    _equal(monkeypatch, g, tg, np.clip(rng.normal(size=(g.pre.shape[0], 1, n)), lo, hi), lo, hi)
    # not trivial: runs meet poses and directions (6 joints), positions (from 3), none the far target
    hit = (a[1] <= tg.tol_p[None, :, None]) & (a[2] <= tg.tol_r[None, :, None])
    if n == 6 and limits == "library":
        assert hit[:, tg.oriented].any()
    if which == "mixed" and n >= 3:
        assert hit.any()
    if which != "pointing":
        assert not hit[:, -1].any()
    assert (a[2][:, tg.oriented] > 0).any()


def test_oriented_one_run_few_iterations_and_half_turns_equal_too(monkeypatch, posed):
    """A batch of one (numpy sums in lanes there), cut short, and the branches for a turn of 180°:
    a pose target turned half way round from the start, a direction opposite tool0's x axis."""
    from modc.design.batch import forward

    kinds = (1, 4, 3)
    g = _candidates(posed, kinds, 1)
    lo, hi = np.full(3, posed.lower), np.full(3, posed.upper)
    q0 = np.zeros((1, 3))
    for it in (0, 1, 7, 12, 40):
        for k in range(len(posed.targets.names)):
            _equal(monkeypatch, g, posed.targets.take(slice(k, k + 1)), q0, lo, hi, it)
    _, _, M, _ = forward(g, np.zeros((1, 1, 1, 3)))
    R0, x0 = M[0, 0, 0, :3, :3], M[0, 0, 0, :3, 3]
    half = np.diag([1.0, -1.0, -1.0])  # 180° about x
    tg = reach.Targets(np.array([x0, x0]), np.array([R0 @ half, R0]), np.array([True, True]), np.array([1e-3, 1e-3]),
                       np.array([0.02, 0.02]), ("turned", "opposite"), np.array([[1.0, 0, 0], -R0[:, 0]]),
                       np.array([False, True]))
    e = reach._rotation_error(np.moveaxis(tg.R[:1], 0, -1), np.moveaxis(R0[None], 0, -1))
    assert np.isclose(np.linalg.norm(e), np.pi)  # the half-turn branch of batch.rotation_error
    assert np.isclose(np.linalg.norm(reach.axis_error(R0[:, :1], -R0[:, :1])), np.pi)  # opposite axes
    for it in (0, 1, 40):
        a = _equal(monkeypatch, g, tg, q0, lo, hi, it)
        assert it or np.allclose(a[2], np.pi)


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


def _posed_cell() -> str:
    """A full pose and a direction that an H1 - L3 - L3 arm meets with its own twists."""
    from modc.design.batch import forward
    from modc.kinematics import matrix_rpy

    lib = check_text("design d {\n    target a at (0.3, 0, 0.2) m\n}\n", "d.mod").design.problems[0].cell.library
    types = [lib.units[k] for k in (1, 3, 3)]
    g = geometry(types, np.radians([[0.0, 45.0, 0.0]]), np.radians([[0.0, 30.0, 90.0]]), [t.x23 for t in types],
                 (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    _, _, T, _ = forward(g, np.array([[0.3, -0.8, 0.5], [1.2, 0.6, -0.4]])[None, :, None, :])
    x, R = T[0, :, 0, :3, 3], T[0, :, 0, :3, :3]
    r = np.degrees(matrix_rpy(R[0]))
    return ("design posed {\n"
            f"    target t0 at ({x[0, 0]:.6f}, {x[0, 1]:.6f}, {x[0, 2]:.6f}) m"
            f" rpy ({r[0]:.4f}, {r[1]:.4f}, {r[2]:.4f}) deg within 5 mm, 3 deg\n"
            f"    target t1 at ({x[1, 0]:.6f}, {x[1, 1]:.6f}, {x[1, 2]:.6f}) m"
            f" pointing ({R[1, 0, 0]:.6f}, {R[1, 1, 0]:.6f}, {R[1, 2, 0]:.6f}) within 5 mm, 3 deg\n"
            "    units 2 to 3\n    modules H1, L3\n}\n")


@pytest.mark.parametrize("cell", ["small", "posed"])
def test_a_design_run_ranks_the_same_with_either_path(monkeypatch, cell):
    """End to end on a small cell, and on one with a full pose and a direction: the designs, their
    joint vectors (the candidates' solutions, to the bit) and the search's counts."""
    from conftest import SMALL_CELL

    from modc.design import run

    c = check_text(SMALL_CELL if cell == "small" else _posed_cell(), "cell.mod")
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


def test_numpy_with_its_own_arccos_keeps_oriented_batches_on_the_numpy_path(monkeypatch, posed):
    """Where numpy's arccos or arctan2 are not the C library's (its AVX-512 builds), the pose kernel
    could not return numpy's bits: oriented batches stay in numpy, position-only ones compile."""
    from modc.design import reach_jit_pose

    assert reach_jit_pose.matches_numpy()  # here they are
    monkeypatch.setattr(reach_jit_pose, "matches_numpy", lambda: False)
    calls = []
    monkeypatch.setattr(reach_jit_pose, "solve", lambda *a, **k: calls.append(1))
    g = _candidates(posed, (1, 4, 3), 20)
    lo, hi = np.full(3, posed.lower), np.full(3, posed.upper)
    q0 = reach.seeds(3, 2, lo, hi, 0)
    a = _solve(monkeypatch, True, g, posed.targets, q0, lo, hi)
    assert not calls and a[2].any()
    position = posed.targets.take(np.array([2]))
    assert np.array_equal(_solve(monkeypatch, True, g, position, q0, lo, hi)[1],
                          _solve(monkeypatch, False, g, position, q0, lo, hi)[1])


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
    r = subprocess.run([sys.executable, "-c", "import numpy as np; from modc.design import reach_jit, reach_jit_pose; "
                        "reach_jit._s3(1.0, 2.0, 3.0, False); reach_jit_pose._dot(np.ones(6), np.ones(6), 6, False)"],
                       env=env, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    # compiled once, kept for the next process: both kernels' modules
    assert list((tmp_path / "modc-numba").rglob("reach_jit._s3*.nbi"))
    assert list((tmp_path / "modc-numba").rglob("reach_jit_pose._dot*.nbi"))
    assert sorted(str(p) for p in (root / "modc").rglob("*.nb[ic]")) == before
