"""What each command imports, seen from a fresh process (sys.modules after the command ran).

Heavy libraries cost a cold start tenths of a second each: a command may import only what it
uses. A compile whose results are all cached (meshes, collision matrix, worst-case torques) needs
no dynamics or geometry library at all.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest
from conftest import ROOT

HEAVY = ("pinocchio", "coal", "pybullet", "ompl", "trimesh", "pygls", "scipy", "networkx", "mujoco", "dask")

_PROBE = """
import json, sys
from modc.cli import main
try:
    main(sys.argv[1:])
except SystemExit as e:
    code = e.code
else:
    code = 0
sys.stderr.write(json.dumps({"exit": code, "modules": sorted(sys.modules)}))
"""


def _run(args: list[str], cache_dir, no_cache: bool = False) -> tuple[int, set[str]]:
    env = dict(os.environ, MODC_CACHE_DIR=str(cache_dir))
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), *filter(None, [env.get("PYTHONPATH")])])
    env.pop("MODC_NO_CACHE", None)
    if no_cache:
        env["MODC_NO_CACHE"] = "1"
    p = subprocess.run([sys.executable, "-c", _PROBE, *args], capture_output=True, text=True, env=env, cwd=ROOT)
    doc = json.loads(p.stderr.strip().splitlines()[-1])
    return doc["exit"], set(doc["modules"])


@pytest.mark.slow
def test_lint_imports_no_heavy_library(tmp_path):
    code, modules = _run(["lint", str(ROOT / "examples" / "farm.mod")], tmp_path)
    assert code in (0, None)
    assert not modules & set(HEAVY), modules & set(HEAVY)
    assert "numpy" not in modules and "jinja2" not in modules  # lint checks text; it renders and computes nothing
    assert "typer" not in modules  # its pydantic-based parameter handling cost every command ~40 ms


@pytest.mark.slow
def test_compile_imports_no_trimesh_and_a_cached_compile_no_pinocchio(tmp_path):
    src = ROOT / "examples" / "farm.mod"
    code, first = _run([str(src), "-o", str(tmp_path / "a")], tmp_path / "cache")
    assert code in (0, None)
    # really computed (torque search, collision matrix), on numpy: the farm arm's boxes settle every
    # pair of the matrix, so neither pinocchio nor coal is imported (~0.1 s of a new arm's compile)
    assert {p.parent.name for p in (tmp_path / "cache").glob("*/*.json")} >= {"torque", "collisions"}
    assert not first & {"pinocchio", "coal"}
    assert not first & {"trimesh", "scipy", "networkx", "pybullet", "ompl", "pygls"}
    code, second = _run([str(src), "-o", str(tmp_path / "b")], tmp_path / "cache")
    assert code in (0, None)
    assert not second & set(HEAVY), second & set(HEAVY)
    assert "numpy" not in second and "jinja2" not in second  # served from modc's cache (build_cached)
    a, b = tmp_path / "a", tmp_path / "b"
    names = sorted(str(p.relative_to(a)) for p in a.rglob("*") if p.is_file())
    assert names == sorted(str(p.relative_to(b)) for p in b.rglob("*") if p.is_file())
    for rel in names:  # the cache hits give the very same outputs
        assert (a / rel).read_bytes() == (b / rel).read_bytes(), rel


def test_torque_cache_hit_equals_a_fresh_search(tmp_path, monkeypatch):
    from modc.compiler import check_file
    from modc.dynamics.model import with_payload
    from modc.dynamics.torque import analyse
    from modc.dynamics.worst import worst_case
    from modc.physical.assembly import describe
    from modc.physical.statics import Statics

    monkeypatch.setenv("MODC_CACHE_DIR", str(tmp_path))
    monkeypatch.delenv("MODC_NO_CACHE", raising=False)
    (robot,) = check_file(ROOT / "examples" / "farm.mod").design.robots
    fresh = worst_case(Statics(robot))
    assert analyse(robot) == fresh  # a miss computes and stores
    assert len(list((tmp_path / "torque").glob("*.json"))) == 1
    assert analyse(robot) == fresh  # a hit gives it back exactly
    heavier = analyse(robot, payload_mass=0.2)  # another payload is another key
    assert len(list((tmp_path / "torque").glob("*.json"))) == 2
    assert heavier == worst_case(Statics(robot, describe(with_payload(robot, (0.2, robot.payload.com)))))
    assert heavier[1].tau > fresh[1].tau  # joint 1 turns about the vertical: no gravity torque either way
