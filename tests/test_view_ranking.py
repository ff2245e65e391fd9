"""`modc view DIR/ranking.json` without a browser: the list of designs, switching design, playing
a design's task (joint values against the .traj.json's own points, the segment named), a ranking
without tasks at its target poses, and names that lead out of DIR refused."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import test_design_task  # tests/: the task cell the design tests search

from modc.view.page import ViewError
from modc.view.ranking import Ranking, RankingPage

ROOT = Path(__file__).resolve().parent.parent

# a 3-module arm that serves two targets on either side of a post (as `modc design` wrote it)
TASKED = """robot small_1 {
    chain H1 - H1(pivot=-45deg) - L3(pivot=-15deg)
    payload 100 g
    box post size (0.05, 0.05, 0.6) m at (0.2, 0.25, 0.3) m
    target a at (0.3, 0.1, 0.25) m
    target b at (0.25, -0.15, 0.3) m
    task serve { visit a, b }
}
"""
# a second design, of another length, without a task
STATIC = """robot small_2 {
    chain H1 - L4(port=45deg) - L3 - L1
    target a at (0.3, 0.1, 0.25) m
}
"""
Q_A = [0.4, -0.3, 0.5, 0.2]


def _make(folder: Path) -> Path:
    """DIR as `modc design` writes it for a cell with a task: ranking.json, the robot files, and
    the first design's task planned by modc plan's own planner into its .traj.json."""
    from modc.compiler import check_text
    from modc.plan.task import plan_task_robot

    folder.mkdir(parents=True, exist_ok=True)
    (folder / "small_1.mod").write_text(TASKED, encoding="utf-8")
    (folder / "small_2.mod").write_text(STATIC, encoding="utf-8")
    plan = plan_task_robot(check_text(TASKED, "small_1.mod").design.robots[0], "serve")
    (folder / "small_1.traj.json").write_text(plan.dumps(), encoding="utf-8")
    doc = {"designs": [
        {"rank": 2, "file": "small_2.mod", "chain": "H1 - L4(port=45deg) - L3 - L1", "mass_kg": 2.9,
         "targets": {"a": {"q": Q_A, "position_error_m": 1e-9}}},
        {"rank": 1, "file": "small_1.mod", "chain": "H1 - H1(pivot=-45deg) - L3(pivot=-15deg)", "mass_kg": 2.08,
         "cycle_time_s": round(plan.cycle_time, 6), "traj": "small_1.traj.json", "traj_task": "serve",
         "targets": {"a": {"q": [0.0, 0.0, 0.0]}}}]}
    (folder / "ranking.json").write_text(json.dumps(doc), encoding="utf-8")
    return folder / "ranking.json"


@pytest.fixture(scope="module")
def made(tmp_path_factory) -> Path:
    return _make(tmp_path_factory.mktemp("designs") / "out")


@pytest.fixture
def ranking(made, tmp_path) -> Path:
    """A copy per test: tests may change the files."""
    shutil.copytree(made.parent, tmp_path / "out")
    return tmp_path / "out" / "ranking.json"


def _file_q(path: Path, t: float) -> np.ndarray:
    """The trajectory file's joint values at t, read here from its points (linear between them)."""
    doc = json.loads(path.read_text(encoding="utf-8"))
    ts = np.array([p["t"] for p in doc["points"]])
    qs = np.array([p["q"] for p in doc["points"]])
    return np.array([np.interp(t, ts, qs[:, j]) for j in range(qs.shape[1])])


def test_the_page_lists_the_designs_best_first(ranking):
    r = Ranking(ranking)
    assert [d["rank"] for d in r.designs] == [1, 2]
    cycle = json.loads(ranking.read_text(encoding="utf-8"))["designs"][1]["cycle_time_s"]
    assert r.choice(0) == f"1. rank 1: H1 - H1(pivot=-45deg) - L3(pivot=-15deg), {cycle:.3f} s"
    assert r.choice(1) == "2. rank 2: H1 - L4(port=45deg) - L3 - L1"
    assert "cycle time" in r.caption(0) and "'serve'" in r.caption(0)


def test_playback_follows_the_trajectory_file(ranking):
    page = RankingPage(Ranking(ranking))
    traj_file = ranking.parent / "small_1.traj.json"
    assert page.arm.robot.name == "small_1" and page.source.trajectory is not None
    assert page.q == pytest.approx(tuple(_file_q(traj_file, 0.0)))
    page.play()
    for _ in range(7):
        assert page.tick(0.37)
        assert np.allclose(page.q, _file_q(traj_file, page.t), atol=1e-9)
    assert page.t == pytest.approx(7 * 0.37)
    segs = json.loads(traj_file.read_text(encoding="utf-8"))["segments"]
    for t in (0.1, segs[1]["t_start_s"] + 0.01):
        page.seek(t)
        want = next(s for s in reversed(segs) if s["t_start_s"] <= t)
        seg = page.segment()
        assert seg is not None and (seg.kind, seg.start, seg.end) == (want["kind"], want["from"], want["to"])


def test_a_design_without_a_task_starts_at_its_target_pose(ranking):
    page = RankingPage(Ranking(ranking))
    page.choose(1)
    assert page.arm.robot.name == "small_2" and page.arm.dof == 4
    assert page.source.trajectory is None and page.segment() is None
    assert page.q == pytest.approx(tuple(Q_A))
    page.play()
    assert not page.tick(0.1)


def test_the_view_switches_design_and_names_the_segment(ranking):
    from modc.view.ranking_view import RankingView
    from modc.view.server import start

    server, view = start(RankingPage(Ranking(ranking)), port=0)
    try:
        assert isinstance(view, RankingView)
        assert view._designs.options == (Ranking(ranking).choice(0), Ranking(ranking).choice(1))
        assert len(view._sliders) == 3 and "small_1" in view._title.content
        assert 'data-segment="0"' in view._segment.content and "home → a" in view._segment.content
        view.page.play()
        view.step(2.5)  # into the motion a -> b
        assert 'data-segment="1"' in view._segment.content and "segment 1 of 1: a → b" in view._segment.content
        shown = [view._links[f"link_{i}"] for i in (1, 2, 3)]
        assert shown[0].wxyz is not None
        # the user picks the second design in the list
        view._designs.value = view._designs.options[1]
        view._on_choose(SimpleNamespace(client=object(), target=view._designs))
        assert view.page.index == 1 and len(view._sliders) == 4 and "small_2" in view._title.content
        assert view._segment is None
        assert [s.value for s in view._sliders] == pytest.approx([round(np.degrees(x), 1) for x in Q_A])
        # the previous/next buttons keep the list in step
        view._go(+1)
        assert view._designs.value == view._designs.options[0] and len(view._sliders) == 3
    finally:
        server.stop()


def test_collisions_and_diagnostics_show_as_in_the_normal_view(ranking):
    from modc.view.arm import COLLISION_RGB
    from modc.view.server import start

    (ranking.parent / "small_2.mod").write_text(STATIC.replace("L3 - L1", "L3 - L1 - L9"), encoding="utf-8")
    server, view = start(RankingPage(Ranking(ranking)), port=0)
    try:
        for i, x in enumerate((-2.9, -2.9, 0.97)):  # link_3 swung into the post
            view.page.set_joint(i, x)
        view._show_pose()
        assert [c.describe() for c in view.contacts] == ["link_3 with box 'post'"]
        assert 'data-contacts="1"' in view._contacts.content and "post" in view._contacts.content
        assert {tuple(rgb) for s, _, rgb in view._meshes if s.link == "link_3"} == {COLLISION_RGB}
        view._go(+1)  # the second design's file does not check: its diagnostics show, as `modc FILE` prints them
        assert view._errors.visible and "L9" in view._errors.content and view.page.arm is None
    finally:
        server.stop()


@pytest.mark.parametrize("field,name", [
    ("file", "../outside.mod"), ("file", "/etc/hostname"), ("traj", "../t.json"), ("file", "sub/../../x.mod"),
    ("file", "link.mod")])
def test_a_name_leading_out_of_the_folder_is_refused(ranking, field, name):
    outside = ranking.parent.parent / "outside.mod"
    outside.write_text(STATIC, encoding="utf-8")
    (ranking.parent / "link.mod").symlink_to(outside)
    doc = json.loads(ranking.read_text(encoding="utf-8"))
    doc["designs"][0][field] = name
    ranking.write_text(json.dumps(doc), encoding="utf-8")
    with pytest.raises(ViewError, match="ranking.json"):
        Ranking(ranking)


def test_the_command_refuses_a_ranking_that_leads_out(ranking):
    doc = json.loads(ranking.read_text(encoding="utf-8"))
    doc["designs"][1]["traj"] = "../../secret.json"
    ranking.write_text(json.dumps(doc), encoding="utf-8")
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    r = subprocess.run([sys.executable, "-m", "modc", "view", str(ranking), "--no-browser", "--port", "0"],
                       capture_output=True, text=True, env=env, timeout=120)
    assert r.returncode == 2 and "designs[1].traj" in r.stderr and "leads out of" in r.stderr
    assert "Traceback" not in r.stderr and "modc view:" not in r.stdout


@pytest.mark.slow
def test_a_real_design_run_plays_in_the_page(tmp_path):
    """`modc design` on a small cell with a task: its ranking.json opens, every design plays its own file's motion."""
    cell = tmp_path / "cell.mod"
    cell.write_text(test_design_task.TASKED, encoding="utf-8")
    env = dict(os.environ, PYTHONPATH=str(ROOT), MODC_CACHE_DIR=str(tmp_path / "cache"), PYTHONWARNINGS="ignore")
    r = subprocess.run([sys.executable, "-m", "modc", "design", str(cell), "-o", str(tmp_path / "out"), "-q",
                        "--no-render", "--top", "2"], capture_output=True, text=True, env=env, timeout=900)
    assert r.returncode == 0, r.stderr
    ranking = Ranking(tmp_path / "out" / "ranking.json")
    page = RankingPage(ranking)
    for k in range(len(ranking.designs)):
        page.choose(k)
        traj = ranking.traj(k)
        assert traj is not None and page.source.trajectory is not None, page.source.diagnostics
        assert page.arm.robot.name == f"small_{k + 1}"
        end = page.source.trajectory.t[-1]
        for t in (0.0, end / 3, end * 0.8, end):
            page.seek(t)
            assert np.allclose(page.q, _file_q(traj, t), atol=1e-9)
        assert page.segment() is not None
