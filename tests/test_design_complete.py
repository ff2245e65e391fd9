"""The search is complete within its bounds: compared with a brute-force enumeration written
here, independently of modc.design (its own forward kinematics from docs/conventions.md's formula,
its own damped-least-squares IK), on cells small enough to enumerate; and the sound bounds never
exclude a point some joint vector reaches."""
from __future__ import annotations

import itertools
import math
import warnings

import numpy as np
import pytest

from modc.compiler import check_text
from modc.kinematics import transform

PIVOTS = np.radians(np.arange(-90.0, 90.1, 15.0))
PORTS = np.radians(np.arange(-180.0, 180.0, 15.0))
LIMIT = math.radians(170.0)


def _rx(a):
    c, s = np.cos(a), np.sin(a)
    o, z = np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([o, z, z], -1), np.stack([z, c, -s], -1), np.stack([z, s, c], -1)], -2)


def _ry(a):
    c, s = np.cos(a), np.sin(a)
    o, z = np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([c, z, s], -1), np.stack([z, o, z], -1), np.stack([-s, z, c], -1)], -2)


def _rz(a):
    c, s = np.cos(a), np.sin(a)
    o, z = np.ones_like(a), np.zeros_like(a)
    return np.stack([np.stack([c, -s, z], -1), np.stack([s, c, z], -1), np.stack([z, z, o], -1)], -2)


def fk(units, pivots, ports, q, tool=(0.0, 0.0, 0.0)):
    """docs/conventions.md: T = prod_i A_t1(pivot_i) A_J(theta_i) A_t2(port_i), then the tool offset.
    A_t1 = (Ry(pivot), (x01, 0, z01)), A_J = (Rz(theta), (0, 0, z12)), A_t2 = (Rx(port), (x23, 0, 0)).
    Broadcasts over leading axes; returns tool0's position (..., 3)."""
    shape = np.broadcast_shapes(pivots.shape[:-1], q.shape[:-1])
    R = np.broadcast_to(np.eye(3), shape + (3, 3))
    p = np.zeros(shape + (3,))
    for i, u in enumerate(units):
        p = p + R @ np.array([u["x01"], 0.0, u["z01"]])
        R = R @ _ry(pivots[..., i])
        R = R @ _rz(q[..., i])
        p = p + R @ np.array([0.0, 0.0, u["z12"]])
        if u["link"]:
            R = R @ _rx(ports[..., i])
            p = p + R @ np.array([u["x23"], 0.0, 0.0])
    return p + R @ np.asarray(tool, float)


def dls(units, pivots, ports, target, seeds, iterations=60):
    """Smallest position error (C,) from per-setting seeds (S, C, n): damped least squares with a
    numerical Jacobian, joints clamped to +-170 deg."""
    C, n = pivots.shape
    best = np.full(C, np.inf)
    for q0 in seeds:
        q = q0.copy()
        lam = np.full(C, 1e-2)
        e = target - fk(units, pivots, ports, q)
        err = np.linalg.norm(e, axis=-1)
        for _ in range(iterations):
            J = np.stack([(fk(units, pivots, ports, q + 1e-7 * np.eye(n)[k]) - (target - e)) / 1e-7
                          for k in range(n)], -1)
            A = np.swapaxes(J, -1, -2) @ J + lam[:, None, None] * np.eye(n)
            dq = np.linalg.solve(A, (np.swapaxes(J, -1, -2) @ e[..., None]))[..., 0]
            qn = np.clip(q + dq, -LIMIT, LIMIT)
            en = target - fk(units, pivots, ports, qn)
            errn = np.linalg.norm(en, axis=-1)
            ok = errn < err
            q[ok], e[ok], err[ok] = qn[ok], en[ok], errn[ok]
            lam = np.where(ok, lam / 3, lam * 4)
        best = np.minimum(best, err)
    return best


def brute_force(units, pivots, ports, target, step_deg=15.0, keep=3):
    """Every setting: a grid over the joints (every step_deg within the limits), then damped least
    squares from the keep best grid points of each setting."""
    n = pivots.shape[1]
    axis = np.radians(np.arange(-170.0, 170.1, step_deg))
    grid = np.array(list(itertools.product(axis, repeat=n)))  # (G, n)
    seeds = np.empty((keep, len(pivots), n))
    for lo in range(0, len(pivots), 256):
        sl = slice(lo, lo + 256)
        x = fk(units, pivots[sl, None], ports[sl, None], grid[None])  # (c, G, 3)
        d = np.linalg.norm(x - target, axis=-1)
        best = np.argsort(d, axis=1)[:, :keep]
        seeds[:, sl] = np.moveaxis(grid[best], 1, 0)
    return dls(units, pivots, ports, target, seeds)


def library_units():
    c = check_text("design d {\n    target a at (0.3, 0, 0.2) m\n}\n", "d.mod")
    lib = c.design.problems[0].cell.library
    return {k: {"x01": u.x01, "z01": u.z01, "z12": u.z12, "x23": u.x23, "link": u.link} for k, u in lib.units.items()}


def test_bounds_never_exclude_a_reachable_point():
    from modc.design import bounds
    from modc.design.batch import geometry

    c = check_text("design d {\n    target a at (0.3, 0, 0.2) m\n}\n", "d.mod")
    lib = c.design.problems[0].cell.library
    rng = np.random.default_rng(5)
    for n in range(1, 7):
        kinds = rng.integers(1, 5, n)
        types = [lib.units[k] for k in kinds]
        units = [library_units()[k] for k in kinds]
        C = 400
        piv = PIVOTS[rng.integers(len(PIVOTS), size=(C, n))]
        por = PORTS[rng.integers(len(PORTS), size=(C, n))] * np.array([u["link"] for u in units])
        q = rng.uniform(-LIMIT, LIMIT, (C, n))
        tool = (0.05, 0.01, -0.02)
        x = fk(units, piv, por, q, tool)
        g = geometry(types, piv, por, [t.x23 for t in types], tool, (0.0, 0.0, 0.0))
        ok = bounds.possible(bounds.frames(g), x, np.zeros(C))
        assert np.diag(ok).all(), n  # each setting's own FK point stays possible
        if n <= 3:
            assert not ok.all()  # and the bound does exclude something


def _problem(text):
    c = check_text(text, "cell.mod")
    assert c.ok, c.diagnostics
    return c.design.problems[0]


def _two_target_cell():
    """A 2-module arm H4-L3 with random twists, two targets at its tool0 for two joint vectors
    (far enough that no link-free chain gets there)."""
    units = library_units()
    rng = np.random.default_rng(11)
    arm = [units[4], units[3]]
    while True:
        piv = PIVOTS[rng.integers(len(PIVOTS), size=2)]
        por = np.array([PORTS[rng.integers(len(PORTS))], 0.0])
        qs = rng.uniform(-2.5, 2.5, (2, 2))
        xs = fk(arm, piv[None], por[None], qs)
        if np.all(np.linalg.norm(xs, axis=-1) > 0.32) and np.linalg.norm(xs[0] - xs[1]) > 0.1:
            break
    text = "design two {\n" + "".join(
        f"    target t{k} at ({x:.9f}, {y:.9f}, {z:.9f}) m within 3 mm, 2 deg\n" for k, (x, y, z) in enumerate(xs)
    ) + "    units 2\n    modules H4, L3\n}\n"
    return text, xs, arm, piv, por


@pytest.mark.slow
def test_two_target_cell_every_working_setting_is_found(monkeypatch):
    """H4-L3 has 13 x 24 x 13 = 4,056 twist settings (over the old 1,536 cut-off for full
    enumeration); only a few reach both targets. The search finds each one the brute force finds,
    and ranks the one deepest inside the tolerances first."""
    from modc.design import run, search
    from modc.design.evaluate import Spec
    from modc.design.space import Shape

    text, xs, arm, piv0, por0 = _two_target_cell()
    p = _problem(text)
    grid = np.array(list(itertools.product(PIVOTS, PORTS, PIVOTS)))
    pivots = grid[:, [0, 2]]
    ports = np.stack([grid[:, 1], np.zeros(len(grid))], -1)
    err = np.max([brute_force(arm, pivots, ports, x) for x in xs], axis=0)
    brute = {(tuple(np.round(pv, 6)), tuple(np.round(po, 6))) for pv, po, e in zip(pivots, ports, err, strict=True)
             if e <= 0.003}
    clear = {(tuple(np.round(pv, 6)), tuple(np.round(po, 6))) for pv, po, e in zip(pivots, ports, err, strict=True)
             if e <= 0.0015}
    assert (tuple(np.round(piv0, 6)), tuple(np.round(por0, 6))) in clear
    assert 1 <= len(brute) <= 40  # only a few work

    monkeypatch.setattr(search, "KEEP", 10_000)
    spec = Spec.of(p)
    res = search.search_shape(spec, Shape((4, 3), (None, None)), 0)
    assert res.complete and res.evaluated == 4056
    found = {(tuple(np.round(f.pivots, 6)), tuple(np.round(f.ports, 6))) for f in res.found}
    assert clear <= found  # every setting clearly inside the tolerance for the brute force is found
    assert found <= brute  # and nothing the brute force cannot confirm
    monkeypatch.undo()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        o = run.design(p, top=3, seed=0)
    assert o.designs and o.complete and o.designs[0].modules == 2
    best = o.designs[0].candidate
    worst = [max(t["position_error_m"] for t in d.verified.targets.values()) for d in o.designs]
    assert (tuple(np.round(best.pivots, 6)), tuple(np.round(best.ports, 6))) in brute
    assert worst[0] <= min(worst) + 1e-6 or o.designs[0].mass < o.designs[1].mass


@pytest.mark.parametrize("cell", [
    "box floor size (6, 6, 0.03) m at (0, 0, -0.02) m\n    target a at (0.30, 0.10, -0.25) m",
    "box machine size (0.2, 0.2, 0.2) m at (0.35, 0, 0.2) m\n    target a at (0.35, 0.0, 0.20) m",
])
def test_a_target_walled_off_or_buried_is_named_without_a_search(cell):
    """Below a floor wider than any arm's reach, or deep inside a machine: no arm serves target a
    (a sound bound, no IK), and the no-design answer names it and the obstacle, not target b."""
    from modc.design import run

    p = _problem(f"design d {{\n    {cell}\n    target b at (0.25, -0.15, 0.30) m\n    units 1 to 6\n}}\n")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        o = run.design(p, top=1, seed=0)
    assert not o.designs and o.evaluated == 0
    why = o.why_none()
    assert "target 'a'" in why and "obstacles" in why and "target 'b'" not in why and "inf" not in why
    assert o.targets["a"]["ruled_out_by"] == "obstacles" and o.targets["b"]["reached_alone"]


@pytest.mark.parametrize("units", [4, 5])
def test_shapes_of_many_units_whose_every_family_is_out_of_reach_are_complete(units):
    """Two targets beyond what any twist setting of `units` units reaches, but within every
    offset laid end to end (the old shape-level bound): the search rules every setting out by
    families, so it is complete with no coarse grid, and says the targets are out of reach."""
    from modc.design import run
    from modc.design.screen import reach_bound

    r = {4: 1.3, 5: 1.6}[units]
    p = _problem(f"design d {{\n    target a at ({r}, 0.0, 0.3) m\n    target b at (0.0, {r}, 0.2) m\n"
                 f"    units {units}\n}}\n")
    lib = p.cell.library
    longest = reach_bound([lib.units[4]] * units, [lib.units[4].x23] * units, (0.0, 0.0, 0.0))
    assert longest > 1.05 * float(np.hypot(r, 0.3))  # the old bound would search these shapes
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        o = run.design(p, top=1, seed=0)
    assert not o.designs and o.complete and not o.coarse and o.screened == 0
    assert o.evaluated == o.excluded > 10**8  # every setting of the long shapes, none listed
    why = o.why_none()
    # both named, under the one reason they share
    assert "targets 'a', 'b': out of reach" in why and "inf" not in why


@pytest.mark.slow
def test_top_designs_are_distinct_arms_with_variant_swaps_as_alternatives():
    """H1-H1-L3 and H1-L1-L3 are one arm (H and L units of a type share their geometry): one entry,
    the other listed as its alternative, in ranking.json too."""
    from modc.design import run
    from modc.design.rank import identity
    from modc.design.write import ranking

    p = _problem("""design small {
    payload 100 g
    target a at (0.30, 0.10, 0.25) m
    target b at (0.25, -0.15, 0.30) m
    units 3
    modules H1, L1, L3
}
""")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        o = run.design(p, top=2, seed=0)
    assert len(o.designs) == 2 and o.complete
    assert identity(o.designs[0]) != identity(o.designs[1])
    with_alt = [d for d in o.designs if d.alternatives]
    assert with_alt
    d = with_alt[0]
    assert all(identity(a) == identity(d) and a.chain() != d.chain() for a in d.alternatives)
    entry = ranking([o])["designs"][o.designs.index(d)]
    assert entry["alternatives"][0]["chain"] == d.alternatives[0].chain()


def test_families_excluded_whole_never_hold_a_reaching_setting():
    """modc.design.prefix rules out a family of settings (a prefix of the chain fixed, the rest
    free) by one test: for random settings of random shapes, the point their tool0 reaches stays
    possible for every family the setting belongs to, at every depth; and the option lists the
    families are built from multiply to the shape's settings."""
    from modc.design import bounds, prefix, settings, space
    from modc.design.batch import geometry
    from modc.design.evaluate import Spec

    prob = _problem("design d {\n    tool at (0.05, 0.01, -0.02) m\n    target a at (0.3, 0, 0.2) m\n"
                    "    units 1 to 6\n}\n")
    lib, spec = prob.cell.library, Spec.of(prob)
    rng = np.random.default_rng(7)
    for n in range(1, 7):
        kinds = tuple(int(k) for k in rng.integers(1, 5, n))
        shape = space.Shape(kinds, (None,) * n)
        ax = settings.full_axes(spec, shape)
        types = [lib.units[k] for k in kinds]
        units = [library_units()[k] for k in kinds]
        links = [t.x23 for t in types]
        lv = prefix.levels(types, links, ax.values[0], PORTS, space.port_free(prob, shape, lib),
                           transform((0.05, 0.01, -0.02), (0.0, 0.0, 0.0)))
        assert math.prod(len(level.t) for level in lv) == ax.count
        C = 300
        piv = PIVOTS[rng.integers(len(PIVOTS), size=(C, n))]
        por = PORTS[rng.integers(len(PORTS), size=(C, n))] * np.array(space.port_free(prob, shape, lib))
        x = fk(units, piv, por, rng.uniform(-LIMIT, LIMIT, (C, n)), (0.05, 0.01, -0.02))
        f = bounds.frames(geometry(types, piv, por, links, (0.05, 0.01, -0.02), (0.0, 0.0, 0.0)))
        U = prefix.tails(lv)
        for k in range(1, n + 2):
            family = bounds.Frames(f.R[:, :k], f.t[:, :k])
            ok = bounds.possible(family, x, np.zeros(C), U[k - 1] if k <= n else None)
            assert np.diag(ok).all(), (kinds, k)
        far = prefix.refine(lv, np.array([[2.5, 0.0, 0.3]]), np.array([0.005]))
        assert far.settings == 0  # a point beyond every setting's reach: every family excluded


def test_a_setting_that_reaches_the_target_lies_in_a_family_left_alive():
    """The numbering of families is the search's numbering of settings: for a setting picked at
    random (by its number), a target put where its tool0 gets lies in a range left alive."""
    from modc.design import prefix, settings, space
    from modc.design.batch import forward, geometry
    from modc.design.evaluate import Spec

    prob = _problem("design d {\n    target a at (0.25, 0.1, 0.3) m\n    units 4\n}\n")
    lib, spec = prob.cell.library, Spec.of(prob)
    rng = np.random.default_rng(3)
    for kinds in [(4, 1, 3), (3, 4, 2), (4, 3, 4, 3), (1, 4, 2, 3)]:
        shape = space.Shape(kinds, (None,) * len(kinds))
        ax = settings.full_axes(spec, shape)
        types = [lib.units[k] for k in kinds]
        links = [t.x23 for t in types]
        lv = prefix.levels(types, links, ax.values[0], space.twist_values(lib.twists.port),
                           space.port_free(prob, shape, lib), np.eye(4))
        for _ in range(5):
            i = int(rng.integers(ax.count))
            piv, por = settings.range_settings(ax, len(kinds), i, i + 1)
            q = rng.uniform(-LIMIT, LIMIT, (1, 1, 1, len(kinds)))
            x = forward(geometry(types, piv, por, links, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)), q)[2][0, 0, 0, :3, 3]
            fam = prefix.refine(lv, x[None], np.array([1e-4]), cap=20_000)
            if len(kinds) == 3:
                assert fam.settings < ax.count  # a point target does rule families out
            assert any(lo <= i < hi for lo, hi in fam.ranges()), (kinds, i)


def test_a_huge_region_keeps_to_the_time_budget_and_names_targets_by_reason(tmp_path):
    """A 100 x 100 region is 10,000 targets: the budget holds inside a block of settings (checked
    between targets), the diagnosis does not probe 10,000 targets after it, and the no-design
    message names a few targets per reason and counts the rest."""
    from conftest import modc_design

    text = ("design huge {\n    target a at (0.30, 0.10, 0.25) m\n"
            "    region tray box size (0.10, 0.10, 0) m at (0.30, 0, 0.15) m grid 100 x 100 x 1\n"
            "    task serve { visit a, tray }\n    units 2\n    modules H1, L3\n}\n")
    r = modc_design(tmp_path, text, "--time-budget", "3s", timeout=600)
    assert r.returncode == 1, r.stderr
    assert ("time budget" in r.stderr or "the time ran out" in r.stderr) and "Traceback" not in r.stderr
    assert " more: " in r.stderr and len(r.stderr) < 5000  # 'tray[…]' five times, the rest counted


def test_family_bounds_test_a_spread_subset_of_many_targets():
    """A region of hundreds of neighbouring points: the family bounds test at most SPREAD of them,
    spread out, every one a target (sound: a family that misses one misses them all); few targets
    are all kept."""
    from modc.design import prefix

    xyz = np.array([[0.3 + 0.005 * i, 0.005 * j, 0.2] for i in range(20) for j in range(20)])
    tol = np.full(len(xyz), 0.005)
    sub, sub_tol = prefix.spread(xyz, tol)
    assert len(sub) == prefix.SPREAD and len(sub_tol) == prefix.SPREAD
    assert {tuple(p) for p in sub} <= {tuple(p) for p in xyz}
    corners = {(0.3, 0.0), (0.3 + 0.095, 0.0), (0.3, 0.095), (0.3 + 0.095, 0.095)}
    assert corners <= {(round(p[0], 9), round(p[1], 9)) for p in sub}  # the extremes are among them
    few = xyz[:5]
    assert prefix.spread(few, tol[:5])[0] is few


def test_a_search_stopped_before_any_design_does_not_claim_that_none_exists():
    """Stopped by the budget with every target reached alone: only the chains searched are known
    to fail together (it said "no chain reaches all of them", as a complete search does)."""
    from modc.design.outcome import Outcome

    p = _problem("design d {\n    box wall size (0.1, 0.1, 0.1) m at (0.5, 0.5, 0) m\n"
                 "    target a at (0.3, 0.1, 0.3) m\n    target b at (0.2, -0.2, 0.3) m\n    units 1 to 3\n}\n")
    alone = {"reached_alone": True}
    o = Outcome(p, [], targets={"a": alone, "b": alone})
    assert "no chain reaches all of them without touching the cell" in o.why_none()
    o.stopped = "time budget"
    why = o.why_none()
    assert why.startswith("the search stopped (time budget) before finding one")
    assert "no chain searched before it stopped reaches all of them" in why and "--time-budget" in why
    assert "no chain reaches" not in why
