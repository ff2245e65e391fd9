"""Issue 25 item 3, the first compile of a new arm: what it does once and not twice, and what it
leaves out, with the same results (benchmarks/bench_startup.py measures the time)."""
from __future__ import annotations

import warnings

import pytest
from conftest import ROOT

FARM = ROOT / "examples" / "farm.mod"
MARK2 = ROOT / "libraries" / "mark2.yaml"


def _modc(capsys, *args) -> tuple[int, str]:
    from modc.cli import main

    with pytest.raises(SystemExit) as e, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        main([str(a) for a in args])
    return int(e.value.code or 0), capsys.readouterr().err


@pytest.fixture
def cache_dir(tmp_path, monkeypatch):
    monkeypatch.setenv("MODC_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.delenv("MODC_NO_CACHE", raising=False)
    return tmp_path / "cache"


def test_a_compile_parses_and_checks_its_file_once(cache_dir, tmp_path, capsys, monkeypatch):
    import modc.compiler as compiler

    calls = []
    real = compiler.parse_text
    monkeypatch.setattr(compiler, "parse_text", lambda text, path: calls.append(path) or real(text, path))
    rc, err = _modc(capsys, FARM, "-o", tmp_path / "out")
    assert rc == 0, err
    assert calls == [str(FARM)]  # inputs_of, then check_file, parsed and checked it twice


def test_check_compile_gives_check_files_result_and_inputs_ofs_inputs(cache_dir, tmp_path):
    from modc.compiler import COMPILE_ANALYSES, check_compile, check_file, inputs_of

    lib = tmp_path / "lib"
    lib.mkdir()
    (lib / "mine.yaml").write_bytes(MARK2.read_bytes())
    src = tmp_path / "arm.mod"
    src.write_text('robot arm {\n    library "lib/mine.yaml"\n    chain H1 - L4 - L3\n}\n', encoding="utf-8")
    for file in (src, FARM):
        checked, inputs = check_compile(file, analyses=COMPILE_ANALYSES, torque_severity="error")
        alone = check_file(file, analyses=COMPILE_ANALYSES, torque_severity="error")
        assert checked.diagnostics == alone.diagnostics and checked.sources == alone.sources
        assert checked.design == alone.design and [r.torque for r in checked.design.robots] == [
            r.torque for r in alone.design.robots]
        assert inputs == inputs_of(file)
    assert check_compile(src)[1] == [str(src), str(lib / "mine.yaml")]


def test_the_library_a_robot_uses_is_protected_before_the_torque_search_caches(tmp_path, capsys, monkeypatch):
    """A cache directory holding the robot's library file (not the .mod) gets no torque entry:
    the library is declared an input once the checks found it, before the analyses run."""
    lib = tmp_path / "lib"
    lib.mkdir()
    (lib / "mine.yaml").write_bytes(MARK2.read_bytes())
    src = tmp_path / "src" / "arm.mod"
    src.parent.mkdir()
    src.write_text(f'robot arm {{\n    library "{lib / "mine.yaml"}"\n    chain H1 - L4 - L3\n}}\n', encoding="utf-8")
    monkeypatch.setenv("MODC_CACHE_DIR", str(lib))
    monkeypatch.delenv("MODC_NO_CACHE", raising=False)
    rc, err = _modc(capsys, src, "-o", tmp_path / "out")
    assert rc == 0, err
    assert f"not caching in {lib}: it is or holds the input" in err
    assert not (lib / "torque").exists() and not (lib / "builds").exists()


def test_an_unreadable_file_is_still_a_diagnostic(cache_dir, tmp_path, capsys):
    rc, err = _modc(capsys, tmp_path / "missing.mod", "-o", tmp_path / "out")
    assert rc != 0 and "missing.mod" in err and "Traceback" not in err
    assert not (tmp_path / "out").exists()


def test_the_collision_matrix_imports_no_numpy_ma(tmp_path):
    """np.unique imports numpy.ma (~15 ms of a new arm's first compile); the matrix uses none."""
    import subprocess
    import sys

    code = ("import sys; from modc.compiler import check_file; from modc.physical.assembly import describe;"
            "from modc.physical.collisions import compute, geometry;"
            f"(r,) = check_file({str(FARM)!r}).design.resolved_robots();"
            "compute(geometry(describe(r)), samples=200);"
            "print('numpy.ma' in sys.modules)")
    env = {"PYTHONPATH": str(ROOT), "MODC_CACHE_DIR": str(tmp_path), "PATH": "/usr/bin:/bin"}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "False"
