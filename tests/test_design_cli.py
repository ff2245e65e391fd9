"""`modc design` as a command: a time budget, Ctrl-C, progress on stderr, the output folder
checked before the search, exit codes."""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent

# two targets at tool0 of an H4-L3 arm: found within a second; the 3- and 4-unit shapes after it
# take far longer than the budgets below
CELL = """design two {
    target t0 at (-0.333652449, -0.199597937, 0.127445974) m within 3 mm, 2 deg
    target t1 at (-0.186580953, 0.390032369, -0.056370661) m within 3 mm, 2 deg
    units 2 to 4
    modules H4, L3
}
"""

BIG = """design big {
    target a at (0.30, 0.10, 0.25) m
    target b at (0.25, -0.15, 0.30) m
    target c at (0.10, 0.30, 0.45) m
    units 5 to 6
}
"""


def _env(tmp_path) -> dict:
    return dict(os.environ, PYTHONPATH=str(ROOT), MODC_CACHE_DIR=str(tmp_path / "cache"), PYTHONWARNINGS="ignore")


def _run(tmp_path, text: str, *args: str, timeout: float = 600) -> subprocess.CompletedProcess:
    src = tmp_path / "cell.mod"
    src.write_text(text, encoding="utf-8")
    return subprocess.run([sys.executable, "-m", "modc", "design", str(src), *args], capture_output=True, text=True,
                          env=_env(tmp_path), cwd=tmp_path, timeout=timeout)


@pytest.mark.slow
def test_time_budget_keeps_the_best_found(tmp_path):
    out = tmp_path / "out"
    p = _run(tmp_path, CELL, "-o", str(out), "--no-render", "--top", "20", "--time-budget", "20s")
    # how far 20 s get depends on the machine's load: assert what each outcome must look like
    if p.returncode == 1:  # nothing found before the budget ran out: said so, nothing written
        assert "the time budget ran out" in p.stderr and "no design found" in p.stderr and not out.exists()
    else:
        assert p.returncode == 0, p.stderr
        ranking = json.loads((out / "ranking.json").read_text(encoding="utf-8"))
        assert ranking["designs"] and ranking["designs"][0]["modules"] == 2  # the best found is kept
        if ranking["stopped"] is None:  # a fast machine finished within the budget
            assert ranking["complete"] is True and not ranking["unfinished_shapes"]
        else:
            assert ranking["stopped"] == "time budget" and ranking["complete"] is False
            assert ranking["unfinished_shapes"]
            assert "the time budget ran out" in p.stderr and "shapes not finished" in p.stderr
    # progress lines on a non-terminal stderr, the first at once
    lines = [ln for ln in p.stderr.splitlines() if "feasible, best" in ln]
    assert lines and "shapes" in lines[0] and "ETA" in lines[0]


@pytest.mark.slow
def test_time_budget_with_nothing_found_exits_1(tmp_path):
    # a payload no arm holds: whatever the machine's speed, nothing is found before the budget
    # runs out over the 5,120 shapes (the torque screen rules out each chain the search finds)
    out = tmp_path / "out"
    heavy = BIG.replace("design big {\n", "design big {\n    payload 40 kg\n")
    p = _run(tmp_path, heavy, "-o", str(out), "--no-render", "--time-budget", "1s", "-q")
    assert p.returncode == 1, p.stderr
    assert "the time budget ran out" in p.stderr and "no design found" in p.stderr
    assert "feasible, best" not in p.stderr  # -q: no progress
    assert "inf" not in p.stderr.replace("info", "") and not out.exists()


def test_output_folder_is_checked_before_the_search(tmp_path):
    (tmp_path / "taken").write_text("not a directory", encoding="utf-8")
    p = _run(tmp_path, BIG, "-o", str(tmp_path / "taken"), "--no-render")
    assert p.returncode == 2, p.stderr
    assert "output-unsafe" in p.stderr and "feasible, best" not in p.stderr  # a plain file is never replaced
    assert (tmp_path / "taken").read_text(encoding="utf-8") == "not a directory"
    other = tmp_path / "other"
    other.mkdir()
    (other / "notes.txt").write_text("mine", encoding="utf-8")
    p = _run(tmp_path, BIG, "-o", str(other), "--no-render")
    assert p.returncode == 2 and "notes.txt" in p.stderr and "feasible, best" not in p.stderr
    assert (other / "notes.txt").read_text(encoding="utf-8") == "mine"  # and no progress line: no search ran


def test_bad_duration_is_a_usage_error(tmp_path):
    p = _run(tmp_path, BIG, "-o", str(tmp_path / "o"), "--time-budget", "soon")
    assert p.returncode == 2 and "not a duration" in p.stderr


@pytest.mark.slow
@pytest.mark.parametrize("workers", ["1", "2"])
def test_ctrl_c_stops_with_exit_130(tmp_path, workers):
    """Ctrl-C keeps what was found and exits 130, also with a process pool (whose workers are
    ended, not waited for)."""
    src = tmp_path / "cell.mod"
    src.write_text(BIG, encoding="utf-8")
    proc = subprocess.Popen([sys.executable, "-m", "modc", "design", str(src), "-o", str(tmp_path / "out"),
                             "--no-render", "--workers", workers], stderr=subprocess.PIPE, stdout=subprocess.DEVNULL,
                            text=True, env=_env(tmp_path), cwd=tmp_path)
    try:
        assert proc.stderr is not None
        first = proc.stderr.readline()  # blocks until the first progress line: the search has started
        assert "feasible, best" in first, first
        proc.send_signal(signal.SIGINT)
        rest = proc.stderr.read()
        rc = proc.wait(timeout=300)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert rc == 130, rest
    assert "interrupted" in rest and "Traceback" not in rest


@pytest.mark.slow
def test_a_block_the_budget_leaves_unsearched_is_said(tmp_path):
    """Two design blocks, the first far larger than the budget: the second is named as not
    searched (on stderr and in ranking.json), not skipped in silence; a target beyond every arm
    of the bounds is still proven out of reach though the time ran out."""
    far = BIG.replace("    units 5 to 6\n", "    target far at (3.0, 0, 0.2) m\n    units 5 to 6\n")
    out = tmp_path / "out"
    # no shape reaches `far`: nothing to search, and the time runs out probing a, b and c alone
    p = _run(tmp_path, far, "-o", str(out), "--no-render", "--time-budget", "1s", "-q")
    assert p.returncode == 1, p.stderr
    assert "target 'far': no design gets closer than" in p.stderr and "(reach)" in p.stderr, p.stderr
    p = _run(tmp_path, BIG + CELL, "-o", str(out), "--no-render", "--time-budget", "1s", "-q")
    assert "two: not searched: the time budget ran out" in p.stderr
    if p.returncode == 0:  # the first block found a design within the second
        ranking = json.loads((out / "ranking.json").read_text(encoding="utf-8"))
        assert ranking["not_searched"] == ["two"] and ranking["complete"] is False
    else:
        assert p.returncode == 1 and not out.exists()


@pytest.mark.slow
def test_max_units_bounds_the_diagnosis_too(tmp_path):
    """--max-units replaces the design's upper bound everywhere: the no-design reason is the
    one the file would get with `units 2` written, and a bound below the design's least units is
    a usage error, not an empty search."""
    text = "design f {\n    target far at (0.55, 0, 0.2) m\n    units 2 to 3\n    modules H1, L3\n}\n"
    p = _run(tmp_path, text, "-o", str(tmp_path / "out"), "--no-render", "-q", "--max-units", "2")
    assert p.returncode == 1, p.stderr
    assert "no design of 2 units" in p.stderr and "no design gets closer than" in p.stderr, p.stderr
    p = _run(tmp_path, text, "-o", str(tmp_path / "out"), "--no-render", "-q", "--max-units", "1")
    assert p.returncode == 2 and "--max-units 1 is below" in p.stderr, p.stderr


def test_plain_progress_repeats_itself_when_nothing_new_comes(monkeypatch, capsys):
    """A CI log never goes quiet: with no new status (a design being planned, a long block), the
    last line is said again, with the time spent on it."""
    import time

    from modc.cli import design_progress
    from modc.design.run import Status

    monkeypatch.setattr(design_progress, "PLAIN_EVERY", 0.05)
    with design_progress.progress("plain", "cell") as say:
        assert say is not None
        say(Status(1, 4, 10, 0, "", None), True)
        deadline = time.monotonic() + 30
        while "still at it" not in capsys.readouterr().err and time.monotonic() < deadline:
            time.sleep(0.05)
        say(Status(4, 4, 40, 1, "H1 - L3", None, "planning and timing design 1 of 2"), True)
    err = capsys.readouterr().err
    assert "planning and timing design 1 of 2 (H1 - L3)" in err


def test_plain_progress_says_a_new_status_as_it_is_not_as_still_at_it(monkeypatch, capsys):
    """Statuses that change faster than a line is printed (a search counting its settings): the
    next line gives the latest one as it is; "still at it" is for a status that did not change."""
    import time

    from modc.cli import design_progress
    from modc.design.run import Status

    monkeypatch.setattr(design_progress, "PLAIN_EVERY", 0.2)
    with design_progress.progress("plain", "cell") as say:
        assert say is not None
        say(Status(0, 4, 10, 0, "", None), True)
        say(Status(0, 4, 20, 0, "", None))  # within PLAIN_EVERY: not printed now
        deadline = time.monotonic() + 30
        err = ""
        while "20 settings" not in err and time.monotonic() < deadline:
            time.sleep(0.05)
            err += capsys.readouterr().err
    line = next(x for x in err.splitlines() if "20 settings" in x)
    assert "still at it" not in line
