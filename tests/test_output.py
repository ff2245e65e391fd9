"""Output discipline: atomic replacement, nothing written on failure, byte-identical reruns."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from conftest import ROOT

QUICK = ROOT / "examples" / "quickstart.mod"


def modc(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "modc", *args], capture_output=True, text=True, cwd=cwd)


def tree(root: Path) -> dict[str, bytes]:
    return {str(p.relative_to(root)): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


def test_compile_writes_the_normative_layout(tmp_path):
    r = modc(str(QUICK), "-o", str(tmp_path / "out"))
    assert r.returncode == 0, r.stderr
    files = tree(tmp_path / "out")
    assert "urdf/mod3_farm.urdf" in files
    assert "report.json" in files
    assert any(f.startswith("meshes/") and f.endswith(".stl") for f in files)
    # every mesh the URDF names exists, relative to the URDF
    urdf = files["urdf/mod3_farm.urdf"].decode()
    import re

    for mesh in set(re.findall(r'filename="([^"]+)"', urdf)):
        assert (tmp_path / "out" / "urdf" / mesh).resolve().is_file(), mesh


def test_two_compiles_are_byte_identical(tmp_path):
    for name in ("a", "b"):
        assert modc(str(QUICK), "-o", str(tmp_path / name)).returncode == 0
    assert tree(tmp_path / "a") == tree(tmp_path / "b")


def test_failed_compile_leaves_out_untouched(tmp_path):
    out = tmp_path / "out"
    assert modc(str(QUICK), "-o", str(out)).returncode == 0
    before = tree(out)
    bad = tmp_path / "bad.mod"
    bad.write_text("robot farm {\n    chain H1 - L4(port=40deg) - L1\n}\n")
    r = modc(str(bad), "-o", str(out))
    assert r.returncode == 1
    assert "twist-not-realisable" in r.stderr and "nothing written" in r.stderr
    assert tree(out) == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.mod", "out"], "no temporary directories left behind"


def test_failed_compile_creates_no_out(tmp_path):
    bad = tmp_path / "bad.mod"
    bad.write_text("robot farm { chain H1 - L1 pose home (0) deg }\n")
    assert modc(str(bad), "-o", str(tmp_path / "out")).returncode == 1
    assert not (tmp_path / "out").exists()


def test_recompile_replaces_stale_files(tmp_path):
    out = tmp_path / "out"
    two = tmp_path / "two.mod"
    two.write_text("robot a { chain H1 - L1 }\nrobot b { chain H3 - L4 }\n")
    assert modc(str(two), "-o", str(out)).returncode == 0
    assert {"urdf/mod2_a.urdf", "urdf/mod2_b.urdf"} <= set(tree(out))
    assert modc(str(QUICK), "-o", str(out)).returncode == 0
    assert "urdf/mod2_a.urdf" not in tree(out), "files of the previous compile must not linger"


def test_refuses_to_replace_a_foreign_directory(tmp_path):
    out = tmp_path / "precious"
    out.mkdir()
    (out / "thesis.tex").write_text("do not delete")
    r = modc(str(QUICK), "-o", str(out))
    assert r.returncode == 2
    assert "output-not-modc" in r.stderr and "--force" in r.stderr
    assert (out / "thesis.tex").read_text() == "do not delete"


def test_exit_codes_and_no_traceback(tmp_path):
    assert modc("lint", str(QUICK)).returncode == 0
    r = modc("lint", str(tmp_path / "missing.mod"))
    assert r.returncode == 2 and "file-not-found" in r.stderr
    bad = tmp_path / "bad.mod"
    bad.write_text("robot r {\n  chain H1 H4 - L1\n}\n")
    r = modc("lint", str(bad))
    assert r.returncode == 1
    assert f"{bad}:2:12: error[missing-dash]" in r.stderr
    assert "chain H1 H4 - L1" in r.stderr and "^^" in r.stderr
    r = modc("frobnicate", "--nope")
    assert r.returncode == 2
    for out in (r.stdout, r.stderr):
        assert "Traceback" not in out


def test_several_robots_give_several_urdfs(tmp_path):
    src = tmp_path / "two.mod"
    src.write_text("robot left { chain H1 - L1 }\nrobot right { chain H1 - H4(pivot=-90deg) - L4 }\n")
    assert modc(str(src), "-o", str(tmp_path / "out")).returncode == 0
    urdfs = sorted(p.name for p in (tmp_path / "out" / "urdf").glob("*.urdf") if not p.name.endswith("_ros.urdf"))
    assert urdfs == ["mod2_left.urdf", "mod3_right.urdf"]  # (and *_ros.urdf: the same robots for ROS tools)


def test_only_selects_backends(tmp_path):
    assert modc(str(QUICK), "-o", str(tmp_path / "out"), "--only", "urdf").returncode == 0
    files = tree(tmp_path / "out")
    assert "urdf/mod3_farm.urdf" in files and not any(f.startswith("meshes/") for f in files)
    r = modc(str(QUICK), "-o", str(tmp_path / "o2"), "--only", "nope")
    assert r.returncode == 2 and "unknown backend" in r.stderr
