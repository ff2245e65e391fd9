"""`modc plan --task` progress on stderr (a plain line at least every PLAIN_EVERY s when stderr
is not a terminal, nothing with -q), Ctrl-C exiting 130, and --timeout refusing nan, inf and
negatives."""
from __future__ import annotations

import io
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent

# two targets on either side of a post: one approach and one motion around it
TASKED = """robot small {
    chain H1 - H1(pivot=-45deg) - L3(pivot=-15deg)
    payload 100 g
    box post size (0.05, 0.05, 0.6) m at (0.2, 0.25, 0.3) m
    target a at (0.3, 0.1, 0.25) m
    target b at (0.25, -0.15, 0.3) m
    task serve { visit a, b }
}
"""


def _env(tmp_path: Path) -> dict[str, str]:
    return dict(os.environ, PYTHONPATH=str(ROOT), MODC_CACHE_DIR=str(tmp_path / "cache"), PYTHONWARNINGS="ignore")


def _plan(tmp_path: Path, *args: str) -> subprocess.CompletedProcess:
    src = tmp_path / "small.mod"
    src.write_text(TASKED, encoding="utf-8")
    return subprocess.run([sys.executable, "-m", "modc", "plan", str(src), *args], capture_output=True, text=True,
                          env=_env(tmp_path), timeout=300)


@pytest.mark.parametrize("value", ["nan", "inf", "-inf", "-1", "0", "NaN"])
def test_timeout_must_be_finite_seconds(tmp_path, value):
    """Was accepted: FloatRange(min=0.1) lets nan and inf through (nan < 0.1 is false)."""
    r = _plan(tmp_path, "--task", "serve", f"--timeout={value}")
    assert r.returncode == 2 and "--timeout" in r.stderr and "Traceback" not in r.stderr
    r = _plan(tmp_path, "--to", "a", f"--timeout={value}")
    assert r.returncode == 2 and "--timeout" in r.stderr


@pytest.mark.slow
def test_task_progress_on_stderr_and_quiet(tmp_path):
    r = _plan(tmp_path, "--task", "serve", "--json")
    assert r.returncode == 0, r.stderr
    lines = [ln for ln in r.stderr.splitlines() if ln.startswith("modc plan: task 'serve'")]
    assert lines and lines[-1].startswith("modc plan: task 'serve': 1 segment(s) planned and timed")
    assert r.stdout.lstrip().startswith("{")  # the trajectory alone on stdout
    q = _plan(tmp_path, "--task", "serve", "--json", "-q")
    assert q.returncode == 0 and "modc plan:" not in q.stderr and q.stdout == r.stdout


def test_plain_progress_ticks_while_a_segment_is_planned(monkeypatch):
    """A segment's search may take the whole --timeout: the plain lines come from a ticker, not the planner."""
    from modc.cli import plan_progress

    monkeypatch.setattr(plan_progress, "PLAIN_EVERY", 0.05)
    err = io.StringIO()
    monkeypatch.setattr(sys, "stderr", err)
    with plan_progress.progress("plain", "serve") as hook:
        assert hook is not None
        hook(1, 3, "motion", "a", "b")
        time.sleep(0.5)  # one long segment, no call from the planner
        hook(3, 3, "done", "", "")
    lines = err.getvalue().splitlines()
    ticks = [ln for ln in lines if "planning the segment 1 of 2 (a -> b)" in ln]
    assert len(ticks) >= 3, lines
    assert lines[-1].startswith("modc plan: task 'serve': 2 segment(s) planned and timed")
    with plan_progress.progress("off", "serve") as hook:
        assert hook is None


def test_live_status_names_the_segment():
    from modc.cli.plan_progress import Status

    s = Status("serve")
    assert "reading the file" in s.line()
    s(0, 3, "approach", "home", "tray[1,0,0]")
    assert "planning the approach (home -> tray[1,0,0])" in s.__rich__().plain  # not read as rich markup
    s(2, 3, "motion", "b", "c")
    assert "segment 2 of 2 (b -> c)" in s.line()


def test_task_plan_reports_each_segment_to_the_hook():
    from modc.compiler import check_text
    from modc.plan.task import plan_task_robot

    robot = check_text(TASKED, "small.mod").design.robots[0]
    calls: list[tuple] = []
    plan = plan_task_robot(robot, "serve", progress=lambda *a: calls.append(a))
    assert calls == [(0, 2, "approach", "home", "a"), (1, 2, "motion", "a", "b"), (2, 2, "done", "", "")]
    assert len(plan.segments) == 2


@pytest.mark.skipif(sys.platform == "win32", reason="SIGINT to a child process")
def test_ctrl_c_exits_130_without_a_traceback(tmp_path):
    src = tmp_path / "small.mod"
    src.write_text(TASKED, encoding="utf-8")
    p = subprocess.Popen([sys.executable, "-m", "modc", "plan", str(src), "--task", "serve"], env=_env(tmp_path),
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert p.stderr is not None
    first = p.stderr.readline()  # the first progress line: the command is past click's parsing
    assert first.startswith("modc plan: task 'serve'"), first
    p.send_signal(signal.SIGINT)
    out, err = p.communicate(timeout=120)
    if p.returncode == 0:  # the plan finished before the signal came: nothing to check
        pytest.skip("the plan finished before Ctrl-C")
    assert p.returncode == 130, err
    assert "interrupted" in err and "Traceback" not in err
