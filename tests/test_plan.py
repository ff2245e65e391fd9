"""`modc plan` (modc/plan): collision-free motions to named targets.

The properties that matter are checked independently of the code under test:
  - collisions: the URDF the compiler writes is read here with ElementTree (collision meshes,
    their origins and scales) and yourdfpy (forward kinematics), the STL files with trimesh, the
    obstacles are rebuilt from the file's model, and coal is called directly (no pinocchio, no
    modc.plan code); the motion is sampled as `modc play` interpolates it (linearly between
    points), at most 0.25 deg per joint and 1 mm of tool0 motion apart;
  - the target: tool0 by modc.kinematics.Chain (docs/conventions.md), not by the planner's pinocchio;
  - the velocity limits: read from the URDF's <limit velocity=…>.
"""
from __future__ import annotations

import itertools
import json
import math
import os
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
from conftest import ROOT

from modc.compiler import build, check_file, write_tree
from modc.kinematics import Chain
from modc.plan import PlanError, plan, timing

FARM = ROOT / "examples" / "farm.mod"
JOINT_STEP = math.radians(0.25)  # rad per joint between independently checked samples
TOOL_STEP = 0.001  # m of tool0 motion between them


# ------------------------------------------------------------------------------------------------
# An independent collision check: ElementTree + yourdfpy + trimesh + coal


def _rpy(r, p, y) -> np.ndarray:
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return np.array([[cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
                     [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
                     [-sp, cp * sr, cp * cr]])


def _T(xyz, rpy) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = _rpy(*rpy)
    T[:3, 3] = xyz
    return T


class Independent:
    """Collision meshes of a compiled URDF + the robot's obstacles, tested with coal directly.
    Self pairs: every pair of links with geometry that are not adjacent (links without
    geometry collapsed, as MoveIt does); environment: every moving link vs every obstacle."""

    def __init__(self, urdf_path: Path, robot):
        import coal
        import trimesh
        import yourdfpy

        self.coal = coal
        self.urdf = yourdfpy.URDF.load(str(urdf_path), load_meshes=False, build_collision_scene_graph=False,
                                       load_collision_meshes=False)
        root = ET.parse(urdf_path).getroot()
        self.geoms = []
        for link in root.findall("link"):
            for col in link.findall("collision"):
                o = col.find("origin")
                xyz = [float(v) for v in o.get("xyz", "0 0 0").split()] if o is not None else [0.0] * 3
                rpy = [float(v) for v in o.get("rpy", "0 0 0").split()] if o is not None else [0.0] * 3
                mesh = col.find("geometry/mesh")
                m = trimesh.load(urdf_path.parent / mesh.get("filename"), force="mesh")
                scale = np.array([float(v) for v in mesh.get("scale", "1 1 1").split()])
                bvh = coal.BVHModelOBBRSS()
                bvh.beginModel(len(m.faces), len(m.vertices))
                bvh.addVertices(np.asarray(m.vertices, float) * scale)
                bvh.addTriangles(np.asarray(m.faces, dtype=np.int64))
                bvh.endModel()
                self.geoms.append((link.get("name"), _T(xyz, rpy), bvh))
        self.obstacles = []
        for ob in robot.obstacles:
            g = {"box": lambda s: coal.Box(*s), "sphere": lambda s: coal.Sphere(s[0]),
                 "cylinder": lambda s: coal.Cylinder(s[0], s[1])}[ob.shape](ob.size)
            self.obstacles.append((ob.name, _T(ob.origin.xyz, ob.origin.rpy), g))
        with_geom = {link for link, _, _ in self.geoms}
        nbr = {link.get("name"): set() for link in root.findall("link")}
        for j in root.findall("joint"):
            a, b = j.find("parent").get("link"), j.find("child").get("link")
            nbr[a].add(b)
            nbr[b].add(a)
        for link in list(nbr):
            if link not in with_geom:
                ns = nbr.pop(link)
                for n in ns:
                    nbr[n].discard(link)
                for a in ns:
                    nbr[a] |= ns - {a}
        links = sorted(with_geom)
        self.self_pairs = {(a, b) for i, a in enumerate(links) for b in links[i + 1:] if b not in nbr[a]}
        revolute = [j for j in root.findall("joint") if j.get("type") == "revolute"]
        self.joints = [j.get("name") for j in revolute]
        self.velocity = np.array([float(j.find("limit").get("velocity")) for j in revolute])
        self.lower = np.array([float(j.find("limit").get("lower")) for j in revolute])
        self.upper = np.array([float(j.find("limit").get("upper")) for j in revolute])

    def _hit(self, g1, T1, g2, T2) -> bool:
        c = self.coal
        tf1 = c.Transform3s(T1[:3, :3].copy(), T1[:3, 3].copy())
        tf2 = c.Transform3s(T2[:3, :3].copy(), T2[:3, 3].copy())
        return c.collide(g1, tf1, g2, tf2, c.CollisionRequest(), c.CollisionResult()) > 0

    def collisions(self, q) -> list[tuple[str, str]]:
        self.urdf.update_cfg(dict(zip(self.joints, (float(v) for v in q), strict=True)))
        T_link: dict[str, np.ndarray] = {}
        placed = []
        for link, T, g in self.geoms:
            if link not in T_link:
                T_link[link] = self.urdf.get_transform(link, "base_link")
            placed.append((link, T_link[link] @ T, g))
        hits = set()
        for link, T, g in placed:
            if link == "base_link":
                continue  # never moves; tested on its own
            for name, To, go in self.obstacles:
                if (link, name) not in hits and self._hit(g, T, go, To):
                    hits.add((link, name))
        for i, (a, Ta, ga) in enumerate(placed):
            for b, Tb, gb in placed[i + 1:]:
                key = (min(a, b), max(a, b))
                if key in self.self_pairs and key not in hits and self._hit(ga, Ta, gb, Tb):
                    hits.add(key)
        return sorted(hits)


def dense(q_rows, chain: Chain):
    """The motion as `play` interpolates it (linearly between points), sampled at most
    JOINT_STEP per joint and TOOL_STEP of tool0 apart."""
    Q = np.asarray(q_rows, float)
    out = [Q[0]]
    for a, b in itertools.pairwise(Q):
        n = max(1, math.ceil(np.max(np.abs(b - a)) / JOINT_STEP))
        while True:
            seg = [a + (b - a) * k / n for k in range(n + 1)]
            P = np.array([chain.T_base_tool(q)[:3, 3] for q in seg])
            if np.max(np.linalg.norm(np.diff(P, axis=0), axis=1)) <= TOOL_STEP:
                break
            n *= 2
        out += seg[1:]
    return out


# ------------------------------------------------------------------------------------------------
# Fixtures


@pytest.fixture(scope="module")
def farm(tmp_path_factory):
    checked = check_file(FARM)
    assert checked.ok
    robot = checked.design.robots[0]
    out = tmp_path_factory.mktemp("farm") / "out"
    write_tree(build(checked, ["urdf", "meshes"]), out)
    ind = Independent(out / "urdf" / f"{robot.file_stem}.urdf", robot)
    return robot, ind


@pytest.fixture(scope="module")
def plant_plan():
    return plan(FARM, "plant", seed=0)


def _write(tmp_path: Path, text: str, name: str = "cell.mod") -> Path:
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


FARM_CHAIN = """robot farm {
    chain H1 - L4(pivot=-90deg, port=45deg) - L3(link=180mm)
    tool at (0.06, 0, 0) m
    pose home (0, 0, 0) deg
    pose ready (90, -45, -90) deg
"""


# ------------------------------------------------------------------------------------------------
# The farm cell: home -> plant, with the cell's walls, roof and floor in the way


def test_farm_needs_a_detour(farm, plant_plan):
    """The straight joint-space motion from home to the plan's goal collides (checked
    independently): the example really has obstacles in the way, and the planner went round."""
    robot, ind = farm
    chain = Chain(robot)
    start, goal = np.array(plant_plan.q[0]), np.array(plant_plan.q[-1])
    straight = dense([start, goal], chain)
    assert any(ind.collisions(q) for q in straight)
    assert len(plant_plan.waypoints) >= 3


def test_farm_path_collision_free(farm, plant_plan):
    robot, ind = farm
    assert ind.self_pairs  # the self-collision check is not vacuous
    assert not ind.collisions(np.array(plant_plan.q[0]))
    samples = dense(plant_plan.q, Chain(robot))
    assert len(samples) > 200
    bad = [(q, h) for q in samples if (h := ind.collisions(q))]
    assert not bad, f"{len(bad)} of {len(samples)} samples collide, first at q = {bad[0][0]}: {bad[0][1]}"


def test_farm_reaches_target(farm, plant_plan):
    robot, _ = farm
    target = next(t for t in robot.targets if t.name == "plant")
    tool = Chain(robot).T_base_tool(np.array(plant_plan.q[-1]))[:3, 3]
    err = float(np.linalg.norm(tool - np.array(target.xyz)))
    assert err < 0.005
    assert err < 1e-6  # what the IK actually achieves
    assert plant_plan.tool_error < 1e-6


def test_farm_starts_at_home_within_limits(farm, plant_plan):
    robot, ind = farm
    assert plant_plan.q[0] == pytest.approx(robot.home(), abs=1e-12)
    Q = np.array(plant_plan.q)
    assert np.all(Q >= ind.lower - 1e-9) and np.all(Q <= ind.upper + 1e-9)


def test_farm_timing(farm, plant_plan):
    _, ind = farm
    assert list(plant_plan.joint_names) == ["joint_1", "joint_2", "joint_3"] == ind.joints
    t = np.array(plant_plan.t)
    assert t[0] == 0.0
    assert np.all(np.diff(t) > 0)
    Q = np.array(plant_plan.q)
    v = np.abs(np.diff(Q, axis=0)) / np.diff(t)[:, None]
    assert np.all(v <= ind.velocity * (1 + 1e-6)), (v.max(axis=0), ind.velocity)
    # the arm uses its speed: some joint gets near its limit somewhere (no needless slowness)
    assert np.max(v / ind.velocity) > 0.5


def test_farm_json(plant_plan):
    doc = json.loads(plant_plan.dumps())
    assert list(doc) == ["joint_names", "points"]  # docs/conventions.md, a single robot in the file
    assert doc["joint_names"] == ["joint_1", "joint_2", "joint_3"]
    assert len(doc["points"]) == len(plant_plan.t)
    for pt in doc["points"]:
        assert list(pt) == ["t", "q"] and len(pt["q"]) == 3
    assert doc == json.loads(json.dumps(plant_plan.to_json()))


def test_json_plays(farm, plant_plan):
    """What `plan --json` prints is a trajectory `play --traj` accepts."""
    traj = pytest.importorskip("modc.trajectory")
    robot, _ = farm
    parsed, errors = traj.parse(json.loads(plant_plan.dumps()))
    assert not errors, errors
    assert not traj.validate_for(parsed, robot)
    assert parsed.dumps() == plant_plan.dumps()  # one writer: read back and written again, the same bytes


def test_same_seed_same_json(plant_plan, tmp_path):
    again = plan(FARM, "plant", seed=0)
    assert again.dumps() == plant_plan.dumps()
    # and in a fresh process with another hash seed
    code = "import sys; from modc.plan import plan; sys.stdout.write(plan(sys.argv[1], 'plant', seed=0).dumps())"
    env = dict(os.environ, PYTHONHASHSEED="12345")
    r = subprocess.run([sys.executable, "-c", code, str(FARM)], capture_output=True, text=True, env=env, timeout=120)
    assert r.returncode == 0, r.stderr
    assert r.stdout == plant_plan.dumps()
    assert "leaked" not in r.stderr  # nanobind's leak report at exit would be noise on stderr


def test_other_seed_also_valid(farm):
    robot, ind = farm
    p = plan(FARM, "tray", seed=3)
    target = next(t for t in robot.targets if t.name == "tray")
    chain = Chain(robot)
    assert np.linalg.norm(chain.T_base_tool(np.array(p.q[-1]))[:3, 3] - np.array(target.xyz)) < 1e-6
    assert not any(ind.collisions(q) for q in dense(p.q, chain))


def test_start_option(farm):
    robot, _ = farm
    p = plan(FARM, "plant", start="ready")
    assert p.start == "ready"
    assert p.q[0] == pytest.approx(robot.pose("ready").q, abs=1e-12)


def test_summary_mentions_the_essentials(plant_plan):
    s = plant_plan.summary()
    for word in ("plant", "duration", "points", "tool0 error", "clearance"):
        assert word in s


# ------------------------------------------------------------------------------------------------
# Errors: clear messages, the right codes and exit codes, no traceback


def test_unknown_target():
    with pytest.raises(PlanError) as e:
        plan(FARM, "tomato")
    assert e.value.code == "target-unknown"
    assert e.value.exit_code == 2
    assert "'tomato'" in e.value.message
    assert "plant" in e.value.hint and "tray" in e.value.hint


def test_unknown_start_pose():
    with pytest.raises(PlanError) as e:
        plan(FARM, "plant", start="nowhere")
    assert e.value.code == "pose-unknown" and e.value.exit_code == 2
    assert "home" in e.value.hint and "ready" in e.value.hint


def test_unknown_robot():
    with pytest.raises(PlanError) as e:
        plan(FARM, "plant", robot="nope")
    assert e.value.code == "robot-unknown" and e.value.exit_code == 2


def test_unreadable_file(tmp_path):
    with pytest.raises(PlanError) as e:
        plan(tmp_path / "missing.mod", "plant")
    assert e.value.code == "file-not-found" and e.value.exit_code == 2


def test_file_with_errors(tmp_path):
    p = _write(tmp_path, "robot bad {\n    chain H1 - Q9\n    target t at (0.3, 0, 0.3) m\n}\n")
    with pytest.raises(PlanError) as e:
        plan(p, "t")
    assert e.value.exit_code == 1
    assert e.value.diagnostics and all(d.is_error for d in e.value.diagnostics)


def test_out_of_reach(tmp_path, farm):
    robot, _ = farm
    p = _write(tmp_path, FARM_CHAIN + "    target far at (1.2, 0, 0.3) m\n}\n")
    with pytest.raises(PlanError) as e:
        plan(p, "far")
    err = e.value
    assert err.code == "target-unreachable" and err.exit_code == 1
    assert "'far'" in err.message and "out of reach" in err.message
    reported = float(err.message.split("no closer than ")[1].split(" m")[0])
    # independently: the closest of many random poses (Chain FK) is no closer than the IK's answer
    rng = np.random.default_rng(99)
    chain = Chain(robot)
    lo, hi = np.array([-2.967] * 3), np.array([2.967] * 3)
    d = min(
        np.linalg.norm(chain.T_base_tool(lo + (hi - lo) * rng.random(3))[:3, 3] - [1.2, 0, 0.3]) for _ in range(3000)
    )
    assert reported <= d + 1e-3
    assert reported >= d - 0.03
    assert err.diagnostics[0].span.line == 6  # points at the target's line in the file


def test_start_in_collision(tmp_path):
    # a thin shelf through link_2 (vertical at home)
    p = _write(tmp_path, FARM_CHAIN + "    box shelf size (0.3, 0.3, 0.02) m at (-0.1, 0, 0.33) m\n"
                                      "    target t at (0.3, 0, 0.3) m\n}\n")
    with pytest.raises(PlanError) as e:
        plan(p, "t")
    err = e.value
    assert err.code == "start-in-collision" and err.exit_code == 1
    assert err.message.startswith("the start pose 'home' collides: ")
    assert "link_2 with box 'shelf'" in err.message
    assert err.diagnostics[0].span.line == 4  # the `pose home` line


def test_start_in_collision_with_the_base(tmp_path):
    p = _write(tmp_path, FARM_CHAIN + "    box plinth size (0.3, 0.3, 0.1) m at (0, 0, 0.03) m\n"
                                      "    target t at (0.3, 0, 0.3) m\n}\n")
    with pytest.raises(PlanError) as e:
        plan(p, "t")
    assert e.value.code == "start-in-collision"
    assert "base_link with box 'plinth'" in e.value.message
    assert "base_link never moves" in e.value.hint


def test_floor_touching_the_base_is_fine(tmp_path):
    """A floor whose top is the base's bottom face (z = 0) only touches base_link."""
    p = _write(tmp_path, FARM_CHAIN + "    box ground size (1.5, 1.5, 0.02) m at (0, 0, -0.01) m\n"
                                      "    target t at (0.3, 0.1, 0.3) m\n}\n")
    result = plan(p, "t")
    assert result.tool_error < 1e-6


def test_target_only_in_collision(tmp_path):
    p = _write(tmp_path, FARM_CHAIN + "    box crate size (0.25, 0.25, 0.25) m at (0.3, 0, 0.3) m\n"
                                      "    target inside at (0.3, 0, 0.3) m\n}\n")
    with pytest.raises(PlanError) as e:
        plan(p, "inside")
    err = e.value
    assert err.code == "target-in-collision" and err.exit_code == 1
    assert "reachable only in collision" in err.message and "'crate'" in err.message


def test_no_path_within_budget():
    with pytest.raises(PlanError) as e:
        plan(FARM, "plant", max_checks=20)
    assert e.value.code == "no-path" and e.value.exit_code == 1
    assert "'home'" in e.value.message and "'plant'" in e.value.message


def test_multi_robot_file(tmp_path):
    text = (FARM_CHAIN + "    target t at (0.3, 0.1, 0.3) m\n}\n"
            "robot other {\n    chain H1 - L1\n}\n")
    p = _write(tmp_path, text)
    result = plan(p, "t")  # only farm has target t
    doc = json.loads(result.dumps())
    assert doc["robot"] == "farm"
    with pytest.raises(PlanError) as e:
        plan(p, "t", robot="other")
    assert e.value.code == "target-unknown"


def test_obstacle_shapes_agree_with_the_independent_check(tmp_path):
    """Boxes, spheres and tilted cylinders are placed and sized as the independent check reads
    the model (full box extents, cylinder length along its own z, URDF roll-pitch-yaw): both
    find the same contacts in random poses (self pairs are compared too, though this arm's
    links never meet in random poses)."""
    from modc.plan.collision import CollisionChecker

    text = (FARM_CHAIN + "    box b size (0.4, 0.1, 0.2) m at (0.2, 0.1, 0.3) m rpy (10, 20, 30) deg\n"
            "    sphere s radius 0.08 m at (-0.2, 0.2, 0.4) m\n"
            "    cylinder c radius 0.03 m length 0.5 m at (0.0, -0.25, 0.35) m rpy (80, 0, 30) deg\n}\n")
    path = _write(tmp_path, text)
    checked = check_file(path)
    assert checked.ok
    robot = checked.design.robots[0]
    files = build(checked, ["urdf", "meshes"])
    write_tree(files, tmp_path / "out")
    ind = Independent(tmp_path / "out" / "urdf" / f"{robot.file_stem}.urdf", robot)
    mine = CollisionChecker(robot, files)
    rng = np.random.default_rng(7)
    seen = set()
    for _ in range(300):
        q = ind.lower + (ind.upper - ind.lower) * rng.random(robot.dof)
        a = {(c.a, c.b) if c.b_is_obstacle else (min(c.a, c.b), max(c.a, c.b)) for c in mine.contacts(q, 0.0)}
        b = set(ind.collisions(q))
        assert a == b, (q, a, b)
        seen |= {o for _, o in a}
    assert seen == {"b", "s", "c"}  # every shape was hit somewhere: the comparison is not vacuous


# ------------------------------------------------------------------------------------------------
# Timing on its own


def test_trapezoid_respects_limits_and_ends_exactly():
    vmax = np.array([1.0, 2.0, 0.5])
    amax = vmax / timing.ACCEL_RAMP_TIME
    path = [np.zeros(3), np.array([1.0, -0.5, 0.2]), np.array([1.01, -0.5, 0.2]), np.array([-1.0, 1.0, 0.0])]
    ts, qs = timing.parameterise(path, vmax, amax)
    t = np.array(ts)
    Q = np.array(qs)
    assert np.all(np.diff(t) > 0)
    assert np.all(np.abs(np.diff(Q, axis=0)) / np.diff(t)[:, None] <= vmax * (1 + 1e-9))
    for p in path:  # every vertex is a point of the output (the arm stops there)
        assert np.min(np.max(np.abs(Q - p), axis=1)) == 0.0
    assert ts[-1] == pytest.approx(timing.path_duration(path, vmax, amax))
    # a long segment cruises at the slowest joint's limit: duration = distance / v + ramp time
    d = timing.segment_duration(np.array([3.0, 0.0, 0.0]), vmax, amax)
    assert d == pytest.approx(3.0 / 1.0 + timing.ACCEL_RAMP_TIME)
