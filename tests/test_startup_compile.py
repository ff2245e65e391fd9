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


@pytest.mark.parametrize("example", ["farm.mod", "example_b.mod", "table3_skew.mod"])
def test_the_box_filter_changes_no_collision_result_and_spares_exact_tests(example, monkeypatch):
    """A mesh's box holds it: boxes apart => meshes apart. The matrix is the sphere filter's alone;
    the farm arm's pairs reach coal no more (neither in the samples nor at the default pose)."""
    import numpy as np

    from modc.compiler import check_file
    from modc.physical import broadphase, collisions
    from modc.physical.assembly import describe

    monkeypatch.setenv("MODC_NO_CACHE", "1")
    for robot in check_file(ROOT / "examples" / example).design.resolved_robots():
        geo = collisions.geometry(describe(robot))
        boxed = collisions.compute(geo, samples=3000, seed=2)
        with monkeypatch.context() as m:  # spheres alone: every box is said to touch
            m.setattr(broadphase.Checker, "_boxes_apart", lambda self, R, p, n, ga, gb: np.zeros(len(n), bool))
            spheres = collisions.compute(geo, samples=3000, seed=2)
        assert boxed == spheres  # the classification (counts and stats do not compare)
        # a pair seen colliding is known to be free often enough only at the next sample that
        # reaches coal, so its counts may be taken a few samples later; Never pairs see them all
        assert {p: c for p, c in boxed.counts.items() if c[0] == 0} == {
            p: c for p, c in spheres.counts.items() if c[0] == 0}
        assert boxed.stats["exact_tests"] <= spheres.stats["exact_tests"]
        if example == "farm.mod":
            assert spheres.stats["exact_tests"] > 500 and boxed.stats["exact_tests"] == 0


def test_the_box_test_finds_touching_and_apart_boxes():
    """_boxes_apart on two unit boxes (no margin), the second turned about z: apart beyond the sum
    of their extents along the separating axis, touching within it."""
    import numpy as np

    from modc.physical.broadphase import Checker

    c = Checker.__new__(Checker)
    c.box_joint = np.array([1, 2])
    c.box_R = np.array([np.eye(3), np.eye(3)])
    c.box_c = np.zeros((2, 3))
    c.box_h = np.full((2, 3), 0.5)

    def apart(offset, angle) -> bool:
        rz = np.array([[np.cos(angle), -np.sin(angle), 0], [np.sin(angle), np.cos(angle), 0], [0, 0, 1]])
        R = np.array([[np.eye(3), np.eye(3), rz]])
        p = np.array([[np.zeros(3), np.zeros(3), np.asarray(offset, float)]])
        return bool(c._boxes_apart(R, p, np.array([0]), np.array([0]), np.array([1]))[0])

    assert apart((1.01, 0, 0), 0) and not apart((0.99, 0, 0), 0)
    assert apart((0, 0, 1.01), 0.3) and not apart((0, 0, 0.99), 0.3)
    d = 0.5 + 0.5 * np.sqrt(2)  # a box turned 45 deg reaches 0.707 along x
    assert apart((d + 0.01, 0, 0), np.pi / 4) and not apart((d - 0.01, 0, 0), np.pi / 4)
    assert not apart((0.7, 0.7, 0), 0)  # overlapping along both x and y


def test_unique_rows_merges_as_np_unique_did():
    """meshes.unique_rows (rows as bytes) keeps np.unique(axis=0)'s first occurrences and
    inverse up to the order of the unique rows, which every caller sets by first appearance;
    -0.0 and 0.0 are one value, as numbers."""
    import numpy as np

    from modc.physical.meshes import unique_rows

    rng = np.random.default_rng(1)
    for a in (rng.integers(-3, 3, size=(400, 3)), rng.integers(-2, 2, size=(300, 3)).astype(np.float32) * 0.5,
              np.array([[0.0, -0.0, 1.0], [-0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [1.0, 0.0, -0.0]], np.float32)):
        _, first0, inverse0 = np.unique(a, axis=0, return_index=True, return_inverse=True)
        first, inverse = unique_rows(a)
        order0, order = np.argsort(first0), np.argsort(first)
        assert np.array_equal(first0[order0], first[order])
        rank0, rank = np.empty_like(order0), np.empty_like(order)
        rank0[order0], rank[order] = np.arange(len(order0)), np.arange(len(order))
        assert np.array_equal(rank0[inverse0.reshape(-1)], rank[inverse])


def _example_robots():
    from conftest import EXAMPLES

    from modc.compiler import check_file

    return [r for f in EXAMPLES for r in check_file(f).design.resolved_robots()]


def test_the_numpy_gravity_derivatives_are_pinocchios():
    """Statics.gravity_with_jacobians equals pinocchio's g(q) and dg/dq (the reference) on every
    example arm, a tilted base and another payload included."""
    import numpy as np

    from modc.compiler import check_text
    from modc.dynamics.model import Dynamics, with_payload
    from modc.physical.assembly import describe
    from modc.physical.statics import Statics

    text = ("robot t {\n    chain H1 - L4(port=30deg) - L3\n    base at (0, 0, 0.1) m rpy (20, -35, 10) deg\n"
            "    payload 200 g at (0.01, 0.02, 0) m\n}\n")
    (tilted,) = check_text(text, "t.mod").design.resolved_robots()
    loads = []
    for robot in [*_example_robots(), tilted]:
        for payload in (None, (0.3, (0.0, 0.01, 0.02))):
            statics = Statics(robot, describe(with_payload(robot, payload)))
            dyn = Dynamics(robot, payload)
            assert np.array_equal(statics.lower, dyn.lower) and np.array_equal(statics.upper, dyn.upper)
            Q = np.random.default_rng(5).uniform(dyn.lower, dyn.upper, size=(40, robot.dof))
            G, J = statics.gravity_with_jacobians(Q)
            assert np.allclose(G, dyn.gravities(Q), rtol=0, atol=1e-11)
            assert np.allclose(J, dyn.gravity_with_jacobians(Q)[1], rtol=0, atol=1e-11)
            loads.append(np.abs(G).max())
    assert min(loads[-2:]) > 0.1 and sum(x > 0.1 for x in loads) > len(loads) // 2  # real loads (a planar arm has none)


def test_the_worst_case_on_the_numpy_statics_reports_what_pinocchio_does():
    """The compile's torque search (numpy statics) and the reference (pinocchio) give the same
    report on every example arm: same worst torques (to 1e-9 N·m) and poses (to 1e-9 rad)."""
    from modc.dynamics.worst import Dynamics, worst_case
    from modc.physical.statics import Statics

    for robot in _example_robots():
        fast, ref = worst_case(Statics(robot)), worst_case(Dynamics(robot))
        assert [j.to_json() for j in fast] == [j.to_json() for j in ref]
        for a, b in zip(fast, ref, strict=True):
            assert abs(a.tau - b.tau) < 1e-9 and max(abs(x - y) for x, y in zip(a.q, b.q, strict=True)) < 1e-9


def test_the_collision_matrix_needs_no_pinocchio_and_equals_the_naive_one(tmp_path):
    """collisions.geometry + compute run on numpy and coal alone (a fresh process imports no
    pinocchio; no coal either when the bounding boxes settle every pair, as on the farm arm), and
    classify every example arm's pairs as compute_naive (pinocchio) does."""
    import subprocess
    import sys

    code = ("import sys; from modc.compiler import check_file; from modc.physical.assembly import describe;"
            "from modc.physical.collisions import compute, geometry;"
            f"(r,) = check_file({str(FARM)!r}).design.resolved_robots();"
            "m = compute(geometry(describe(r)), samples=300);"
            "print('pinocchio' in sys.modules, 'coal' in sys.modules, len(m.disabled) > 0)")
    env = {"PYTHONPATH": str(ROOT), "MODC_CACHE_DIR": str(tmp_path), "PATH": "/usr/bin:/bin"}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["False", "False", "True"]

    from modc.physical import collisions
    from modc.physical.assembly import describe

    for robot in _example_robots():
        geo = collisions.geometry(describe(robot))
        assert collisions.compute(geo, samples=1200, seed=4) == collisions.compute_naive(geo, samples=1200, seed=4)


ARM_CACHES = {"builds", "collisions", "meshes", "torque"}  # keyed by the arm compiled (its design, parts, robot)


def test_the_benchmarks_install_caches_are_every_cache_a_compile_keys_by_modc_alone(tmp_path):
    """bench_startup's "first compile of a new arm" keeps INSTALL_CACHES warm and empties the rest:
    a compile writes exactly those kinds and the arm's, so a new cache kind must be placed in one."""
    import os
    import subprocess
    import sys

    sys.path.insert(0, str(ROOT / "benchmarks"))
    try:
        from bench_startup import INSTALL_CACHES
    finally:
        sys.path.remove(str(ROOT / "benchmarks"))
    env = dict(os.environ, PYTHONPATH=str(ROOT), MODC_CACHE_DIR=str(tmp_path / "cache"))
    env.pop("MODC_NO_CACHE", None)
    out = subprocess.run([sys.executable, "-m", "modc", str(FARM), "-o", str(tmp_path / "out")], env=env,
                         capture_output=True, text=True, cwd=tmp_path)
    assert out.returncode == 0, out.stderr
    kinds = {p.name for p in (tmp_path / "cache").iterdir()}
    assert kinds == set(INSTALL_CACHES) | ARM_CACHES and not set(INSTALL_CACHES) & ARM_CACHES


# --- the compile's command line without click -------------------------------------------------------

def test_the_plain_compile_command_line_means_what_click_reads_in_it():
    from modc.cli.compile import compile_cmd
    from modc.cli.compile_run import plain_args

    for args in (["a.mod", "-o", "out"], ["-o", "out", "a.mod", "-q"], ["a.mod", "--out=o", "--library", "lib.yaml"],
                 ["a.mod", "-o", "o", "--force", "--only", "urdf,srdf", "--torque=warning", "-v"],
                 ["a.mod", "-o", "o", "--no-force", "--ros-distro", "humble", "--ik-solver=kdl", "--smoke",
                  "--ros-package", "p", "--command-interface", "effort", "--package-license", "MIT",
                  "--maintainer", "A <a@b.c>", "--quiet", "--verbose"]):
        ours = plain_args(args)
        assert ours is not None, args
        theirs = compile_cmd.make_context("compile", list(args)).params
        assert {**theirs, **ours} == theirs, args  # the same values; the rest are click's defaults
        import inspect

        from modc.cli.compile_run import run

        defaults = {k: p.default for k, p in inspect.signature(run).parameters.items()
                    if p.default is not inspect.Parameter.empty}
        assert {**defaults, **ours} == theirs, args  # run()'s defaults are the command's
    for args in ([], ["a.mod"], ["-o", "o"], ["a.mod", "b.mod", "-o", "o"], ["a.mod", "-oo"], ["a.mod", "-o"],
                 ["a.mod", "-o", "o", "-o", "p"], ["a.mod", "-o", "-x"], ["a.mod", "-o", "o", "--seed", "1"],
                 ["a.mod", "-o", "o", "--torque", "loud"], ["a.mod", "-o", "o", "--force=1"],
                 ["a.mod", "-o", "o", "-h"], ["a.mod", "-o", "o", "--help"], ["a.mod", "-o", "o", "--"],
                 ["a.mod", "-o", "o", "--collision-samples=5"]):
        assert plain_args(args) is None, args


def test_a_plain_compile_imports_no_click_and_writes_what_click_s_command_writes(tmp_path):
    import json
    import os
    import subprocess
    import sys

    probe = ("import json, sys\nfrom modc.cli import main\ntry:\n    main(sys.argv[1:])\n"
             "except SystemExit as e:\n    code = e.code\nelse:\n    code = 'returned'\n"
             "sys.stderr.write(json.dumps({'exit': code, 'click': 'click' in sys.modules}))\n")
    env = dict(os.environ, MODC_CACHE_DIR=str(tmp_path / "cache"), PYTHONPATH=str(ROOT))
    env.pop("MODC_NO_CACHE", None)

    def run(*args):
        p = subprocess.run([sys.executable, "-c", probe, *map(str, args)], capture_output=True, text=True, env=env,
                           cwd=tmp_path)
        return json.loads(p.stderr.strip().splitlines()[-1]), p.stderr

    plain, err = run(FARM, "-o", tmp_path / "a", "-v")
    assert plain == {"exit": 0, "click": False}, err
    assert err.count("files written") == 1  # the compile ran once
    clicked, _ = run("compile", FARM, "-o", tmp_path / "b", "--seed", "0")  # a number: click reads it
    assert clicked == {"exit": 0, "click": True}
    a, b = sorted((tmp_path / "a").rglob("*")), sorted((tmp_path / "b").rglob("*"))
    assert [p.relative_to(tmp_path / "a") for p in a] == [p.relative_to(tmp_path / "b") for p in b]
    assert all(x.read_bytes() == y.read_bytes() for x, y in zip(a, b, strict=True) if x.is_file())
    (tmp_path / "d").mkdir()
    (tmp_path / "d" / "mine.txt").write_text("not modc's")
    refused, err = run(FARM, "-o", tmp_path / "d")  # OUT holds a file modc did not write: a usage error
    assert refused == {"exit": 2, "click": False} and "Traceback" not in err, err
    missing, err = run(tmp_path / "none.mod", "-o", tmp_path / "c")
    assert missing == {"exit": 2, "click": False} and "none.mod" in err and "Traceback" not in err


# --- the end of the command: no interpreter finalization ---------------------------------------------

def _python_m_modc(tmp_path, *args, cache=None):
    import os
    import subprocess
    import sys

    env = dict(os.environ, MODC_CACHE_DIR=str(cache or tmp_path / "cache"), PYTHONPATH=str(ROOT))
    env.pop("MODC_NO_CACHE", None)
    return subprocess.run([sys.executable, "-m", "modc", *map(str, args)], capture_output=True, text=True, env=env,
                          cwd=tmp_path)


def test_python_m_modc_ends_with_the_command_s_exit_code_its_whole_output_and_its_exit_handlers_run(tmp_path):
    import json

    lint = _python_m_modc(tmp_path, "lint", FARM, "--format", "json")  # an empty cache: the records' codes are new
    assert lint.returncode == 0 and json.loads(lint.stdout)["diagnostics"] == []  # stdout flushed, all of it
    assert list((tmp_path / "cache" / "records").glob("*.marshal"))  # written by the exit handler
    ok = _python_m_modc(tmp_path, FARM, "-o", tmp_path / "out")
    assert ok.returncode == 0 and "files written" in ok.stderr and (tmp_path / "out" / "report.json").is_file()
    bad = tmp_path / "bad.mod"
    bad.write_text("robot bad {\n    chain H1 - Q9\n}\n", encoding="utf-8")
    failed = _python_m_modc(tmp_path, bad, "-o", tmp_path / "out2")
    assert failed.returncode == 1 and "bad.mod:2" in failed.stderr and not (tmp_path / "out2").exists()
    assert _python_m_modc(tmp_path, "nonsense").returncode == 2
    assert _python_m_modc(tmp_path, "--version").stdout.startswith("modc ")


def test_a_thread_still_running_or_an_exit_message_ends_the_usual_way():
    import threading

    from modc.cli import _end

    _end("modc: a message")  # returns: Python prints it and exits 1
    stop = threading.Event()
    t = threading.Thread(target=stop.wait)
    t.start()
    try:
        _end(0)  # returns: Python joins the thread before it ends
    finally:
        stop.set()
        t.join()
