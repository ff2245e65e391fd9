"""PyBullet: `modc sim` (smoke test), `modc render` (pictures), `modc play` (trajectories), all
headless (no DISPLAY: PyBullet DIRECT and its TinyRenderer).

The smoke test must pass every example and must fail, saying why, on an arm whose actuator
cannot hold it (the sagging joint named), on a pose where two links collide (the pair named), on
a pose inside an obstacle, and on a URDF whose kinematics or inertials were tampered with.
"""
from __future__ import annotations

import hashlib
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
from conftest import EXAMPLES, ROOT

from modc import trajectory
from modc.compiler import COMPILE_ANALYSES, build, check_file, check_text
from modc.kinematics import Chain
from modc.model.select import RobotChoiceError
from modc.sim import scene, smoke
from modc.sim.play import play
from modc.sim.render import render

YAML_EXAMPLES = sorted(p for p in (ROOT / "examples").iterdir() if p.suffix in (".yaml", ".yml"))

# The arm of the issue: two 0.45 m link modules on light actuators with 1 kg at the tip, held
# horizontal. Static gravity torque at joint_2: 11.7 N·m against the KA-58's 6.8 N·m peak.
HEAVY = """
robot heavy {
    chain H1 - L4(pivot=-90deg, link=450mm) - L4(link=450mm)
    payload 1 kg
    pose out (0, -90, 0) deg
}
"""
# Folding joint 2 to 165° swings link 2's module into the base (hull penetration 33 mm).
FOLD = """
robot fold {
    chain H4(link=100mm) - H4(pivot=-90deg, link=400mm) - L3(link=400mm)
    pose folded (0, 165, 0) deg
}
"""
# A wall-mounted arm: base tilted 90° about x and turned 30°, an obstacle with its own rpy.
WALL = """
robot wall {
    chain H1 - H4(pivot=-90deg) - L4
    base at (0.2, -0.1, 0.8) m rpy (90, 0, 30) deg
    payload 100 g
    pose reach (20, -30, 45) deg
    box plate size (0.1, 0.1, 0.1) m at (0.3, 0.2, 0.1) m rpy (0, 0, 45) deg
    target t1 at (0.3, 0.1, 0.3) m
}
"""


@pytest.fixture(autouse=True)
def headless(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)


def write(tmp_path: Path, text: str, name: str = "t.mod") -> Path:
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


# ------------------------------------------------------------------------------------------------
# modc sim


@pytest.mark.slow
@pytest.mark.parametrize("path", EXAMPLES + YAML_EXAMPLES, ids=lambda p: p.name)
def test_every_example_passes_sim(path):
    ok, lines, checked = smoke.run_sim(path)
    assert checked.ok
    assert ok, "\n".join(lines)
    for r in checked.design.robots:
        for name, _ in r.named_poses():
            assert any(line.strip().startswith(f"pose {name}: ok") for line in lines), lines


@pytest.mark.slow
def test_every_example_holds_tracks_and_agrees():
    """The measured figures behind the tolerances: tracking (1 kHz, PyBullet's default gains),
    FK against modc's kinematics, holding torques against modc's dynamics."""
    for path in EXAMPLES:
        checked = check_file(path)
        for res in smoke.simulate(checked):
            for p in res.poses:
                assert max(p.track_error) < smoke.TRACK_TOL / 20, (path.name, p.name, p.track_error)
                assert p.fk_pos_error < smoke.FK_POS_TOL and p.fk_rot_error < smoke.FK_ROT_TOL
                assert p.torque_error < 1e-6, (path.name, p.name, p.torque_error)
                assert p.max_velocity < 0.1


def test_overloaded_arm_fails_naming_the_sagging_joint(tmp_path):
    path = write(tmp_path, HEAVY)
    # the static torque analysis of `modc FILE -o OUT` refuses this arm; sim loads it anyway
    assert not check_file(path, analyses=COMPILE_ANALYSES).ok
    ok, lines, checked = smoke.run_sim(path)
    assert checked.ok and not ok
    (res,) = smoke.simulate(checked)
    home, out = res.poses
    assert not home.failures
    sags = [f for f in out.failures if f.kind == "sag"]
    assert [f.joint for f in sags] == ["joint_2"], out.failures
    msg = sags[0].message
    assert msg.startswith("robot heavy, pose out: joint_2 sags")
    assert "6.8 N·m" in msg and "cannot hold the arm" in msg
    needs = float(re.search(r"needs ([0-9.]+) N·m", msg).group(1))
    assert 11.0 < needs < 12.5  # the static gravity torque of the outstretched arm
    assert out.track_error[1] > 0.1  # not a rounding matter: tenths of a radian
    assert any("joint_2 sags" in line for line in lines)


def test_self_colliding_pose_fails_naming_the_pair(tmp_path):
    ok, lines, checked = smoke.run_sim(write(tmp_path, FOLD))
    assert not ok
    (res,) = smoke.simulate(checked)
    folded = res.poses[1]
    cols = [f for f in folded.failures if f.kind == "self-collision"]
    assert [f.links for f in cols] == [("base_link", "link_2")]
    assert "base_link and link_2 collide" in cols[0].message
    assert not res.poses[0].failures  # home is fine
    assert any("pose folded" in line and "base_link and link_2 collide" in line for line in lines)


@pytest.mark.slow
def test_srdf_disabled_pairs_are_honoured_but_never_pairs_are_not(tmp_path):
    path = write(tmp_path, FOLD)
    out = tmp_path / "out"
    (out / "config").mkdir(parents=True)
    srdf = out / "config" / "mod3_fold.srdf"
    for reason, passes in (("Default", True), ("Always", True), ("Adjacent", True), ("Never", False)):
        srdf.write_text(
            f'<robot name="mod3_fold"><disable_collisions link1="base_link" link2="link_2" reason="{reason}"/></robot>'
        )
        ok, lines, _ = smoke.run_sim(path, out_dir=out)
        assert ok == passes, (reason, lines)


def test_pose_inside_an_obstacle_fails_naming_link_and_obstacle(tmp_path):
    base = "robot boxed {\n    chain H1 - H4(pivot=-90deg) - L4\n"
    robot = check_text(base + "}", "t.mod").design.robots[0]
    p = Chain(robot).frames([0.0, 0.0, 0.0])[2]["T_base_joint"][:3, 3]  # joint 3, inside link_2's actuator
    text = base + f"    box wall size (0.05, 0.05, 0.05) m at ({p[0]:.4f}, {p[1]:.4f}, {p[2]:.4f}) m\n}}\n"
    ok, lines, checked = smoke.run_sim(write(tmp_path, text))
    assert not ok
    (res,) = smoke.simulate(checked)
    env = [f for f in res.poses[0].failures if f.kind == "environment"]
    assert env and all(f.links[1] == "wall" for f in env)
    assert "link_2" in {f.links[0] for f in env}
    assert "is inside obstacle wall" in env[0].message


def test_tilted_base_gravity_and_environment_follow_the_placement(tmp_path):
    """base rpy turns gravity as the torque analysis assumes; obstacles and targets, given in
    base_link, land at T_world_base · origin."""
    ok, lines, checked = smoke.run_sim(write(tmp_path, WALL))
    assert ok, lines
    (res,) = smoke.simulate(checked)
    assert all(p.torque_error < 1e-6 for p in res.poses)
    robot = checked.design.robots[0]
    T = scene.transform(robot.base.xyz, robot.base.rpy)
    with scene.compiled(checked) as urdfs, scene.connect() as client:
        s = scene.load_robot(client, robot, urdfs[robot.name])
        assert np.allclose(s.T_world_link("base_link"), T, atol=1e-6)
        ob = robot.obstacles[0]
        pos, orn = client.getBasePositionAndOrientation(s.obstacles["plate"])
        assert np.allclose(scene.pose_matrix(pos, orn), T @ scene.transform(ob.origin.xyz, ob.origin.rpy), atol=1e-6)
        tpos, _ = client.getBasePositionAndOrientation(s.targets["t1"])
        assert np.allclose(tpos, (T @ np.array([0.3, 0.1, 0.3, 1.0]))[:3], atol=1e-9)
        assert client.getCollisionShapeData(s.targets["t1"], -1) == ()  # a marker only


def tampered(tmp_path: Path, text: str, edit) -> tuple:
    checked = check_text(text, "t.mod")
    robot = checked.design.robots[0]
    files = build(checked, ["urdf", "meshes"])
    for rel, content in files.items():
        (tmp_path / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / rel).write_bytes(content if isinstance(content, bytes) else content.encode())
    urdf = tmp_path / "urdf" / f"{robot.file_stem}.urdf"
    urdf.write_text(edit(urdf.read_text()))
    with scene.connect() as client:
        return smoke.simulate_robot(client, robot, urdf, hold_time=0.2)


def test_fk_disagreement_is_caught(tmp_path):
    text = "robot t { chain H1 - L4(port=45deg) - L1 }"
    res = tampered(tmp_path, text, lambda u: u.replace('<origin xyz="0 0 0.147" rpy="0 0 0"/>\n    <axis',
                                                       '<origin xyz="0 0 0.1475" rpy="0 0 0"/>\n    <axis', 1))
    fk = [f for f in res.all_failures if f.kind == "fk"]
    assert fk and "tool0" in fk[0].message


def test_missing_inertial_is_caught(tmp_path):
    text = "robot t { chain H1 - L4(port=45deg) - L1 }"

    def drop(u: str) -> str:
        a = u.index("<inertial>", u.index('<link name="link_1">'))
        return u[:a] + u[u.index("</inertial>", a) + len("</inertial>"):]

    res = tampered(tmp_path, text, drop)
    load = [f.message for f in res.failures if f.kind == "load"]
    assert any("link link_1 has no <inertial>" in m for m in load), load


def test_adjacency_collapses_links_without_geometry():
    s = scene.Scene(client=None, robot=None, urdf=Path("x.urdf"), body=0, T_world_base=None, joint_names=[], joints={},
                    links={"base_link": -1, "a": 0, "tool0": 1, "b": 2, "c": 3},
                    parents={"a": "base_link", "tool0": "a", "b": "tool0", "c": "b"},
                    geometry_links=["base_link", "a", "b", "c"], limits={})
    adj = s.adjacent_pairs()
    assert frozenset(("a", "b")) in adj and frozenset(("base_link", "a")) in adj and frozenset(("b", "c")) in adj
    assert frozenset(("base_link", "b")) not in adj and frozenset(("a", "c")) not in adj
    assert s.self_collision_pairs() == [("base_link", "b"), ("base_link", "c"), ("a", "c")]
    assert s.self_collision_pairs(allowed=[("c", "a")]) == [("base_link", "b"), ("base_link", "c")]


def test_file_with_errors_is_not_simulated(tmp_path):
    ok, lines, checked = smoke.run_sim(write(tmp_path, "robot x { chain H1 - Q9 }"))
    assert not ok and lines == [] and not checked.ok


def test_unknown_robot_is_a_usage_error():
    with pytest.raises(RobotChoiceError, match="no robot 'nope'"):
        smoke.run_sim(ROOT / "examples" / "farm.mod", robot="nope")


def test_pybullet_prints_nothing(capfd):
    capfd.readouterr()
    smoke.run_sim(ROOT / "examples" / "table3_planar.mod")
    out, err = capfd.readouterr()
    assert out == "" and err == ""


# ------------------------------------------------------------------------------------------------
# modc render




@pytest.mark.slow
def test_render_makes_a_clear_picture(tmp_path):
    from PIL import Image

    out = tmp_path / "farm.png"
    ok, lines, _ = render(ROOT / "examples" / "farm.mod", out)
    assert ok and out.is_file() and "farm" in lines[0]
    img = Image.open(out)
    assert img.size == (1280, 960) and img.format == "PNG"
    a = np.asarray(img.convert("RGB"), dtype=int)
    colours = len(np.unique(a.reshape(-1, 3), axis=0))
    assert colours > 1000, colours
    # the arm's modules are orange (L) and blue (H): saturated pixels, unlike the grey background,
    # ground and light steel obstacles
    saturation = a.max(axis=2) - a.min(axis=2)
    arm = (saturation > 80).mean()
    assert 0.01 < arm < 0.5, arm
    # not-background: anything darker than the light backdrop
    drawn = (a.min(axis=2) < 200).mean()
    assert 0.1 < drawn < 0.9, drawn
    # deterministic
    again = tmp_path / "again.png"
    render(ROOT / "examples" / "farm.mod", again)
    assert again.read_bytes() == out.read_bytes()


@pytest.mark.slow
def test_render_pose_size_and_errors(tmp_path):
    from PIL import Image

    home, ready = tmp_path / "home.png", tmp_path / "ready.png"
    render(ROOT / "examples" / "farm.mod", home, width=320, height=240)
    render(ROOT / "examples" / "farm.mod", ready, pose="ready", width=320, height=240)
    assert Image.open(ready).size == (320, 240)
    assert home.read_bytes() != ready.read_bytes()
    with pytest.raises(scene.UsageError, match="no pose 'nope'.*home, ready"):
        render(ROOT / "examples" / "farm.mod", tmp_path / "x.png", pose="nope")
    assert not (tmp_path / "x.png").exists()


def test_render_one_camera_per_file_captions_and_target_labels(tmp_path):
    """Two poses of one file are seen from the same camera (framed over every pose), so the
    static cell stays put; the picture is captioned (robot, chain, pose) and its targets labelled."""
    from PIL import Image

    from modc.sim import caption

    path = ROOT / "examples" / "farm.mod"
    pics = {}
    for pose in ("home", "ready"):
        out = tmp_path / f"{pose}.png"
        ok, lines, _ = render(path, out, pose=pose, width=480, height=360)
        assert ok
        pics[pose] = (np.asarray(Image.open(out).convert("RGB"), dtype=int), lines[0].split("; ")[1])
    (home, cam_home), (ready, cam_ready) = pics["home"], pics["ready"]
    assert cam_home == cam_ready, (cam_home, cam_ready)
    same = (np.abs(home - ready).sum(axis=2) == 0).mean()
    assert same > 0.6, same  # the background and the cell: identical pixels
    bare = tmp_path / "bare.png"
    render(path, bare, pose="ready", width=480, height=360, captions=False)
    plain = np.asarray(Image.open(bare).convert("RGB"), dtype=int)
    band = caption.band_height(360)
    assert (ready[-band:].min(axis=2) < 90).mean() > 0.01  # caption text on the band
    assert (ready[-band:].min(axis=2) > 240).mean() > 0.5
    ink = (np.abs(ready - np.array(caption.TARGET_INK)).sum(axis=2) < 40).sum()
    assert ink > 40 and (np.abs(plain - np.array(caption.TARGET_INK)).sum(axis=2) < 40).sum() < ink / 4


@pytest.mark.slow
def test_render_two_robots_in_one_file(tmp_path):
    from PIL import Image

    path = write(tmp_path, "robot a { chain H3 - L4 }\nrobot b { chain H1 - H4(pivot=-90deg) - L4 }\n")
    ok, lines, _ = render(path, tmp_path / "two.png", width=400, height=300)
    assert ok and "a (H3-L4)" in lines[0] and "b (H1-H4-L4)" in lines[0]
    a = np.asarray(Image.open(tmp_path / "two.png").convert("RGB"), dtype=int)
    assert ((a.max(axis=2) - a.min(axis=2)) > 80).mean() > 0.01


# ------------------------------------------------------------------------------------------------
# modc play


def traj_file(tmp_path: Path, doc, name: str = "traj.json") -> Path:
    p = tmp_path / name
    p.write_text(json.dumps(doc) if not isinstance(doc, str) else doc)
    return p


SWEEP = {
    "joint_names": ["joint_1", "joint_2", "joint_3"],
    "points": [{"t": 0.0, "q": [0.0, 0.0, 0.0]}, {"t": 0.6, "q": [0.9, -0.5, 0.8]}, {"t": 1.2, "q": [1.6, -0.9, 1.4]}],
}


@pytest.mark.slow
def test_play_records_a_gif_of_many_different_frames(tmp_path):
    from PIL import Image

    gif = tmp_path / "sweep.gif"
    path = ROOT / "examples" / "table3_spatial.mod"
    ok, lines, _ = play(path, traj_file(tmp_path, SWEEP), record=gif, size=(240, 180))
    assert ok, lines
    assert "headless" in lines[0] and "no collisions" in "\n".join(lines)
    img = Image.open(gif)
    assert img.format == "GIF" and img.size == (240, 180) and img.info.get("loop") == 0
    hashes = []
    for k in range(img.n_frames):
        img.seek(k)
        hashes.append(hashlib.sha256(img.convert("RGB").tobytes()).hexdigest())
    assert img.n_frames >= 12, img.n_frames
    assert len(set(hashes)) >= 12  # the arm moves from frame to frame
    # deterministic: same input, same bytes
    gif2 = tmp_path / "again.gif"
    play(path, traj_file(tmp_path, SWEEP), record=gif2, size=(240, 180))
    assert gif2.read_bytes() == gif.read_bytes()


def test_play_tracks_and_reports_collisions(tmp_path):
    # straight from home to ready in joint space: link_3 cuts through the cell's right wall
    doc = {"joint_names": ["joint_1", "joint_2", "joint_3"],
           "points": [{"t": 0.0, "q": [0, 0, 0]}, {"t": 2.0, "q": [math.pi / 2, -math.pi / 4, -math.pi / 2]}]}
    ok, lines, _ = play(ROOT / "examples" / "farm.mod", traj_file(tmp_path, doc))
    assert ok
    text = "\n".join(lines)
    worst = float(re.search(r"worst tracking error ([0-9.e-]+) rad", text).group(1))
    assert worst < 0.02
    assert "warning: link_3 collides with obstacle right" in text


def test_play_joint_order_is_free(tmp_path):
    doc = {"joint_names": ["joint_3", "joint_1", "joint_2"],
           "points": [{"t": 0.0, "q": [0.0, 0.0, 0.0]}, {"t": 0.3, "q": [0.3, 0.2, 0.1]}]}
    ok, lines, _ = play(ROOT / "examples" / "table3_spatial.mod", traj_file(tmp_path, doc))
    assert ok, lines


BAD = [
    (
        {"joint_names": ["joint_1", "joint_2"], "points": [{"t": 0, "q": [0, 0]}]},
        "joint(s) joint_3 of robot spatial missing",
    ),
    ({"joint_names": ["joint_1", "joint_2", "elbow"], "points": [{"t": 0, "q": [0, 0, 0]}]}, "has no joint(s) elbow"),
    (
        {
            "joint_names": ["joint_1", "joint_2", "joint_3"],
            "points": [{"t": 0, "q": [0, 0, 0]}, {"t": 0, "q": [0, 0, 0]}],
        },
        "points[1].t: 0 s does not come after points[0].t = 0 s",
    ),
    (
        {"joint_names": ["joint_1", "joint_2", "joint_3"], "points": [{"t": 0, "q": [0, 0]}]},
        "points[0].q: 2 value(s) for 3 joint name(s)",
    ),
    (
        {"joint_names": ["joint_1", "joint_2", "joint_3"], "points": [{"t": 0, "q": [0, 4, 0]}]},
        "joint_2 = 4 rad (229.2°) is outside its range",
    ),
    ({"joint_names": ["joint_1", "joint_2", "joint_3"], "points": []}, "points: expected a non-empty list"),
    (
        {"joint_names": ["joint_1", "joint_2", "joint_3"], "points": [{"t": -1, "q": [0, 0, 0]}]},
        "points[0].t: -1 s is negative",
    ),
    (
        {"joint_names": ["joint_1", "joint_1", "joint_3"], "points": [{"t": 0, "q": [0, 0, 0]}]},
        "joint_1 listed more than once",
    ),
    ({"points": [{"t": 0, "q": [0, 0, 0]}]}, "joint_names: expected a non-empty list"),
    (
        {"joint_names": ["joint_1", "joint_2", "joint_3"], "points": [{"t": "0", "q": [0, 0, 0]}]},
        "points[0].t: expected a finite number",
    ),
    (
        '{"joint_names": ["joint_1", "joint_2", "joint_3"], "points": [{"t": 0, "q": [NaN, 0, 0]}]}',
        "points[0].q: expected a list of finite numbers",
    ),
    ("[1, 2", "not JSON"),
    ([1, 2], "the top level must be an object"),
]


@pytest.mark.parametrize("doc,message", BAD, ids=[m for _, m in BAD])
def test_play_rejects_bad_trajectories_saying_why(tmp_path, doc, message):
    p = traj_file(tmp_path, doc)
    ok, lines, checked = play(ROOT / "examples" / "table3_spatial.mod", p, record=tmp_path / "x.gif")
    assert checked.ok and not ok
    assert any(line.startswith(f"{p}: ") and message in line for line in lines), lines
    assert not (tmp_path / "x.gif").exists()


def test_play_usage_errors(tmp_path):
    with pytest.raises(scene.UsageError, match="cannot read"):
        play(ROOT / "examples" / "farm.mod", tmp_path / "missing.json")
    two = write(tmp_path, "robot a { chain H3 - L4 }\nrobot b { chain H3 - L4 }\n")
    doc = {"joint_names": ["joint_1", "joint_2"], "points": [{"t": 0, "q": [0, 0]}]}
    with pytest.raises(RobotChoiceError, match="defines 2 robots"):
        play(two, traj_file(tmp_path, doc))
    ok, _, _ = play(two, traj_file(tmp_path, {**doc, "robot": "b"}))
    assert ok


def test_trajectory_roundtrip_and_interpolation():
    t, errors = trajectory.parse(SWEEP)
    assert not errors
    assert t.at(-1.0) == t.q[0] and t.at(5.0) == t.q[-1]
    assert np.allclose(t.at(0.3), [0.45, -0.25, 0.4])
    assert json.loads(t.dumps()) == SWEEP


@pytest.mark.slow
def test_compile_smoke_option(tmp_path):
    """`modc FILE -o OUT --smoke` runs the PyBullet smoke test first; a failure writes nothing."""
    import subprocess
    import sys

    root = Path(__file__).resolve().parent.parent
    r = subprocess.run(
        [sys.executable, "-m", "modc", str(root / "examples" / "farm.mod"), "-o", str(tmp_path / "ok"), "--smoke"],
        capture_output=True,
        text=True,
    )
    assert r.returncode == 0 and "robot farm (H1-L4-L3): ok" in r.stderr
    bad = tmp_path / "heavy.mod"
    bad.write_text("robot heavy {\n    chain H1 - L4(pivot=-90deg, link=450mm) - L4(link=450mm)\n    payload 1 kg\n"
                   "    pose out (0, -90, 0) deg\n}\n")
    # --torque off lets the static check pass, so the simulation is what refuses the arm
    r = subprocess.run(
        [sys.executable, "-m", "modc", str(bad), "-o", str(tmp_path / "out"), "--smoke", "--torque", "off"],
        capture_output=True,
        text=True,
    )
    assert r.returncode == 1, r.stderr
    assert "joint_2 sags" in r.stderr and "smoke test failed; nothing written" in r.stderr
    assert not (tmp_path / "out").exists()
