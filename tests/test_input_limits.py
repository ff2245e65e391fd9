"""Every input is read under the limits of .mod files (issue 21, items 7-9): trajectory files
(`check --traj`, `play --traj`, `view --traj`) and ranking.json (`modc view DIR/ranking.json`)
are regular files of bounded size, UTF-8 and not nested deeply; command-line numbers are checked
before they reach arithmetic. Bad input is a diagnostic or one usage line, never a traceback, a
hang or an exhausted memory."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import ROOT

from modc import trajectory
from modc.files import MAX_JSON_BYTES, MAX_JSON_DEPTH, InputProblem, read_json

QUICKSTART = ROOT / "examples" / "quickstart.mod"
GOOD = {"joint_names": ["joint_1", "joint_2", "joint_3"], "points": [{"t": 0.0, "q": [0.0, 0.0, 0.0]}]}


def _modc(*args: str, cwd: Path, timeout: float = 120) -> subprocess.CompletedProcess:
    # a timeout only so that a regression (a FIFO read blocking) fails instead of hanging the suite
    return subprocess.run([sys.executable, "-m", "modc", *args], capture_output=True, text=True, cwd=cwd,
                          timeout=timeout, stdin=subprocess.DEVNULL)


def _unreadable(tmp_path: Path, kind: str) -> Path:
    """A path that is not a regular file: a FIFO (reading it blocked forever), a link to
    /dev/zero (reading it filled the memory) or a directory."""
    path = tmp_path / f"{kind}.json"
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "zero":
        path.symlink_to("/dev/zero")
    else:
        path.mkdir()
    return path


CONTENT = {
    "deep": "[" * 100_000 + "]" * 100_000,  # Python's json recursed until RecursionError
    "not-utf8": b'{"joint_names": ["joint_\xff"]}',
    "huge-integer": '{"joint_names": ["joint_1"], "points": [{"t": ' + "9" * 5000 + ', "q": [0]}]}',
    "not-json": '{"joint_names": [}',
}


def _bad_content(tmp_path: Path, kind: str) -> Path:
    path = tmp_path / f"{kind}.json"
    data = CONTENT[kind]
    path.write_bytes(data if isinstance(data, bytes) else data.encode())
    return path


# --- the reader ------------------------------------------------------------------------------------

@pytest.mark.parametrize("kind", ["fifo", "zero", "directory"])
def test_only_regular_files_are_read(tmp_path, kind):
    with pytest.raises(OSError):
        read_json(_unreadable(tmp_path, kind))


@pytest.mark.parametrize("kind, where", [("deep", (1, MAX_JSON_DEPTH + 1)), ("not-utf8", (1, 25)),
                                         ("huge-integer", (1, 1)), ("not-json", (1, 18))])
def test_bad_content_is_a_located_problem(tmp_path, kind, where):
    with pytest.raises(InputProblem) as e:
        read_json(_bad_content(tmp_path, kind))
    assert (e.value.line, e.value.col) == where
    assert "\ufffd" not in str(e.value) and "joint_" not in str(e.value)  # no content quoted


def test_a_file_over_the_size_limit_is_refused_before_it_is_parsed(tmp_path):
    path = tmp_path / "big.json"
    with open(path, "wb") as f:
        f.truncate(MAX_JSON_BYTES + 1)  # sparse: no disk used
    with pytest.raises(InputProblem, match="too large"):
        read_json(path)


def test_a_good_trajectory_still_loads(tmp_path):
    path = tmp_path / "t.json"
    path.write_text(json.dumps(GOOD))
    traj, errors = trajectory.load(path)
    assert errors == [] and traj is not None and traj.joint_names == ("joint_1", "joint_2", "joint_3")


# --- through the commands ---------------------------------------------------------------------------

@pytest.mark.parametrize("kind", ["fifo", "zero", "directory"])
def test_check_traj_refuses_what_is_not_a_regular_file(tmp_path, kind):
    path = _unreadable(tmp_path, kind)
    r = _modc("check", str(QUICKSTART), "--traj", str(path), cwd=tmp_path)
    assert r.returncode == 2, r.stderr
    assert "Traceback" not in r.stderr and f"{path}:1:1: error[file-not-found]" in r.stderr


@pytest.mark.parametrize("kind", sorted(CONTENT))
def test_check_traj_reports_bad_content_at_its_place(tmp_path, kind):
    path = _bad_content(tmp_path, kind)
    r = _modc("check", str(QUICKSTART), "--traj", str(path), cwd=tmp_path)
    assert r.returncode == 1, r.stderr
    assert "Traceback" not in r.stderr and "error[traj-invalid]" in r.stderr
    with pytest.raises(InputProblem) as e:
        read_json(path)
    assert f"{path}:{e.value.line}:{e.value.col}: error[traj-invalid]" in r.stderr


@pytest.mark.parametrize("kind", ["fifo", "deep", "not-utf8"])
def test_play_traj_is_read_under_the_limits(tmp_path, kind):
    path = _unreadable(tmp_path, kind) if kind == "fifo" else _bad_content(tmp_path, kind)
    r = _modc("play", str(QUICKSTART), "--traj", str(path), "--headless", cwd=tmp_path)
    assert r.returncode in (1, 2) and "Traceback" not in r.stderr, r.stderr
    assert str(path) in r.stderr


@pytest.mark.parametrize("kind", ["fifo", "zero", "directory", "deep", "not-utf8", "huge-integer"])
def test_view_ranking_is_read_under_the_limits(tmp_path, kind):
    """`modc view DIR/ranking.json` with a ranking that is not a regular file or not JSON it can
    take: exit 2 with one line, before any server starts."""
    (tmp_path / "d").mkdir()
    made = _unreadable(tmp_path / "d", kind) if kind in ("fifo", "zero", "directory") else \
        _bad_content(tmp_path / "d", kind)
    ranking = made.rename(tmp_path / "d" / "ranking.json")
    r = _modc("view", str(ranking), "--no-browser", cwd=tmp_path)
    assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr
    assert r.stderr.startswith(f"modc view: cannot read {ranking}") or r.stderr.startswith(f"modc view: {ranking}: ")


@pytest.mark.parametrize("kind", ["fifo", "deep"])
def test_view_traj_is_read_under_the_limits(tmp_path, kind):
    path = _unreadable(tmp_path, kind) if kind == "fifo" else _bad_content(tmp_path, kind)
    r = _modc("view", str(QUICKSTART), "--traj", str(path), "--no-browser", cwd=tmp_path)
    assert r.returncode == 2 and "Traceback" not in r.stderr and str(path) in r.stderr, r.stderr


# --- command-line numbers and schemes ---------------------------------------------------------------

NO_DESIGN = "robot r {\n    chain H1 - L1\n}\n"  # `modc design` stops at once: no search runs


def test_design_workers_are_capped_at_the_cpu_count(tmp_path):
    (tmp_path / "a.mod").write_text(NO_DESIGN)
    cpus = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    r = _modc("design", "a.mod", "-o", "out", "--workers", "100000", cwd=tmp_path)
    assert f"--workers 100000 capped at {cpus}" in r.stderr and "Traceback" not in r.stderr
    r = _modc("design", "a.mod", "-o", "out", "--workers", "1", cwd=tmp_path)
    assert "capped" not in r.stderr


@pytest.mark.parametrize("scheduler", ["tls://127.0.0.1:8786", "ucx://127.0.0.1:8786", "ws://x:1",
                                       "tl\x1bs://x"])
def test_design_scheduler_schemes_modc_cannot_use_are_refused(tmp_path, scheduler):
    """tls:// needs certificates and ucx:// a package modc does not ship: both gave tracebacks
    from inside `distributed`."""
    (tmp_path / "a.mod").write_text(NO_DESIGN)
    r = _modc("design", "a.mod", "-o", "out", "--scheduler", scheduler, cwd=tmp_path)
    assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr
    assert "is not supported; give tcp://HOST:PORT" in r.stderr and "\x1b" not in r.stderr


def test_design_tcp_scheduler_is_accepted(tmp_path):
    (tmp_path / "a.mod").write_text(NO_DESIGN)
    r = _modc("design", "a.mod", "-o", "out", "--scheduler", "tcp://127.0.0.1:1", cwd=tmp_path)
    assert "not supported" not in r.stderr and "has no `design NAME" in r.stderr


@pytest.mark.parametrize("option", [("--elevation", "inf"), ("--elevation", "nan"), ("--elevation", "1e308"),
                                    ("--azimuth", "-inf"), ("--azimuth", "nan"),
                                    ("--size", "100000x100000"), ("--size", "99999999999999999999x1")])
def test_render_options_are_checked_before_rendering(tmp_path, option):
    r = _modc("render", str(QUICKSTART), "-o", "p.png", *option, cwd=tmp_path)
    assert r.returncode == 2 and "Traceback" not in r.stderr and "bad_alloc" not in r.stderr, r.stderr
    assert option[0] in r.stderr and not (tmp_path / "p.png").exists()


@pytest.mark.parametrize("digits", [17, 400])
def test_wide_integers_never_reach_float_arithmetic(tmp_path, digits):
    """Found by the fuzz campaign: a 400-digit integer in ranking.json or a trajectory overflowed
    (OverflowError) where the page formatted a mass or the trajectory checked a number. Integers
    wider than a float are refused by the reader; wide ones that fit read as floats."""
    from modc.view.page import Ranking, ViewError

    wide = "1" * digits
    ranking = tmp_path / "ranking.json"
    ranking.write_text('{"designs": [{"rank": 1, "file": "a.mod", "mass_kg": ' + wide + "}]}")
    traj = tmp_path / "t.json"
    traj.write_text('{"joint_names": ["joint_1"], "points": [{"t": 0, "q": [' + wide + "]}]}")
    if digits > 308:
        with pytest.raises(ViewError, match="too many digits"):
            Ranking(ranking)
        with pytest.raises(InputProblem):
            read_json(traj)
        _, errors = trajectory.load(traj)
        assert errors and "too many digits" in " ".join(errors)  # a message, not a traceback
    else:
        assert Ranking(ranking).caption(0).startswith("design 1 of 1: rank 1")
        assert isinstance(read_json(traj)["points"][0]["q"][0], float)
        trajectory.load(traj)  # reads; the joint limits are checked against a robot later


def test_collision_samples_are_bounded(tmp_path):
    """Found by the fuzz campaign: --collision-samples 6402373705728000 asked numpy for 136 PiB."""
    r = _modc(str(QUICKSTART), "-o", str(tmp_path / "out"), "--collision-samples", "6402373705728000",
              cwd=tmp_path)
    assert r.returncode == 2 and "Traceback" not in r.stderr and "1000000" in r.stderr.replace(",", "")
    assert not (tmp_path / "out").exists()
