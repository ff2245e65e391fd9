"""A short seeded slice of the fuzz campaign (scripts/fuzz_campaign.py), as CI runs it: every
generator, fmt and full compiles; no tracebacks, hangs or files outside OUT; it resumes; and it
does report a crash and a hang when there is one.

A bigger campaign (all generators; hours):
    python scripts/fuzz_campaign.py --state /tmp/fuzz --seed 1 --inputs 20000 --compiles 500 --progress
only issue 21's generators (design blocks, library files, trajectories, ranking.json, CLI option
values, plan on random arms, the view server's websocket):
    python scripts/fuzz_campaign.py --state /tmp/fuzz21 --seed 1 --inputs 2000 --compiles 100 --progress \
        --kinds design,library,traj,ranking,cli,plan,ws
"""
from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
SCRIPT = ROOT / "scripts" / "fuzz_campaign.py"


ISSUE_10 = "grammar,valid,text,bytes,yaml,csv,hostile"
ISSUE_21 = "design,library,traj,ranking,cli,plan,ws"


def campaign(state: Path, *extra: str) -> subprocess.CompletedProcess:
    # the timeout guards against a hang only: the campaign's own limits are CPU time
    return subprocess.run([sys.executable, str(SCRIPT), "--state", str(state), "--seed", "7", "--batch", "15",
                           "--inputs", "105", "--compiles", "3", "--kinds", ISSUE_10, *extra], capture_output=True,
                          text=True, timeout=1800)


@pytest.mark.slow
def test_a_seeded_slice_finds_nothing_and_resumes(tmp_path):
    first = campaign(tmp_path / "s", "--stop-after", "3")
    assert first.returncode == 0, first.stderr[-3000:]
    assert json.loads(first.stdout)["batch"] == 3
    rest = campaign(tmp_path / "s")
    assert rest.returncode == 0, rest.stderr[-3000:]
    state = json.loads(rest.stdout)
    assert state["inputs"] == 105 and state["batch"] == 7 and state["findings"] == 0
    assert set(state["by_kind"].values()) == {15} and state["compiles"] == 3
    assert not (tmp_path / "s" / "findings.jsonl").exists()


@pytest.mark.slow
def test_a_seeded_slice_of_the_new_generators_finds_nothing(tmp_path):
    """Two inputs of each of issue 21's generators (one `modc view` server, CLI subprocesses)."""
    r = subprocess.run([sys.executable, str(SCRIPT), "--state", str(tmp_path), "--seed", "7", "--batch", "2",
                        "--inputs", "14", "--compiles", "1", "--kinds", ISSUE_21], capture_output=True, text=True,
                       timeout=1800)
    findings = tmp_path / "findings.jsonl"
    if findings.exists():
        found = [json.loads(line) for line in findings.read_text().splitlines()]
        pytest.fail("\n".join(f"{f['kind']}: {f['type']}: {f['detail']}" for f in found))
    assert r.returncode == 0, r.stderr[-3000:]
    state = json.loads(r.stdout)
    assert state["by_kind"] == {k: 2 for k in ISSUE_21.split(",")} and state["findings"] == 0


def _module():
    spec = importlib.util.spec_from_file_location("fuzz_campaign", SCRIPT)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _findings(mod, state: Path, monkeypatch, planted, *limits: str) -> list[dict]:
    import modc.compiler

    monkeypatch.setattr(modc.compiler, "check_text", planted)
    monkeypatch.setattr(mod, "KINDS", ("yaml",))
    n = str(planted.n)
    rc = mod.main(["--state", str(state), "--batch", n, "--inputs", n, "--compiles", "0", "--memory", "0", *limits])
    assert rc == 1
    return [json.loads(line) for line in (state / "findings.jsonl").read_text().splitlines()]


@pytest.mark.slow
def test_crashes_and_cpu_hangs_are_recorded(tmp_path, monkeypatch):
    """A spinning input is a hang by its CPU time; the wall-clock limit is far away, so that a
    loaded machine (which stretches 0.3 s of CPU time over seconds) cannot make it the reason."""
    calls = {"n": 0}

    def broken(text, path="<string>", *a, **kw):
        calls["n"] += 1
        if calls["n"] == 1:
            raise ZeroDivisionError("planted")
        while True:  # spins: CPU time
            pass

    broken.n = 2
    found = _findings(_module(), tmp_path, monkeypatch, broken, "--timeout", "0.3", "--wall", "600")
    assert [(f["type"], f["detail"]) for f in found[1:]] == [("hang", "over 0.3 s of CPU time")]
    assert found[0]["type"] == "traceback"
    assert found[0]["detail"].startswith("ZeroDivisionError") and "planted" in found[0]["traceback"]


def test_a_blocked_input_is_a_wall_clock_hang(tmp_path, monkeypatch):
    """An input that blocks (a FIFO, a lock) uses no CPU time: the wall-clock limit catches it."""
    def blocks(text, path="<string>", *a, **kw):
        time.sleep(600)  # uses no CPU time, so the CPU limit can never fire first

    blocks.n = 1
    found = _findings(_module(), tmp_path, monkeypatch, blocks, "--timeout", "0.3", "--wall", "1")
    assert [(f["type"], f["detail"]) for f in found] == [("hang", "over 1.0 s of wall-clock time")]


def test_a_traceback_in_a_cli_subprocess_is_recorded(tmp_path, monkeypatch):
    mod = _module()
    monkeypatch.setattr(mod.fuzz_surfaces, "GUARDED_MAIN", "raise ZeroDivisionError('planted')")
    rc = mod.main(["--state", str(tmp_path), "--batch", "1", "--inputs", "1", "--compiles", "0", "--memory", "0",
                   "--kinds", "cli"])
    assert rc == 1
    [found] = [json.loads(line) for line in (tmp_path / "findings.jsonl").read_text().splitlines()]
    assert found["type"] == "traceback" and "ZeroDivisionError: planted" in found["detail"], found


def test_a_process_pool_over_the_cap_is_a_finding_not_a_fork(tmp_path):
    """The guard the CLI generator runs modc under: a pool of more than WORKERS_CAP processes ends
    the process before it forks any."""
    mod = _module()
    code = mod.fuzz_surfaces.GUARDED_MAIN.replace(
        "from modc.cli import main", "from concurrent.futures import ProcessPoolExecutor; ProcessPoolExecutor(10**6)")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    assert r.returncode == mod.fuzz_surfaces.UNCAPPED_EXIT and "1000000 workers" in r.stderr


def test_a_non_finite_number_in_an_output_is_a_finding(monkeypatch):
    """A library with a huge peak torque once wrote kp="inf" into the MJCF: the campaign scans every
    compiled URDF, MJCF, SRDF and YAML file for inf and nan."""
    import modc.compiler

    mod = _module()
    real = modc.compiler.build

    def build(*a, **kw):
        files = real(*a, **kw)
        return {**files, "mjcf/arm.xml": '<mujoco><position kp="inf"/></mujoco>\n'}

    text = (ROOT / "examples" / "quickstart.mod").read_text(encoding="utf-8")
    assert mod.compile_one(text, 0) is None
    monkeypatch.setattr(modc.compiler, "build", build)
    found = mod.compile_one(text, 0)
    assert found["type"] == "nonfinite" and "'inf' in arm.xml" in found["detail"] and 'kp="inf"' in found["line"]
