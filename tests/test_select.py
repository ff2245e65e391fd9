"""One way to pick a robot of a file by name (modc.model.select.choose_robot), one diagnostic
(robot-unknown, exit 2) from every command that takes a robot name, and from the Python API."""
from __future__ import annotations

import json

import pytest
from conftest import checked_ok
from test_diagnostics_corpus import run_cli

from modc.api import ModcError, load
from modc.model.select import RobotChoiceError, choose_robot

TWO = "robot a { chain H3 - L4 target t at (0.2, 0, 0.3) m }\nrobot b { chain H3 - L4 target t at (0.2, 0, 0.3) m }\n"


def test_choose_robot_rules():
    d = checked_ok(TWO, "two.mod").design
    assert choose_robot(d, "b").name == "b"
    assert choose_robot(d, None, [d.robots[0]]).name == "a"
    with pytest.raises(RobotChoiceError) as e:
        choose_robot(d, "nope")
    assert e.value.diagnostic.code == "robot-unknown"
    assert e.value.diagnostic.message == "two.mod has no robot 'nope'" and e.value.diagnostic.hint == "robots: a, b"
    with pytest.raises(RobotChoiceError) as e:
        choose_robot(d, None, say="--robot NAME")
    assert e.value.diagnostic.message == "two.mod defines 2 robots (a, b)"
    assert e.value.diagnostic.hint == "say which one with --robot NAME"
    with pytest.raises(RobotChoiceError) as e:
        choose_robot(checked_ok("# nothing\n", "empty.mod").design, None)
    assert e.value.diagnostic.message == "empty.mod defines no robot"


@pytest.mark.slow
def test_every_command_says_robot_unknown(tmp_path, capsys):
    two = tmp_path / "two.mod"
    two.write_text(TWO, encoding="utf-8")
    traj = tmp_path / "t.json"
    traj.write_text(
        json.dumps({"joint_names": ["joint_1", "joint_2"], "points": [{"t": 0, "q": [0, 0]}]}), encoding="utf-8"
    )
    named = tmp_path / "named.json"
    named.write_text(
        json.dumps({"joint_names": ["joint_1", "joint_2"], "robot": "zz", "points": [{"t": 0, "q": [0, 0]}]}),
        encoding="utf-8",
    )
    cases = [
        (["sim", str(two), "--robot", "nope"], "<command line>:1:1", "has no robot 'nope'"),
        (
            ["render", str(two), "--robot", "nope", "-o", str(tmp_path / "x.png")],
            "<command line>:1:1",
            "has no robot 'nope'",
        ),
        (["play", str(two), "--traj", str(traj), "--headless"], "<command line>:1:1", "defines 2 robots (a, b)"),
        (["plan", str(two), "--to", "t", "--robot", "nope"], "<command line>:1:1", "has no robot 'nope'"),
        (["plan", str(two), "--to", "t"], "<command line>:1:1", "robots a, b all have a target 't'"),
        (["check", str(two), "--traj", str(named)], f"{named}:1:1", "has no robot 'zz'"),
    ]
    for args, where, message in cases:
        rc, out, err = run_cli(capsys, *args)
        assert rc == 2, (args, err)
        assert f"{where}: error[robot-unknown]: " in err and message in err, (args, err)
        assert "= hint:" in err and "Traceback" not in err
    assert not (tmp_path / "x.png").exists()


def test_api_load(tmp_path):
    two = tmp_path / "two.mod"
    two.write_text(TWO, encoding="utf-8")
    assert load(two, "a").name == "a"
    for robot in (None, "nope"):
        with pytest.raises(ModcError) as e:
            load(two, robot)
        assert [d.code for d in e.value.diagnostics] == ["robot-unknown"]
