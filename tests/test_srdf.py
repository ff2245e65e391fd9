"""SRDF backend and self-collision matrix (modc/backends/srdf.py, modc/physical/collisions.py).

The checks that matter are made independently of the code under test: the URDF and meshes come
from a normal compile (compiled_examples), pinocchio and coal are called directly here, and the
samples are drawn here with another generator and another seed.
"""
from __future__ import annotations

import os
import subprocess
import sys
import textwrap
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from conftest import EXAMPLES, ROOT, checked_ok

from modc.backends import Build, srdf
from modc.compiler import check_file
from modc.model import Robot
from modc.physical import collisions

RESAMPLES = 2000
RESEED = 20240917  # not the backend's seed


def _build(checked, samples=None, seed=None) -> Build:
    b = Build(checked.design, diagnostics=list(checked.diagnostics))
    if samples is not None:
        b.collision_samples = samples
    if seed is not None:
        b.seed = seed
    return b


@pytest.fixture(scope="module")
def example_srdfs() -> dict[str, tuple[Build, dict[str, str]]]:
    """Every example: its Build (default options) and SRDF files, emitted by the backend directly."""
    out = {}
    for ex in EXAMPLES:
        c = check_file(ex)
        assert c.ok, ex
        b = _build(c)
        out[ex.stem] = (b, srdf.emit(b))
    return out


def _robots(build: Build) -> list[Robot]:
    return list(build.design.robots)


def _urdf(out_dir: Path, robot: Robot) -> tuple[Path, ET.Element]:
    path = out_dir / "urdf" / f"{robot.file_stem}.urdf"
    return path, ET.parse(path).getroot()


def _pin(urdf_path: Path):
    """pinocchio model + collision geometry straight from a compiled tree (no modc code)."""
    import pinocchio as pin

    model = pin.buildModelFromUrdf(str(urdf_path))
    gm = pin.buildGeomFromUrdf(model, str(urdf_path), pin.GeometryType.COLLISION, package_dirs=[str(urdf_path.parent)])
    owner = [model.frames[g.parentFrame].name for g in gm.geometryObjects]
    return model, gm, owner


def _pairs(root: ET.Element) -> dict[frozenset, str]:
    return {frozenset((d.get("link1"), d.get("link2"))): d.get("reason") for d in root.findall("disable_collisions")}


# --------------------------------------------------------------------------------------------
# structure, on every example


def test_every_example_has_one_srdf_per_robot(example_srdfs):
    for stem, (b, files) in example_srdfs.items():
        assert sorted(files) == sorted(f"config/{r.file_stem}.srdf" for r in _robots(b)), stem


@pytest.mark.slow
def test_srdf_parses_and_names_only_urdf_links_and_joints(example_srdfs, compiled_examples):
    for stem, (b, files) in example_srdfs.items():
        for r in _robots(b):
            root = ET.fromstring(files[f"config/{r.file_stem}.srdf"])
            _, urdf = _urdf(compiled_examples[stem], r)
            links = {link.get("name") for link in urdf.findall("link")}
            joints = {j.get("name") for j in urdf.findall("joint")}
            assert root.tag == "robot" and root.get("name") == urdf.get("name")
            named = [c.get(a) for c in root.iter("chain") for a in ("base_link", "tip_link")]
            named += [link.get("name") for g in root.findall("group") for link in g.findall("link")]
            named += [e.get("parent_link") for e in root.findall("end_effector")]
            named += [v.get("child_link") for v in root.findall("virtual_joint")]
            named += [d.get(a) for d in root.findall("disable_collisions") for a in ("link1", "link2")]
            assert named and set(named) <= links, (stem, set(named) - links)
            state_joints = {j.get("name") for s in root.findall("group_state") for j in s.findall("joint")}
            assert state_joints <= joints


def test_virtual_joint_and_arm_chain(example_srdfs):
    for stem, (b, files) in example_srdfs.items():
        for r in _robots(b):
            root = ET.fromstring(files[f"config/{r.file_stem}.srdf"])
            (vj,) = root.findall("virtual_joint")
            assert vj.attrib == {
                "name": "virtual_joint",
                "type": "fixed",
                "parent_frame": "world",
                "child_link": "base_link",
            }
            arm = [g for g in root.findall("group") if g.get("name") == "arm"]
            assert len(arm) == 1
            (chain,) = arm[0].findall("chain")
            assert chain.attrib == {"base_link": "base_link", "tip_link": "tool0"}, stem


def test_group_states_home_first_then_named_poses_one_value_per_joint(example_srdfs):
    for stem, (b, files) in example_srdfs.items():
        for r in _robots(b):
            root = ET.fromstring(files[f"config/{r.file_stem}.srdf"])
            states = root.findall("group_state")
            expected = ["home"] + [p.name for p in r.poses if p.name != "home"]
            assert [s.get("name") for s in states] == expected
            for s in states:
                assert s.get("group") == "arm"
                names = [j.get("name") for j in s.findall("joint")]
                assert names == [f"joint_{i}" for i in range(1, r.dof + 1)], (stem, s.get("name"))
                q = r.home() if s.get("name") == "home" else r.pose(s.get("name")).q
                assert np.allclose([float(j.get("value")) for j in s.findall("joint")], q, atol=1e-11)


def test_home_is_zeros_without_a_home_pose():
    c = checked_ok("robot r { chain H1 - H4(pivot=-90deg) - L4\n pose up (0, 45, 45) deg }")
    root = ET.fromstring(srdf.srdf_text(_build(c, samples=50), c.design.robots[0]))
    home, up = root.findall("group_state")
    assert home.get("name") == "home" and [j.get("value") for j in home] == ["0", "0", "0"]
    assert up.get("name") == "up" and float(up[1].get("value")) == pytest.approx(np.pi / 4, abs=1e-11)


@pytest.mark.parametrize("decl, links", [
    ("", None),
    ("tool at (0.06, 0, 0) m", ["tool0"]),
    ("tool rpy (0, 0, 90) deg", ["tool0"]),
    ("payload 100 g at (0.01, 0, 0) m", ["tool0", "payload"]),
    ("tool at (0.06, 0, 0) m\n payload 50 g", ["tool0", "payload"]),
])
def test_end_effector_only_when_a_tool_is_declared(decl, links):
    c = checked_ok(f"robot r {{ chain H1 - H4(pivot=-90deg) - L4\n {decl} }}")
    root = ET.fromstring(srdf.srdf_text(_build(c, samples=50), c.design.robots[0]))
    groups = {g.get("name"): g for g in root.findall("group")}
    ees = root.findall("end_effector")
    if links is None:
        assert set(groups) == {"arm"} and not ees
        return
    assert [link.get("name") for link in groups["tool"].findall("link")] == links
    (ee,) = ees
    assert ee.attrib == {"name": "tool", "parent_link": "link_3", "group": "tool", "parent_group": "arm"}


def test_farm_end_effector(example_srdfs):
    _, files = example_srdfs["farm"]
    root = ET.fromstring(files["config/mod3_farm.srdf"])
    (ee,) = root.findall("end_effector")
    assert ee.get("parent_link") == "link_3" and ee.get("group") == "tool"


# --------------------------------------------------------------------------------------------
# the collision matrix, checked independently on every example


def test_every_adjacent_pair_is_disabled_and_only_geometry_links_appear(example_srdfs, compiled_examples):
    for stem, (b, files) in example_srdfs.items():
        for r in _robots(b):
            root = ET.fromstring(files[f"config/{r.file_stem}.srdf"])
            pairs = _pairs(root)
            path, urdf = _urdf(compiled_examples[stem], r)
            with_geometry = {link.get("name") for link in urdf.findall("link") if link.find("collision") is not None}
            for j in urdf.findall("joint"):
                a, c = j.find("parent").get("link"), j.find("child").get("link")
                if a in with_geometry and c in with_geometry:
                    assert pairs.get(frozenset((a, c))) == "Adjacent", (stem, a, c)
            assert all(p <= with_geometry for p in pairs), stem
            # every pair of geometry links is either disabled or left for MoveIt to check
            m = srdf.collision_matrix(b, r)
            n = len(with_geometry)
            assert len(pairs) + len(m.enabled) == n * (n - 1) // 2
            assert {frozenset(p) for p in m.enabled}.isdisjoint(pairs)


def _geometry_model(gm, owner: list[str], pairs: dict, reason: str):
    """A copy of gm with the collision pairs the SRDF marks `reason` (owner: geometry index -> link)."""
    import pinocchio as pin

    g = gm.copy()
    g.removeAllCollisionPairs()
    for i in range(len(owner)):
        for j in range(i + 1, len(owner)):
            if pairs.get(frozenset((owner[i], owner[j]))) == reason:
                g.addCollisionPair(pin.CollisionPair(i, j))
    return g, g.createData()


@pytest.mark.slow
def test_never_pairs_do_not_collide_when_resampled_with_another_seed(example_srdfs, compiled_examples):
    """2,000 fresh samples (another generator, another seed), all mesh pairs of every pair the
    SRDF marks Never, pinocchio + coal called directly: none may collide. Default pairs must
    collide at the default pose."""
    import pinocchio as pin

    rng = np.random.default_rng(RESEED)
    checked_pairs = 0
    for stem, (b, files) in example_srdfs.items():
        for r in _robots(b):
            pairs = _pairs(ET.fromstring(files[f"config/{r.file_stem}.srdf"]))
            path, _ = _urdf(compiled_examples[stem], r)
            model, gm, owner = _pin(path)
            data = model.createData()
            lo, hi = model.lowerPositionLimit, model.upperPositionLimit
            never, never_data = _geometry_model(gm, owner, pairs, "Never")
            checked_pairs += sum(1 for v in pairs.values() if v == "Never")
            for q in rng.uniform(lo, hi, size=(RESAMPLES, model.nq)):
                if pin.computeCollisions(model, data, never, never_data, q, True):
                    cp = never.collisionPairs[never_data.collisionPairIndex]
                    pytest.fail(
                        f"{stem}: {owner[cp.first]} / {owner[cp.second]} marked Never collide at q = {q.tolist()}"
                    )
            default, default_data = _geometry_model(gm, owner, pairs, "Default")
            q0 = np.where((lo <= 0) & (hi >= 0), 0.0, (lo + hi) / 2)
            pin.computeCollisions(model, data, default, default_data, q0, False)
            results = zip(default.collisionPairs, default_data.collisionResults, strict=True)
            hit = {frozenset((owner[cp.first], owner[cp.second])) for cp, res in results if res.isCollision()}
            assert hit == {p for p, v in pairs.items() if v == "Default"}, stem
    assert checked_pairs >= 40  # the examples do exercise this (44 Never pairs)


def test_example_b_keeps_colliding_pairs_enabled(example_srdfs, compiled_examples):
    """Example B folds onto itself: e.g. base_link / link_2 collide in ~10 % of configurations.
    Such pairs must stay checked (not disabled); found here by direct sampling."""
    import pinocchio as pin

    b, files = example_srdfs["example_b"]
    (r,) = _robots(b)
    pairs = _pairs(ET.fromstring(files[f"config/{r.file_stem}.srdf"]))
    model, gm, owner = _pin(_urdf(compiled_examples["example_b"], r)[0])
    gm.removeAllCollisionPairs()
    for i in range(len(owner)):
        for j in range(i + 1, len(owner)):
            if {owner[i], owner[j]} == {"base_link", "link_2"}:
                gm.addCollisionPair(pin.CollisionPair(i, j))
    gd, data = gm.createData(), model.createData()
    rng = np.random.default_rng(RESEED)
    hits = sum(pin.computeCollisions(model, data, gm, gd, q, True)
               for q in rng.uniform(model.lowerPositionLimit, model.upperPositionLimit, size=(500, model.nq)))
    assert hits > 10
    assert frozenset(("base_link", "link_2")) not in pairs


@pytest.mark.slow
def test_fast_and_naive_classifications_agree():
    """The broad phase and early exits are filters: the all-mesh-pairs, all-samples anchor
    must give the same matrix."""
    for name in ("example_a", "example_b", "farm", "table3_raven"):
        c = check_file(ROOT / "examples" / f"{name}.mod")
        b = _build(c)
        for r in _robots(b):
            geo = collisions.geometry(b.description(r))
            fast = collisions.compute(geo, samples=1500, seed=3)
            naive = collisions.compute_naive(geo, samples=1500, seed=3)
            assert fast.disabled == naive.disabled and fast.enabled == naive.enabled, name
            for p, (coll, seen) in fast.counts.items():
                if seen == 1500:  # never left the loop early: exact same count
                    assert naive.counts[p] == (coll, seen)


def test_batch_forward_kinematics_matches_pinocchio():
    import pinocchio as pin

    c = check_file(ROOT / "examples" / "example_b.mod")
    b = _build(c)
    (r,) = _robots(b)
    geo = collisions.geometry(b.description(r))
    Q = np.random.default_rng(RESEED).uniform(-3, 3, size=(50, geo.model.nq))
    R, p = collisions.batch_placements(geo.model, Q)
    data = geo.model.createData()
    for n, q in enumerate(Q):
        pin.forwardKinematics(geo.model, data, q)
        for j in range(1, geo.model.njoints):
            assert np.allclose(R[n, j], data.oMi[j].rotation, atol=1e-12)
            assert np.allclose(p[n, j], data.oMi[j].translation, atol=1e-12)


# --------------------------------------------------------------------------------------------
# determinism and options


@pytest.mark.slow
def test_srdf_is_deterministic_and_seeded(example_srdfs, monkeypatch):
    monkeypatch.setenv("MODC_NO_CACHE", "1")  # really recompute: a cache hit would only compare with itself
    for stem in ("example_a", "example_b", "farm"):
        b, files = example_srdfs[stem]
        c = check_file(ROOT / "examples" / f"{stem}.mod")
        assert srdf.emit(_build(c)) == files, stem  # a second, independent run
        assert srdf.emit(_build(c, samples=10_000, seed=0)) == files  # the defaults are what they say
    c = check_file(ROOT / "examples" / "example_b.mod")
    (r,) = c.design.robots
    m1 = srdf.collision_matrix(_build(c, samples=3000, seed=7), r)
    m2 = srdf.collision_matrix(_build(c, samples=3000, seed=7), r)
    assert m1 == m2 and m1.counts == m2.counts and m1.seed == 7 and m1.samples == 3000


def test_options_are_read_from_the_build():
    c = check_file(ROOT / "examples" / "farm.mod")
    text = srdf.srdf_text(_build(c, samples=123, seed=45), c.design.robots[0])
    assert "none of 123 random configurations" in text and "(seed 45)" in text
    assert srdf.options(_build(c)) == (10_000, 0)
    with pytest.raises(ValueError):
        srdf.options(_build(c, samples=-1))


def test_zero_samples_gives_only_adjacent_and_default_pairs():
    c = check_file(ROOT / "examples" / "example_a.mod")
    root = ET.fromstring(srdf.srdf_text(_build(c, samples=0), c.design.robots[0]))
    assert set(_pairs(root).values()) == {"Adjacent"}


@pytest.mark.slow
@pytest.mark.parametrize("threads", ["1", "2", "4"])
def test_same_srdf_in_a_fresh_process_with_other_thread_settings(example_srdfs, threads):
    """Nothing in the computation is threaded; this shows BLAS/OpenMP settings do not matter."""
    _, files = example_srdfs["example_b"]
    env = dict(os.environ)
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        env[var] = threads
    env["PYTHONPATH"] = str(ROOT) + os.pathsep + env.get("PYTHONPATH", "")
    code = textwrap.dedent(f"""
        import sys
        from modc.compiler import check_file
        from modc.backends import Build, srdf
        c = check_file({str(ROOT / "examples" / "example_b.mod")!r})
        sys.stdout.write(srdf.emit(Build(c.design))["config/mod6_example_b.srdf"])
    """)
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True).stdout
    assert out == files["config/mod6_example_b.srdf"]


# --------------------------------------------------------------------------------------------
# each reason, on purpose-built arms


def test_default_reason_on_an_arm_folded_at_its_default_pose():
    """With joint 2 limited to 150..160 deg its default value is the middle (0 is outside), where
    the 180-degree ports fold link 2 back onto the base."""
    c = checked_ok("robot r { chain H4(port=180deg) - H4(port=180deg) - L4\n"
                   " limit joint_2 (150, 160) deg\n limit joint_3 (-125, -115) deg }")
    (r,) = c.design.robots
    m = srdf.collision_matrix(_build(c, samples=1000), r)
    assert m.default_q == pytest.approx((0.0, np.radians(155), np.radians(-120)))
    assert m.reason("base_link", "link_2") == "Default"
    assert m.reason("link_1", "link_3") == "Default"


SYNTHETIC = """<?xml version="1.0"?>
<robot name="synthetic">
  <link name="base_link">
    <collision><origin xyz="0 0 0.05"/><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
  </link>
  <link name="ring">  <!-- y >= 0.03 at z 0..0.1: link_2 is inside it unless its angle is ~0 -->
    <collision><origin xyz="0 0.5 0.05"/><geometry><box size="1.0 0.94 0.1"/></geometry></collision>
  </link>
  <link name="post">  <!-- where link_2 is at q = 0 -->
    <collision><origin xyz="0.3 0 0.05"/><geometry><box size="0.02 0.02 0.02"/></geometry></collision>
  </link>
  <link name="pillar">  <!-- met by link_1's arm around q = pi/2 only -->
    <collision><origin xyz="0.3 0 0.3"/><geometry><box size="0.05 0.05 0.05"/></geometry></collision>
  </link>
  <link name="link_1">
    <collision><origin xyz="0 0 0.4"/><geometry><box size="0.05 0.05 0.05"/></geometry></collision>
    <collision><origin xyz="0 -0.3 0.2"/><geometry><box size="0.05 0.05 0.05"/></geometry></collision>
  </link>
  <link name="flange"/>
  <link name="link_2">
    <collision><origin xyz="0.3 0 -0.05"/><geometry><box size="0.02 0.02 0.02"/></geometry></collision>
  </link>
  <joint name="ring_joint" type="fixed"><parent link="base_link"/><child link="ring"/></joint>
  <joint name="post_joint" type="fixed"><parent link="base_link"/><child link="post"/></joint>
  <joint name="pillar_joint" type="fixed"><parent link="base_link"/><child link="pillar"/></joint>
  <joint name="joint_1" type="revolute">
    <parent link="base_link"/><child link="link_1"/><origin xyz="0 0 0.1"/><axis xyz="0 0 1"/>
    <limit lower="-0.05" upper="3.0" effort="1" velocity="1"/>
  </joint>
  <joint name="flange_joint" type="fixed"><parent link="link_1"/><child link="flange"/></joint>
  <joint name="link_2_joint" type="fixed"><parent link="flange"/><child link="link_2"/></joint>
</robot>
"""


def test_every_reason_on_a_synthetic_urdf():
    geo = collisions.load({"urdf/s.urdf": SYNTHETIC}, "urdf/s.urdf")
    for m in (collisions.compute(geo, samples=2000, seed=1), collisions.compute_naive(geo, samples=2000, seed=1)):
        got = {frozenset((p.link1, p.link2)): p.reason for p in m.disabled}
        want = {
            ("base_link", "ring"): "Adjacent", ("base_link", "post"): "Adjacent", ("base_link", "pillar"): "Adjacent",
            ("base_link", "link_1"): "Adjacent",
            ("link_1", "link_2"): "Adjacent",  # through the geometry-less flange
            ("link_2", "post"): "Default",
            ("link_2", "ring"): "Always",  # ~96 % of the range
            ("base_link", "link_2"): "Never", ("ring", "post"): "Never", ("ring", "pillar"): "Never",
            ("post", "pillar"): "Never", ("link_1", "ring"): "Never", ("link_1", "post"): "Never",
            ("link_2", "pillar"): "Never",
        }
        assert got == {frozenset(k): v for k, v in want.items()}
        assert m.enabled == (("pillar", "link_1"),)  # ~11 % of the range
        assert m.links_without_geometry == ("flange",)


def test_adjacency_collapses_chains_of_geometry_less_links():
    links = ("a", "x", "y", "b", "c")
    edges = (("a", "x"), ("x", "y"), ("y", "b"), ("y", "c"))
    adj = collisions.adjacent_pairs(links, edges, lambda link: link in {"a", "b", "c"})
    assert adj == {frozenset(p) for p in (("a", "b"), ("a", "c"), ("b", "c"))}


def test_links_without_collision_geometry_are_reported(monkeypatch):
    bare = SYNTHETIC.replace("<collision>", "<!--").replace("</collision>", "-->")
    geo = collisions.load({"urdf/s.urdf": bare}, "urdf/s.urdf")
    m = collisions.compute(geo, samples=100)
    assert m.geometry_links == () and m.disabled == () and m.enabled == ()
    c = check_file(ROOT / "examples" / "farm.mod")
    b = _build(c)
    (r,) = c.design.robots
    ws = srdf.robot_warnings(r, m)
    assert any("no collision geometry" in w and "base_link" in w for w in ws)
    assert any("fewer than two links" in w for w in ws)
    # the real farm arm: every body has geometry, tool0 and payload are frames -> no warning
    assert srdf.warnings(_build(c, samples=10)) == []
    monkeypatch.setattr(srdf, "collision_matrix", lambda build, robot: m)
    text = srdf.srdf_text(b, r)
    ET.fromstring(text)  # the comments are well-formed
    assert "<!-- WARNING: robot farm: link(s) base_link, ring" in text
    assert srdf.warnings(b) == ws


def test_pinocchio_reads_the_srdf(example_srdfs, compiled_examples, tmp_path):
    """A real SRDF consumer: pinocchio's parser loads the named states and removes exactly the
    disabled pairs from a full collision-pair set."""
    import pinocchio as pin

    for stem in ("farm", "example_b"):
        b, files = example_srdfs[stem]
        for r in _robots(b):
            text = files[f"config/{r.file_stem}.srdf"]
            path = tmp_path / f"{r.file_stem}.srdf"
            path.write_text(text, encoding="utf-8")
            model, gm, owner = _pin(_urdf(compiled_examples[stem], r)[0])
            pin.loadReferenceConfigurations(model, str(path))
            assert np.allclose(model.referenceConfigurations["home"], r.home(), atol=1e-11)
            for p in r.poses:
                assert np.allclose(model.referenceConfigurations[p.name], p.q, atol=1e-11)
            gm.addAllCollisionPairs()
            pin.removeCollisionPairs(model, gm, str(path))
            left = {frozenset((owner[cp.first], owner[cp.second])) for cp in gm.collisionPairs}
            disabled = set(_pairs(ET.fromstring(text)))
            assert left.isdisjoint(disabled)
            m = srdf.collision_matrix(b, r)
            assert {p for p in left if len(p) == 2} == {frozenset(p) for p in m.enabled}


def test_disk_cache_hit_equals_a_fresh_computation(tmp_path, monkeypatch):
    """The collision matrix is cached by content hash; what comes back is what compute() gives."""
    monkeypatch.setenv("MODC_CACHE_DIR", str(tmp_path))
    c = check_file(ROOT / "examples" / "example_b.mod")
    (r,) = c.design.robots
    fresh = srdf.collision_matrix(_build(c, samples=2000, seed=3), r)
    assert list((tmp_path / "collisions").glob("*.json")), "the first computation is stored"
    hit = srdf.collision_matrix(_build(c, samples=2000, seed=3), r)
    assert hit == fresh and hit.counts == {}  # counts are not kept: they only explain a fresh run
    other_seed = srdf.collision_matrix(_build(c, samples=2000, seed=4), r)
    assert len(list((tmp_path / "collisions").glob("*.json"))) == 2 and other_seed.seed == 4
