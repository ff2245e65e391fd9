"""`modc view` without a browser: the page model (joints -> FK and torques, poses, playback,
re-checking the file on save, paging a ranking) and the command line around the server."""
from __future__ import annotations

import contextlib
import io
import json
import logging
import math
import os
import signal
import socket
import subprocess
import sys
import urllib.request
from pathlib import Path

import numpy as np
import pytest
from websockets.exceptions import ConnectionClosed

from modc.compiler import check_file
from modc.dynamics.model import Dynamics
from modc.kinematics import Chain
from modc.view.arm import Arm
from modc.view.page import Page, Ranking, Source, ViewError

ROOT = Path(__file__).resolve().parent.parent
FARM = ROOT / "examples" / "farm.mod"

GOOD = ("robot arm {\n    chain H1 - L4(port=45deg) - L1\n    pose ready (30, -40, 60) deg\n"
        "    target p at (0.2, 0, 0.3) m\n}\n")
LONGER = "robot arm {\n    chain H1 - L4(port=45deg) - L3 - L1\n}\n"
BROKEN = "robot arm {\n    chain H1 - L4(port=45deg - L1\n}\n"


def _robot(path=FARM):
    c = check_file(path)
    assert c.ok
    return c.design.robots[0]


def _write(path: Path, text: str) -> None:
    """Write and move the mtime on, so a poll sees the change even within the clock's resolution."""
    before = path.stat().st_mtime_ns if path.exists() else 0
    path.write_text(text, encoding="utf-8")
    st = path.stat()
    os.utime(path, ns=(st.st_atime_ns, max(st.st_mtime_ns, before + 1_000_000)))


def test_link_poses_follow_the_kinematics():
    robot = _robot()
    arm, chain = Arm(robot), Chain(robot)
    rng = np.random.default_rng(1)
    for _ in range(5):
        q = [rng.uniform(lo, hi) for lo, hi in arm.limits]
        assert np.allclose(arm.tool0(q), chain.T_base_tool(q)[:3, 3], atol=1e-12)
        T = arm.link_poses(q)
        for i, f in enumerate(chain.frames(q)):
            assert np.allclose(T[f"link_{i + 1}"], f["T_base_joint"], atol=1e-12)


def test_shapes_are_the_urdf_meshes_placed_on_their_links():
    arm = Arm(_robot())
    shapes = arm.shapes()
    assert len(shapes) == sum(len(link.visuals) for link in arm.description.links)
    assert {s.link for s in shapes} == {"base_link", "link_1", "link_2", "link_3"}
    for s in shapes:
        assert s.faces.max() < len(s.vertices) and len(s.faces) > 10
    # the 180 mm link bar of the last unit is the 1 m mesh scaled to its length
    bar = next(s for s in shapes if s.link == "link_3" and s.name.startswith("link_"))
    assert bar.vertices[:, 0].max() - bar.vertices[:, 0].min() == pytest.approx(0.18, abs=1e-6)


def test_shapes_are_the_stl_triangles_the_urdf_ships():
    from modc.physical.meshes import stl_bytes

    arm = Arm(_robot())
    link = next(link for link in arm.description.links if link.name == "link_1")
    shape = next(s for s in arm.shapes() if s.link == "link_1")
    v = link.visuals[0]
    data = stl_bytes(v.part)
    n = int(np.frombuffer(data, "<u4", 1, 80)[0])
    rec = np.dtype([("normal", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    tri = np.frombuffer(data, rec, n, 84)["v"].astype(np.float64)
    tri[..., 0] *= v.part.scale_x
    tri = tri @ v.T_link_part[:3, :3].T + v.T_link_part[:3, 3]
    assert np.allclose(shape.vertices[shape.faces], tri, atol=1e-6)


def test_torques_are_pinocchio_gravity_against_the_actuators():
    robot = _robot()
    arm, dyn = Arm(robot), Dynamics(robot)
    q = (0.3, -0.8, 1.1)
    got = arm.torques(q)
    assert [j.tau for j in got] == pytest.approx(dyn.gravity(q).tolist(), abs=1e-12)
    lib = robot.library
    for j, u in zip(got, robot.units, strict=True):
        act = lib.variants[u.variant].actuator
        assert (j.tau_nom, j.tau_max, j.unit) == (act.torque_nominal, act.torque_peak, u.name)
        want = "over-peak" if abs(j.tau) > j.tau_max else "over-nominal" if abs(j.tau) > j.tau_nom else "ok"
        assert j.level == want


def test_torque_level_follows_the_slider(tmp_path):
    """5 kg at tool0: held upright every joint is fine; stretched out the shoulder is over its
    nominal torque and the elbow over its peak."""
    f = tmp_path / "heavy.mod"
    f.write_text("robot heavy {\n    chain H1 - H4(pivot=-90deg) - L3\n    payload 5 kg\n}\n", encoding="utf-8")
    page = Page([Source(f)])
    assert [j.level for j in page.arm.torques(page.q)] == ["ok", "ok", "ok"]
    page.set_joint(1, math.pi / 2)
    assert [j.level for j in page.arm.torques(page.q)] == ["ok", "over-nominal", "over-peak"]


def test_sliders_clamp_and_move_tool0():
    page = Page([Source(FARM)])
    arm = page.arm
    assert page.q == arm.robot.home()
    before = arm.tool0(page.q)
    page.set_joint(0, 0.5)
    assert page.q[0] == 0.5
    assert not np.allclose(arm.tool0(page.q), before)
    page.set_joint(1, 100.0)
    assert page.q[1] == arm.limits[1][1]


def test_poses_home_first():
    page = Page([Source(FARM)])
    assert [n for n, _ in page.arm.poses] == ["home", "ready"]
    page.go_pose("ready")
    assert page.q == pytest.approx(tuple(math.radians(d) for d in (90, -45, -90)))
    page.go_pose("home")
    assert page.q == page.arm.robot.home()


def test_saving_rechecks_and_an_error_keeps_the_last_good_arm(tmp_path):
    f = tmp_path / "arm.mod"
    _write(f, GOOD)
    page = Page([Source(f)])
    good = page.arm
    assert good is not None and not page.source.errors and page.source.diagnostics == ""
    page.set_joint(0, 0.4)
    assert not page.poll()  # nothing changed on disk

    _write(f, BROKEN)
    assert page.poll()
    assert page.arm is good and page.source.errors
    assert "error[" in page.source.diagnostics and f"{f}:2:" in page.source.diagnostics
    assert page.q[0] == 0.4  # the pose stays with the arm

    _write(f, GOOD.replace("pose ready (30, -40, 60) deg", "pose ready (10, -40, 60) deg"))
    assert page.poll()
    assert page.arm is not good and not page.source.errors and page.source.diagnostics == ""
    assert page.q[0] == 0.4  # same joints: the sliders stay where they were
    assert dict(page.arm.poses)["ready"][0] == pytest.approx(math.radians(10))

    _write(f, LONGER)  # one more module: the joints it had keep their values, the new one starts at home
    assert page.poll()
    assert page.arm.dof == 4 and page.q == (0.4, 0.0, 0.0, page.arm.robot.home()[3])


def test_a_file_that_starts_broken_shows_an_arm_once_fixed(tmp_path):
    f = tmp_path / "arm.mod"
    _write(f, BROKEN)
    page = Page([Source(f)])
    assert page.arm is None and page.source.errors
    _write(f, GOOD)
    assert page.poll() and page.arm is not None and page.q == page.arm.robot.home()


HEAVY = "robot heavy {\n    chain H1 - H4(pivot=-90deg) - L3\n    payload 5 kg\n    target far at (0.3, 0, 0.2) m\n}\n"


def test_the_page_shows_what_the_compile_says_and_the_module_it_names(tmp_path):
    """`modc FILE -o OUT` refuses an arm whose elbow cannot hold 5 kg (torque-over-peak): the page
    says so too, still draws the arm, and names the module."""
    from modc.compiler import COMPILE_ANALYSES
    from modc.diagnostics.render import render_text

    f = tmp_path / "heavy.mod"
    _write(f, HEAVY)
    page = Page([Source(f)])
    compiled = check_file(f, analyses=COMPILE_ANALYSES, torque_severity="error")
    assert not compiled.ok and "torque-over-peak" in {d.code for d in compiled.diagnostics}
    assert page.source.diagnostics == render_text(compiled.diagnostics, compiled.sources)
    assert page.source.errors and page.arm is not None and page.source.current
    named = {page.arm.unit_named(d) for d in page.source.found if d.code == "torque-over-peak"}
    assert named == {2}  # L3, the third module
    assert {s.unit for s in page.arm.shapes()} == {0, 1, 2}


def test_each_part_belongs_to_its_module():
    """Shapes per module are exactly that module's parts (physical.parts.unit_parts)."""
    from collections import Counter

    from modc.physical.parts import unit_parts

    arm = Arm(_robot())
    got = Counter(s.unit for s in arm.shapes())
    lib = arm.robot.library
    want = {i: len(unit_parts(lib, u.variant, u.kind, arm.robot.link_length(u))) for i, u in enumerate(arm.robot.units)}
    assert dict(got) == want
    meshes = {i: sorted(s.name.rsplit("_", 1)[0] for s in arm.shapes() if s.unit == i) for i in want}
    for i, u in enumerate(arm.robot.units):
        assert meshes[i] == sorted(p.mesh for p in unit_parts(lib, u.variant, u.kind, arm.robot.link_length(u)))


FLOOR = ("robot arm {\n    chain H1 - L4(pivot=-90deg, port=45deg) - L3(link=180mm)\n"
         "    box floor size (0.8, 0.8, 0.02) m at (0, 0, -0.01) m\n"
         "    target plant at (0.25, 0.1, 0.2) m\n    target tray at (0.25, 0.05, 0.22) m rpy (0, 90, 0) deg\n}\n")


def test_contacts_are_the_planner_s(tmp_path):
    """Bending the shoulder down puts the arm into the floor: the page lists what `modc plan`'s
    checker (the URDF's collision meshes, the SRDF's disabled pairs, the obstacles) finds."""
    from modc.plan.collision import CollisionChecker

    f = tmp_path / "floor.mod"
    _write(f, FLOOR)
    page = Page([Source(f)])
    arm = page.arm
    assert arm.contacts(page.q) == []
    page.set_joint(1, arm.limits[1][1])
    got = arm.contacts(page.q)
    assert {(c.a, c.b) for c in got} >= {("link_2", "floor")}
    assert got == CollisionChecker(arm.robot).contacts(page.q)


def test_framing_fits_the_scene_beside_the_panel():
    from modc.view.camera import ASPECT, PANEL, frame, project

    arm = Arm(_robot())
    pts = arm.extent(arm.robot.home())
    cam = frame(pts, math.radians(210), math.radians(30))
    p = project(pts, cam)
    assert p[:, 0].min() >= -1 and p[:, 0].max() <= 1 - 2 * PANEL and abs(p[:, 1]).max() <= 1
    # as close as that allows: the scene spans the free area's width or its height, nearly
    span = max((p[:, 0].max() - p[:, 0].min()) / (2 - 2 * PANEL), (p[:, 1].max() - p[:, 1].min()) / 2)
    assert span > 0.75, span
    assert ASPECT > 1


def test_labels_do_not_overlap_on_screen(tmp_path):
    from modc.view import draw
    from modc.view.camera import HEIGHT, frame, project

    f = tmp_path / "floor.mod"
    _write(f, FLOOR)
    arm = Page([Source(f)]).arm
    cam = frame(arm.extent(arm.robot.home()), math.radians(210), math.radians(30))
    targets = arm.robot.targets
    lifts = draw.label_lifts(targets, cam, arm.T_world_base)
    anchors = project(np.array([np.asarray(t.xyz) + d for t, d in zip(targets, lifts, strict=True)]), cam)
    y = (1 - anchors[:, 1]) / 2 * HEIGHT
    assert abs(y[0] - y[1]) >= draw.LABEL_HEIGHT - 1  # the two targets are 5 cm apart: stacked
    assert [draw.target_label(t) for t in targets] == ["plant ±5 mm", "tray ±5 mm, ±2°"]


def test_several_robots_need_a_choice(tmp_path):
    from modc.model.select import RobotChoiceError

    f = tmp_path / "two.mod"
    f.write_text("robot a {\n    chain H1 - L1\n}\nrobot b {\n    chain H1 - L4 - L1\n}\n", encoding="utf-8")
    with pytest.raises(RobotChoiceError):
        Source(f).load(strict=True)
    s = Source(f, robot="b")
    s.load(strict=True)
    assert s.arm.robot.name == "b" and s.arm.dof == 3


def _ranking(tmp_path: Path) -> Path:
    d = tmp_path / "designs"
    d.mkdir()
    (d / "d1.mod").write_text(GOOD, encoding="utf-8")
    (d / "d2.mod").write_text(LONGER, encoding="utf-8")
    doc = {"designs": [{"rank": 2, "file": "d2.mod", "chain": "H1-L4-L3-L1", "mass_kg": 3.2},
                       {"rank": 1, "file": "d1.mod", "chain": "H1-L4-L1", "mass_kg": 2.5}],
           "evaluated": 7, "seconds": 1.0}
    (d / "ranking.json").write_text(json.dumps(doc), encoding="utf-8")
    return d / "ranking.json"


def test_ranking_pages_through_the_designs_best_first(tmp_path):
    page = Page.for_ranking(Ranking(_ranking(tmp_path)))
    assert page.caption.startswith("design 1 of 2: rank 1, H1-L4-L1, 2.5 kg")
    assert page.arm.dof == 3 and page.sources[1].arm is None  # later designs are checked when shown
    page.go(+1)
    assert page.caption.startswith("design 2 of 2: rank 2") and page.arm.dof == 4
    assert page.q == page.arm.robot.home()
    page.go(+1)
    assert page.index == 0 and page.arm.dof == 3
    page.go(-1)
    assert page.index == 1


def test_bad_ranking_is_a_usage_error(tmp_path):
    f = tmp_path / "ranking.json"
    for text in ("{", "[]", '{"designs": []}', '{"designs": [{"rank": 1}]}'):
        f.write_text(text, encoding="utf-8")
        with pytest.raises(ViewError):
            Ranking(f)
    with pytest.raises(ViewError):
        Ranking(tmp_path / "missing.json")


def _traj(tmp_path: Path, q_last) -> Path:
    from modc.trajectory import Trajectory

    t = Trajectory(("joint_1", "joint_2", "joint_3"), (0.0, 1.0), ((0.0, 0.0, 0.0), tuple(q_last)))
    p = tmp_path / "t.json"
    p.write_text(t.dumps(), encoding="utf-8")
    return p


def test_playback_runs_the_trajectory(tmp_path):
    from modc.view.page import read_trajectory

    src = Source(FARM, traj=read_trajectory(str(_traj(tmp_path, (0.5, -0.3, 0.2)))))
    page = Page([src])
    assert src.trajectory is not None
    page.play()
    assert page.tick(0.5) and page.q == pytest.approx((0.25, -0.15, 0.1))
    assert page.tick(0.7) and not page.playing and page.q == pytest.approx((0.5, -0.3, 0.2))
    assert not page.tick(0.1)
    page.play()  # from the end: starts over
    assert page.tick(0.1) and page.t == pytest.approx(0.1)


def test_a_trajectory_that_does_not_fit_is_shown_not_played(tmp_path):
    from modc.view.page import read_trajectory

    src = Source(FARM, traj=read_trajectory(str(_traj(tmp_path, (9.0, 0.0, 0.0)))))
    page = Page([src])
    assert src.trajectory is None and "joint_1" in src.diagnostics and "outside its range" in src.diagnostics
    page.play()
    assert not page.tick(0.1)
    (tmp_path / "bad.json").write_text("{", encoding="utf-8")
    with pytest.raises(ViewError):
        read_trajectory(str(tmp_path / "bad.json"))


# --- the server, without a browser -------------------------------------------------------------

def test_server_serves_the_client_locally():
    from modc.view.server import start

    server, view = start(Page([Source(FARM)]), port=0)
    try:
        html = urllib.request.urlopen(view.url, timeout=30).read().decode()
        assert "<html" in html.lower() and "viser" in html.lower()
        view.step(0.05)
        assert set(view._links) >= {"base_link", "link_1", "link_2", "link_3", "tool0"}
        assert len(view._sliders) == 3
    finally:
        server.stop()


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _env():
    return {**os.environ, "PYTHONPATH": str(ROOT)}


def test_busy_port_is_a_clean_error():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        port = s.getsockname()[1]
        r = subprocess.run([sys.executable, "-m", "modc", "view", str(FARM), "--no-browser", "--port", str(port)],
                           capture_output=True, text=True, env=_env(), timeout=120)
    assert r.returncode == 2, r.stderr
    assert f"modc view: port {port} on 127.0.0.1 is busy" in r.stderr and "Traceback" not in r.stderr


def test_unknown_robot_and_bad_ranking_exit_2(tmp_path):
    r = subprocess.run([sys.executable, "-m", "modc", "view", str(FARM), "--no-browser", "--robot", "nope"],
                       capture_output=True, text=True, env=_env(), timeout=120)
    assert r.returncode == 2 and "robot-unknown" in r.stderr and "Traceback" not in r.stderr
    (tmp_path / "ranking.json").write_text("{}", encoding="utf-8")
    r = subprocess.run([sys.executable, "-m", "modc", "view", str(tmp_path / "ranking.json"), "--no-browser"],
                       capture_output=True, text=True, env=_env(), timeout=120)
    assert r.returncode == 2 and "modc view:" in r.stderr and "Traceback" not in r.stderr


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the no-display rule is Linux's")
def test_ctrl_c_stops_cleanly():
    """Without a display (as in CI) no browser is tried; Ctrl-C ends the server with exit 0, at
    any moment after the address is printed."""
    port = _free_port()
    env = {k: v for k, v in _env().items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    p = subprocess.Popen([sys.executable, "-m", "modc", "view", str(FARM), "--port", str(port)],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        line = p.stdout.readline()
        assert f"http://127.0.0.1:{port}/?token=" in line
        url = line.split()[2]
        p.send_signal(signal.SIGINT)  # right after the address, before or while the page serves
        out, err = p.communicate(timeout=60)
    finally:
        if p.poll() is None:
            p.kill()
    assert p.returncode == 0, err
    assert "Traceback" not in err and "stopped" in out and "Aborted" not in err
    assert url.startswith(f"http://127.0.0.1:{port}/?token=")


# Runs `modc view` with the page's build held until the test sends Ctrl-C: the build announces
# itself on stdout (the event the test waits on) and then waits.
HOLD_THE_BUILD = """
import sys, threading
import modc.view.server as s
def held(self, *args, **kwargs):
    print("building the page", flush=True)
    threading.Event().wait()
s.View.__init__ = held
sys.argv = ["modc", "view", sys.argv[1], "--no-browser", "--port", "0"]
from modc.cli import main
main()
"""


def test_ctrl_c_while_starting_aborts():
    p = subprocess.Popen([sys.executable, "-c", HOLD_THE_BUILD, str(FARM)], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True, env=_env())
    try:
        assert p.stdout.readline() == "building the page\n"
        p.send_signal(signal.SIGINT)
        out, err = p.communicate(timeout=60)
    finally:
        if p.poll() is None:
            p.kill()
    assert p.returncode == 1, err
    assert err.strip() == "Aborted!" and out == "", (out, err)


def test_torque_table_colours_each_joint_by_level(tmp_path):
    from modc.view.arm import LEVEL_RGB
    from modc.view.server import torque_table

    f = tmp_path / "heavy.mod"
    f.write_text("robot heavy {\n    chain H1 - H4(pivot=-90deg) - L3\n    payload 5 kg\n}\n", encoding="utf-8")
    arm = Arm(check_file(f).design.robots[0])
    table = torque_table(arm, (0.0, math.pi / 2, 0.0))
    rows = table.split("<tr data-level=")[1:]
    assert [r.split('"')[1] for r in rows] == ["ok", "over-nominal", "over-peak"]
    for row, level in zip(rows, ("ok", "over-nominal", "over-peak"), strict=True):
        assert "background:rgb({},{},{})".format(*LEVEL_RGB[level]) in row
    assert "12 / 30.5" in rows[0] and "3.6 / 6.8" in rows[2]  # τnom / τmax of the H and L actuators


def test_user_text_reaches_the_page_escaped(tmp_path):
    from modc.view.server import start

    ranking = _ranking(tmp_path)
    doc = json.loads(ranking.read_text(encoding="utf-8"))
    doc["designs"][1]["chain"] = "<img src=x onerror=alert(1)>"
    ranking.write_text(json.dumps(doc), encoding="utf-8")
    server, view = start(Page.for_ranking(Ranking(ranking)), port=0)
    try:
        assert "&lt;img src=x" in view._title.content and "<img" not in view._title.content
        _write(ranking.parent / "d1.mod", GOOD.replace("robot arm {", "robot arm { <b>"))
        view.step(0.05)
        assert "&lt;b&gt;" in view._errors.content and "<b>" not in view._errors.content.split("</b>", 1)[1]
    finally:
        server.stop()


# --- who may open the page: this run's token, and on the websocket the page's own origin ---------

def _ws(port: int, origin: str | None, cookie: str | None = None, query: str = ""):
    import viser
    from websockets.sync.client import connect

    headers = {"Cookie": cookie} if cookie else {}
    return connect(f"ws://127.0.0.1:{port}/{query}", origin=origin, additional_headers=headers, open_timeout=30,
                   subprotocols=[f"viser-v{viser.__version__}"])


def test_the_page_needs_its_token_and_the_websocket_its_origin():
    from urllib.error import HTTPError

    from websockets.exceptions import InvalidStatus

    from modc.view.server import start

    server, view = start(Page([Source(FARM)]), port=0)
    port = server.get_port()
    token = view.url.split("?token=", 1)[1]
    origin = f"http://127.0.0.1:{port}"
    try:
        assert view.url == f"{origin}/?token={token}" and len(token) >= 32
        for url in (f"{origin}/", f"{origin}/?token={token[:-1]}", f"{origin}/index.html", f"{origin}/?token="):
            with pytest.raises(HTTPError) as e:
                urllib.request.urlopen(url, timeout=30)
            assert e.value.code == 403
        with urllib.request.urlopen(view.url, timeout=30) as r:
            assert r.status == 200 and "<html" in r.read().decode().lower()
            cookie = r.headers["Set-Cookie"].split(";")[0]
        assert cookie == f"modc-view-{port}={token}" and "HttpOnly" in r.headers["Set-Cookie"]
        assert urllib.request.urlopen(urllib.request.Request(f"{origin}/", headers={"Cookie": cookie}),
                                      timeout=30).status == 200

        refused = [(None, cookie), ("http://evil.example", cookie), (f"http://localhost:{port}", cookie),
                   (f"http://127.0.0.1:{port + 1}", cookie), (origin, None), (origin, f"modc-view-{port}=wrong"),
                   (origin, f"modc-view-{port + 1}={token}")]
        for o, c in refused:
            with pytest.raises(InvalidStatus) as e:
                _ws(port, o, c)
            assert e.value.response.status_code == 403, (o, c)
        for c, query in ((cookie, ""), (None, f"?token={token}")):
            with _ws(port, origin, c, query) as ws:
                assert len(ws.recv(timeout=30)) > 1000  # the scene
    finally:
        server.stop()


def test_the_guard_is_in_viser_s_request_path():
    """modc view wraps the one serve() call viser makes; if a new viser stops making it, the
    server must refuse to start rather than serve an unguarded page."""
    import websockets.asyncio.server as wss

    from modc.view.guard import Guard, guarding

    original = wss.serve
    import viser

    with guarding(Guard()) as used, contextlib.redirect_stdout(io.StringIO()):
        server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    try:
        assert used == [True], "viser no longer calls websockets.asyncio.server.serve: modc view cannot guard it"
        assert wss.serve is original
    finally:
        with contextlib.redirect_stdout(io.StringIO()):
            server.stop()


def test_a_malformed_message_is_one_line_per_connection(caplog):
    from modc.view.server import start

    server, view = start(Page([Source(FARM)]), port=0)
    port = server.get_port()
    token = view.url.split("?token=", 1)[1]
    try:
        with caplog.at_level(logging.INFO, logger="websockets.server"):
            for garbage in (b"\xc1\xff\x00garbage", "text, not msgpack"):
                with _ws(port, f"http://127.0.0.1:{port}", query=f"?token={token}") as ws:
                    ws.recv(timeout=30)
                    ws.send(garbage)
                    for _ in range(1000):  # drained until viser closes the connection
                        try:
                            ws.recv(timeout=30)
                        except ConnectionClosed:
                            break
        failed = [r for r in caplog.records if "malformed message" in r.getMessage()]
        assert len(failed) == 2 and all(r.exc_info is None and "\n" not in r.getMessage() for r in failed)
        assert not [r for r in caplog.records if r.exc_info], "a traceback was logged"
    finally:
        server.stop()


def test_a_message_viser_cannot_apply_is_one_line_per_kind():
    """Found by the fuzz campaign (scripts/fuzz_ws.py, end to end): well-formed frames with values
    viser cannot apply (a GUI update of a property that does not exist, a null slider value) printed
    a full traceback per frame through asyncio's "Task exception was never retrieved". The filter
    modc view installs on asyncio's logger keeps one line per kind of error, without traceback."""
    from modc.view.guard import OneLineHandlerErrors, quiet_malformed_messages

    quiet_malformed_messages()
    assert any(isinstance(f, OneLineHandlerErrors) for f in logging.getLogger("asyncio").filters)

    def record(exc: BaseException) -> logging.LogRecord:
        text = ("Task exception was never retrieved\nfuture: <Task finished coro=<WebsockMessageHandler."
                f"_handle_incoming_message() done> exception={exc!r}>")
        return logging.LogRecord("asyncio", logging.ERROR, __file__, 1, text, None, (type(exc), exc, None))

    f = OneLineHandlerErrors()
    first, again, other = record(AssertionError()), record(AssertionError()), record(TypeError("float() None"))
    assert f.filter(first) and first.exc_info is None and "\n" not in first.getMessage()
    assert "cannot apply" in first.getMessage()
    assert not f.filter(again)  # the same kind again: dropped
    assert f.filter(other) and "TypeError: float() None" in other.getMessage()
    unrelated = logging.LogRecord("asyncio", logging.ERROR, __file__, 1, "something else", None, None)
    assert f.filter(unrelated) and unrelated.getMessage() == "something else"
