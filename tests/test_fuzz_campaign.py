"""A short seeded slice of the fuzz campaign (scripts/fuzz_campaign.py), as CI runs it: every
generator, fmt and full compiles; no tracebacks, hangs or files outside OUT; it resumes; and it
does report a crash and a hang when there is one."""
from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SCRIPT = ROOT / "scripts" / "fuzz_campaign.py"


def campaign(state: Path, *extra: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(SCRIPT), "--state", str(state), "--seed", "7", "--batch", "15",
                           "--inputs", "105", "--compiles", "3", *extra], capture_output=True, text=True, timeout=300)


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
