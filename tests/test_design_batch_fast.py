"""The screen's fast path (modc.design.reach.solve: position-only rows, an element-wise LDL^T
solve, in-place updates; screen.Obstacles.nearest; search._keep building only the settings kept)
decides exactly what the plain path it replaced decided. The plain path is written out here as
the reference: 6-row Jacobians, numpy.linalg.solve per run, every run's tool rotation.

Bit-for-bit equality of joint vectors is not the contract (the reference's own last bits
depend on the LAPACK kernel numpy loads); the decisions are: feasible, reached, hit and tried
per setting and target, each feasible setting's worst share of the tolerance (to the 1 % the
order uses), the settings a search keeps and the ranking of a design run."""
from __future__ import annotations

import warnings

import numpy as np
import pytest
from conftest import SMALL_CELL, THREE_TARGETS

from modc.compiler import check_text

THREE = THREE_TARGETS

TWO = """design two {
    target a at (0.35, 0.10, 0.20) m
    target b at (-0.10, 0.30, 0.40) m
    units 1 to 4
}
"""

ORIENTED = """design ori {
    tool at (0.06, 0, 0) m
    payload 50 g at (0.01, 0, 0) m
    cylinder pillar radius 0.04 m length 0.5 m at (0.2, 0.2, 0.25) m
    sphere ball radius 0.05 m at (0.2, -0.3, 0.1) m
    target g0 at (-0.241245, -0.314383, 0.489102) m pointing (-0.720023, -0.08181, 0.689111) within 5 mm, 3 deg
    target g1 at (-0.176002, -0.058961, 0.522326) m rpy (75.5672, -13.9954, -103.2192) deg within 5 mm, 3 deg
    target g2 at (0.426825, -0.245339, 0.364955) m
    units 3
}
"""  # the farm arm's tool0 at three poses: 6-D, pointing and position-only targets it reaches


SMALL = SMALL_CELL


def problem(text: str):
    c = check_text(text, "cell.mod")
    assert c.ok, c.diagnostics
    return c.design.problems[0]


# --- the reference: the plain path as it was -------------------------------------------------------


def _rot(R, P):
    return np.stack([np.stack([R[i, 0] * P[0, k] + R[i, 1] * P[1, k] + R[i, 2] * P[2, k] for k in range(3)])
                     for i in range(3)])


def _apply(R, v):
    return np.stack([R[i, 0] * v[0] + R[i, 1] * v[1] + R[i, 2] * v[2] for i in range(3)])


def forward_plain(f, q):
    n, B = q.shape
    p, z = np.empty((n, 3, B)), np.empty((n, 3, B))
    c, s = np.cos(q), np.sin(q)
    R, t = f.k_R[0].copy(), f.k_t[0]
    for i in range(n):
        if i:
            t = t + _apply(R, f.k_t[i])
            R = _rot(R, f.k_R[i])
        x, y = R[:, 0].copy(), R[:, 1]
        R[:, 0] = c[i] * x + s[i] * y
        R[:, 1] = c[i] * y - s[i] * x
        p[i] = t
        z[i] = R[:, 2]
    return p, z, _rot(R, f.k_R[n]), t + _apply(R, f.k_t[n])


def residual_plain(runs, R_tool, t_tool):
    from modc.design.reach import _rotation_error, axis_error

    e_p = runs.xyz - t_tool
    if not runs.any_oriented:
        return e_p, np.zeros_like(e_p)
    e_r = _rotation_error(runs.R, R_tool) * runs.oriented
    if runs.any_pointed:
        e_r = np.where(runs.pointed, axis_error(R_tool[:, 0], runs.axis), e_r)
    return e_p, e_r


def solve_plain(g, tg, q0, lower, upper, iterations=None, rows=None):
    """modc.design.reach.solve before the fast path, step for step (rows: g's candidates to solve)."""
    from modc.design import reach
    from modc.design.batch import Flat

    g = g if rows is None else g.take(rows)
    iterations = reach.ITERATIONS if iterations is None else iterations
    C, n, T, S = g.pre.shape[0], g.dof, len(tg.names), q0.shape[-2]
    lo, hi = np.asarray(lower, float)[:, None], np.asarray(upper, float)[:, None]
    B = C * T * S
    c_idx, t_idx = np.repeat(np.arange(C), T * S), np.tile(np.repeat(np.arange(T), S), C)
    q_all = np.ascontiguousarray((np.tile(q0, (C * T, 1)) if q0.ndim == 2 else
                                  np.repeat(q0[:, None], T, axis=1).reshape(B, n)).T)
    ep_all, er_all = np.empty(B), np.empty(B)
    w = reach.ROTATION_WEIGHT
    live, q, f, runs = np.arange(B), q_all.copy(), Flat.of(g, c_idx), reach._Runs(tg, t_idx)
    tol_p, tol_r = np.full(B, 1e-7), np.full(B, 1e-6)
    give_up = np.asarray(tg.tol_p, float)[t_idx] * reach.STALL_FACTOR
    ref = np.full(B, np.inf)
    p, z, R_tool, t_tool = forward_plain(f, q)
    e_p, e_r = residual_plain(runs, R_tool, t_tool)
    cost = (e_p ** 2).sum(0) + w * w * (e_r ** 2).sum(0)
    lam = np.full(B, reach.LAMBDA0)
    for it in range(iterations + 1):
        ep, er = np.sqrt((e_p ** 2).sum(0)), np.sqrt((e_r ** 2).sum(0))
        active = ((ep > tol_p) | (er > tol_r)) & (lam < 1e4) & (it < iterations)
        if it % reach.STALL_EVERY == 0:
            if it >= 2 * reach.STALL_EVERY:
                active &= ~((cost > reach.STALL_GAIN * ref) & (ep > give_up))
            ref = cost.copy()
        if active.sum() < 0.8 * active.size or not active.any():
            gone = ~active
            q_all[:, live[gone]], ep_all[live[gone]], er_all[live[gone]] = q[:, gone], ep[gone], er[gone]
            live, q, f, runs = live[active], q[:, active], f.take(active), runs.take(active)
            tol_p, tol_r, give_up, ref = tol_p[active], tol_r[active], give_up[active], ref[active]
            p, z, t_tool, e_p, e_r = p[..., active], z[..., active], t_tool[:, active], e_p[:, active], e_r[:, active]
            R_tool, cost, lam = R_tool[..., active], cost[active], lam[active]
            active = active[active]
            if live.size == 0:
                break
        if not active.any():
            break
        Jp = np.cross(z, t_tool[None] - p, axis=1)
        J = np.concatenate([Jp, w * runs.rotation_rows(z, R_tool)], axis=1)
        e = np.concatenate([e_p, w * e_r], axis=0)
        A = np.einsum("ikb,jkb->bij", J, J)
        A[:, np.arange(n), np.arange(n)] += lam[:, None]
        dq = np.linalg.solve(A, np.einsum("ikb,kb->bi", J, e)[..., None])[..., 0].T
        qn = np.clip(q + dq, lo, hi)
        pn, zn, Rn, tn = forward_plain(f, qn)
        e_pn, e_rn = residual_plain(runs, Rn, tn)
        cost_n = (e_pn ** 2).sum(0) + w * w * (e_rn ** 2).sum(0)
        ok = (cost_n < cost) & active
        q[:, ok], p[..., ok], z[..., ok], t_tool[:, ok] = qn[:, ok], pn[..., ok], zn[..., ok], tn[:, ok]
        R_tool[..., ok] = Rn[..., ok]
        e_p[:, ok], e_r[:, ok], cost[ok] = e_pn[:, ok], e_rn[:, ok], cost_n[ok]
        lam = np.where(ok, np.maximum(lam / 3.0, 1e-9), lam * 4.0)
    return q_all.T.reshape(C, T, S, n), ep_all.reshape(C, T, S), er_all.reshape(C, T, S)


def distance_plain(obstacles, pts):
    out = np.empty((pts.shape[0], len(obstacles.shape)))
    for k, shape in enumerate(obstacles.shape):
        x = (pts - obstacles.centre[k]) @ obstacles.R[k]
        s = obstacles.size[k]
        if shape == 1:
            out[:, k] = np.sqrt((x * x).sum(1)) - s[0]
            continue
        d = np.abs(x) - s if shape == 0 else np.stack([np.sqrt(x[:, 0] ** 2 + x[:, 1] ** 2) - s[0],
                                                        np.abs(x[:, 2]) - s[1]], -1)
        m = np.maximum(d, 0.0)
        out[:, k] = np.sqrt((m * m).sum(1)) + np.minimum(d.max(1), 0.0)
    return out


def collides_plain(obstacles, frames, radii, step=0.02):
    """screen.collides as it was: every sample of every segment near an obstacle measured."""
    R, n = frames.shape[:2]
    if len(obstacles.shape) == 0 or R == 0:
        return np.zeros(R, bool)
    a, b = frames[:, :, :3, :], frames[:, :, 1:, :]
    mid, half = (a + b) / 2, np.linalg.norm(b - a, axis=-1) / 2
    near = distance_plain(obstacles, mid.reshape(-1, 3)).min(-1).reshape(R, n, 3) - half - radii < -1e-3
    near[:, 0, 0] = False
    out = np.zeros(R, bool)
    if not near.any():
        return out
    m = int(np.ceil(0.25 / step)) + 1
    ts = np.linspace(0.0, 1.0, m)
    r_i, n_i, s_i = np.nonzero(near)
    aa, bb = a[r_i, n_i, s_i], b[r_i, n_i, s_i]
    pts = aa[:, None, :] + (bb - aa)[:, None, :] * ts[:, None]
    d = distance_plain(obstacles, pts.reshape(-1, 3)).min(-1).reshape(len(r_i), m) - radii[s_i][:, None]
    np.logical_or.at(out, r_i, (d < -1e-3).any(-1))
    return out


def order_key_plain(f) -> tuple:
    vals = np.concatenate([np.array(f.pivots), np.array(f.ports)])
    return (round(f.worst, 2), int(np.count_nonzero(np.abs(vals) > 1e-9)), round(float(np.abs(vals).sum()), 9),
            tuple(round(float(v), 9) for v in vals))


def keep_plain(found, s, piv, por):
    """search._keep as it was: a Found for every feasible setting, then sorted."""
    from modc.design.search import KEEP, Found

    found = list(found)
    for j, c in enumerate(np.flatnonzero(s.feasible)):
        sols = tuple(tuple(tuple(float(x) for x in q) for q in per) for per in s.solutions[j])
        found.append(Found(tuple(float(x) for x in piv[c]), tuple(float(x) for x in por[c]), sols, float(s.worst[j])))
    return sorted(found, key=order_key_plain)[:KEEP]


@pytest.fixture
def plain(monkeypatch):
    """Switch the screen to the reference path (within the test)."""
    from modc.design import evaluate, reach, screen, search

    def use():
        monkeypatch.setattr(reach, "solve", solve_plain)
        monkeypatch.setattr(screen.Obstacles, "nearest", lambda self, pts: distance_plain(self, pts).min(-1))
        monkeypatch.setattr(evaluate, "collides", collides_plain)
        monkeypatch.setattr(search, "order_key", order_key_plain)
        monkeypatch.setattr(search, "_keep", keep_plain)
    return use


# --- the pieces ----------------------------------------------------------------------------------------


def test_ldl_solve_equals_lapack_on_damped_normal_equations():
    from modc.design.reach import _step

    rng = np.random.default_rng(5)
    for n, m in ((1, 3), (2, 3), (3, 3), (4, 6), (6, 6)):
        J = rng.normal(scale=0.3, size=(n, m, 500))
        J[:, :, :50] *= 1e-6  # near a singular pose: the damping carries the solve
        e = rng.normal(scale=0.05, size=(m, 500))
        lam = 10.0 ** rng.uniform(-9, 1, 500)
        A = np.einsum("ikb,jkb->bij", J, J) + lam[:, None, None] * np.eye(n)
        want = np.linalg.solve(A, np.einsum("ikb,kb->bi", J, e)[..., None])[..., 0].T
        got = _step(J, e, lam)
        assert np.allclose(got, want, rtol=1e-8, atol=1e-12 * np.abs(want).max())


def test_forward_without_rotation_gives_the_same_positions_and_axes():
    from modc.design import settings
    from modc.design.batch import Flat, forward_flat, geometry
    from modc.design.evaluate import Spec
    from modc.design.space import Shape

    spec = Spec.of(problem(THREE))
    shape = Shape((4, 4, 3), (None, None, None))
    lib, tool = spec.problem.cell.library, spec.problem.cell.tool
    types = [lib.units[k] for k in shape.kinds]
    piv, por = settings.range_settings(settings.axes(spec, shape), 3, 5000, 5200)
    g = geometry(types, piv, por, [t.x23 for t in types], tool.xyz, tool.rpy)
    f = Flat.of(g, np.repeat(np.arange(200), 4))
    q = np.random.default_rng(2).uniform(-2.5, 2.5, (3, 800))
    want = forward_plain(f, q)
    with_rot, without = forward_flat(f, q), forward_flat(f, q, rotation=False)
    for a, b in zip(want, with_rot, strict=True):
        assert np.abs(a - b).max() < 1e-12
    assert without[2] is None and all(np.abs(want[k] - without[k]).max() < 1e-12 for k in (0, 1, 3))
    # in joint 1's frame: the same points and axes once K_0 is put back
    p, z, R, t = forward_flat(f, q, local=True)
    R0, t0 = np.moveaxis(f.k_R[0], -1, 0), f.k_t[0].T  # (B, 3, 3), (B, 3)
    back = np.einsum("bij,nbj->nbi", R0, np.moveaxis(p, -1, 1)) + t0
    assert np.abs(back - np.moveaxis(want[0], -1, 1)).max() < 1e-12
    assert np.abs(np.einsum("bij,nbj->nbi", R0, np.moveaxis(z, -1, 1)) - np.moveaxis(want[1], -1, 1)).max() < 1e-12
    assert np.abs(np.einsum("bij,jb->bi", R0, t) + t0 - want[3].T).max() < 1e-12
    assert np.abs(np.einsum("bij,jkb->bik", R0, R) - np.moveaxis(want[2], -1, 0)).max() < 1e-12
    t_local = forward_flat(f, q, rotation=False, local=True)[3]
    assert np.abs(np.einsum("bij,jb->bi", R0, t_local) + t0 - want[3].T).max() < 1e-12
    one = Flat(f.k_R[:2], f.k_t[:2])  # a single joint: K_0, then K_1 to the tool
    w1 = forward_plain(one, q[:1])
    for rotation in (True, False):
        t1 = forward_flat(one, q[:1], rotation=rotation, local=True)[3]
        assert np.abs(np.einsum("bij,jb->bi", R0, t1) + t0 - w1[3].T).max() < 1e-12
        assert np.abs(forward_flat(one, q[:1], rotation=rotation)[3] - w1[3]).max() < 1e-12
    two = Flat(f.k_R[[0, 1, 3]], f.k_t[[0, 1, 3]])  # two joints
    w2 = forward_plain(two, q[:2])
    for rotation in (True, False):
        t2 = forward_flat(two, q[:2], rotation=rotation, local=True)[3]
        assert np.abs(np.einsum("bij,jb->bi", R0, t2) + t0 - w2[3].T).max() < 1e-12


def test_nearest_obstacle_equals_the_plain_distance():
    from modc.design.screen import Obstacles

    spec_obstacles = Obstacles.of(problem(THREE).cell.obstacles + problem(ORIENTED).cell.obstacles)
    pts = np.random.default_rng(4).uniform(-0.6, 0.6, (5000, 3))
    assert np.array_equal(spec_obstacles.nearest(pts), distance_plain(spec_obstacles, pts).min(-1))
    assert np.array_equal(spec_obstacles.distance(pts), distance_plain(spec_obstacles, pts))


@pytest.mark.parametrize("text", [THREE, ORIENTED])
def test_collisions_skip_only_samples_their_segment_ends_prove_clear(text):
    from modc.design import settings
    from modc.design.batch import forward, geometry
    from modc.design.evaluate import Spec
    from modc.design.screen import collides
    from modc.design.space import Shape

    spec = Spec.of(problem(text))
    shape = Shape((4, 4, 3), (None, None, None))
    lib, tool = spec.problem.cell.library, spec.problem.cell.tool
    types = [lib.units[k] for k in shape.kinds]
    piv, por = settings.range_settings(settings.axes(spec, shape), 3, 9000, 9400)
    g = geometry(types, piv, por, [t.x23 for t in types], tool.xyz, tool.rpy)
    q = np.random.default_rng(8).uniform(-2.9, 2.9, (400, 1, 1, 3))
    frames = forward(g, q, points=True)[3][:, 0, 0]
    got = collides(spec.obstacles, frames, spec.radii)
    assert np.array_equal(got, collides_plain(spec.obstacles, frames, spec.radii))
    assert 0 < got.sum() < len(got)


def test_order_keys_of_a_block_equal_the_key_of_each_setting():
    from modc.design.search import Found, _keys

    rng = np.random.default_rng(6)
    values = np.radians(np.arange(-180, 181, 15.0))
    piv, por = rng.choice(values, (300, 3)), rng.choice(values, (300, 3))
    piv[::7] = 0.0
    worst = rng.uniform(0, 1, 300).round(3)
    want = [order_key_plain(Found(tuple(map(float, a)), tuple(map(float, b)), (), float(w)))
            for a, b, w in zip(piv, por, worst, strict=True)]
    assert _keys(worst, piv, por) == want


# --- whole decisions on real shapes ---------------------------------------------------------------------


def _screen_all(text, kinds, lo, count, links=None):
    """The search's own blocks over a range of a shape's settings: per setting the bound, then the
    screen's decisions."""
    from modc.design import bounds, search, settings
    from modc.design.batch import geometry
    from modc.design.evaluate import Spec, screen_batch
    from modc.design.space import Shape

    spec = Spec.of(problem(text))
    shape = Shape(kinds, links or (None,) * len(kinds))
    lib, tool = spec.problem.cell.library, spec.problem.cell.tool
    types = [lib.units[k] for k in shape.kinds]
    ax = settings.axes(spec, shape)
    if lo is None:  # around the farm arm's own twists
        farm = ((0.0,), (-np.pi / 2, np.pi / 4), (0.0, 0.0))
        at = [int(np.argmin(np.abs(a - farm[i][0 if r == "pivot" else 1]))) for a, (r, i) in zip(ax.values, ax.roles,
                                                                                                    strict=True)]
        lo = int(np.ravel_multi_index(at, [len(a) for a in ax.values])) - count // 2
    piv, por = settings.range_settings(ax, shape.n, lo, lo + count)
    links_m = [(x if x is not None else t.x23) for t, x in zip(types, shape.links, strict=True)]
    g = geometry(types, piv, por, links_m, tool.xyz, tool.rpy)
    k = np.flatnonzero(bounds.possible(bounds.frames(g), spec.targets.xyz, spec.targets.tol_p).all(-1))
    s = screen_batch(spec, shape, piv[k], por[k], search.shape_seed(0, shape),
                     g=type(g)(g.pre[k], g.post[k], g.t1, g.flange_tool))
    return k, s


CASES = [(THREE, (4, 4, 3), 421824, 1500, None), (TWO, (1, 4, 3), 17576, 2500, None),
         (ORIENTED, (1, 4, 3), None, 3000, (None, None, 0.18))]


@pytest.mark.parametrize("text, kinds, lo, count, links", CASES)
def test_the_fast_screen_decides_what_the_plain_screen_decided(plain, text, kinds, lo, count, links):
    k, fast = _screen_all(text, kinds, lo, count, links)
    plain()
    k2, ref = _screen_all(text, kinds, lo, count, links)
    assert np.array_equal(k, k2) and fast.feasible.any() and not fast.feasible.all()
    for what in ("feasible", "reached", "hit", "tried"):
        assert np.array_equal(getattr(fast, what), getattr(ref, what)), what
    assert np.array_equal(np.round(fast.worst, 2), np.round(ref.worst, 2))
    done = np.isfinite(ref.closest)
    assert np.array_equal(np.isfinite(fast.closest), done)
    assert np.allclose(fast.closest[done], ref.closest[done], rtol=0, atol=1e-9)
    assert len(fast.solutions) == len(ref.solutions)
    for a, b in zip(fast.solutions, ref.solutions, strict=True):
        assert [len(x) for x in a] == [len(x) for x in b]


def test_a_shape_search_keeps_the_settings_the_plain_path_kept(plain):
    from modc.design import search
    from modc.design.evaluate import Spec
    from modc.design.space import Shape

    spec = Spec.of(problem(TWO))
    shape = Shape((1, 4, 3), (None, None, None))
    fast = search.search_part(spec, shape, ((17576, 21672),), 0)
    plain()
    ref = search.search_part(spec, shape, ((17576, 21672),), 0)
    assert fast.found and len(fast.found) == len(ref.found) == search.KEEP
    assert [(f.pivots, f.ports, round(f.worst, 2)) for f in fast.found] == \
        [(f.pivots, f.ports, round(f.worst, 2)) for f in ref.found]
    assert (fast.screened, fast.excluded, fast.hit, fast.clear) == (ref.screened, ref.excluded, ref.hit, ref.clear)
    for a, b in zip(fast.found, ref.found, strict=True):
        assert np.allclose(np.array(a.solutions[0][0]), np.array(b.solutions[0][0]), atol=1e-6)


@pytest.mark.slow
@pytest.mark.parametrize("text", [SMALL, TWO.replace("units 1 to 4", "units 1 to 3")])
def test_a_design_run_ranks_as_the_plain_path_ranked(plain, text):
    from modc.design import run

    p = problem(text)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        fast = run.design(p, top=5, seed=0)
        plain()
        ref = run.design(p, top=5, seed=0)
    assert fast.designs and len(fast.designs) == len(ref.designs)
    # the chains, their mass and margin, and the joint vectors the exact check chose per target
    assert [(d.chain(), round(d.mass, 9), round(d.margin, 6)) for d in fast.designs] == \
        [(d.chain(), round(d.mass, 9), round(d.margin, 6)) for d in ref.designs]
    for a, b in zip(fast.designs, ref.designs, strict=True):
        for name, got in a.verified.targets.items():
            assert np.allclose(got["q"], b.verified.targets[name]["q"], atol=1e-6)
    assert (fast.evaluated, fast.excluded) == (ref.evaluated, ref.excluded)
