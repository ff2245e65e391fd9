"""Issue 21 items 1-3 and 12: one output rule for every command that writes. No input (source,
library, trajectory) is ever replaced or deleted, --force or not, through a link or a `..` path;
no folder holding one; leftovers are known by modc's marker; fmt never loses a concurrent save.
Every test runs the real command line on tmp_path and checks the inputs byte for byte after."""
from __future__ import annotations

import json
import os
import warnings
from pathlib import Path

import pytest
from conftest import ROOT

QUICK = ROOT / "examples" / "quickstart.mod"
SPATIAL = ROOT / "examples" / "table3_spatial.mod"
MARK2 = ROOT / "libraries" / "mark2.yaml"
SMALL = """\
design small {
    payload 100 g
    target a at (0.30, 0.10, 0.25) m
    units 3
    modules H1, L3
}
"""
SWEEP = {"joint_names": ["joint_1", "joint_2", "joint_3"],
         "points": [{"t": 0.0, "q": [0.0, 0.0, 0.0]}, {"t": 0.3, "q": [0.5, -0.3, 0.4]}]}


def modc(capsys, *args: str | os.PathLike) -> tuple[int, str]:
    """`modc ARGS` in-process: (exit code, stderr)."""
    from modc.cli import main

    with pytest.raises(SystemExit) as e, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        main([str(a) for a in args])
    _, err = capsys.readouterr()
    assert "Traceback" not in err
    return int(e.value.code or 0), err


def snapshot(*paths: Path) -> dict[Path, bytes]:
    return {p: p.read_bytes() for p in paths}


def unchanged(before: dict[Path, bytes]) -> bool:
    return all(p.is_file() and not p.is_symlink() and p.read_bytes() == b for p, b in before.items())


@pytest.fixture
def project(tmp_path, monkeypatch):
    """A user's folder: a robot, a design problem, a library and a notes file; cwd elsewhere."""
    src = tmp_path / "proj"
    src.mkdir()
    (src / "arm.mod").write_bytes(QUICK.read_bytes())
    (src / "cell.mod").write_text(SMALL, encoding="utf-8")
    (src / "notes.txt").write_text("precious\n", encoding="utf-8")
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    monkeypatch.setenv("MODC_CACHE_DIR", str(tmp_path / "cache"))
    return src


def no_search(monkeypatch):
    """modc design must refuse its DIR before it searches (issue 21 item 4)."""
    from modc.design import run

    def refuse(*a, **k):
        raise AssertionError("searched before checking the output directory")

    monkeypatch.setattr(run, "design", refuse)


# --- item 1: design, compile -------------------------------------------------------------------


@pytest.mark.parametrize("how", ["plain", "dotdot", "link"])
def test_design_into_the_inputs_folder_with_force_deletes_nothing(project, capsys, monkeypatch, how):
    before = snapshot(*project.iterdir())
    out = {"plain": project, "dotdot": project / "nowhere" / "..", "link": Path("link")}[how]
    if how == "link":
        Path("link").symlink_to(project)
    no_search(monkeypatch)
    rc, err = modc(capsys, "design", project / "cell.mod", "-o", out, "--force", "--no-render")
    assert rc == 2 and "error[output-unsafe]" in err and "holding the input" in err, err
    assert unchanged(before) and sorted(project.iterdir()) == sorted(before)


def test_a_library_inside_out_is_never_deleted(project, capsys, monkeypatch):
    out = project / "build"
    out.mkdir()
    lib = out / "mylib.yaml"
    lib.write_bytes(MARK2.read_bytes())
    (project / "arm.mod").write_text('robot arm {\n    library "build/mylib.yaml"\n    chain H1 - L1\n}\n')
    (project / "cell.mod").write_text(SMALL.replace("payload", 'library "build/mylib.yaml"\n    payload'))
    before = snapshot(lib, project / "arm.mod", project / "cell.mod")
    rc, err = modc(capsys, "compile", project / "arm.mod", "-o", out, "--force")
    assert rc == 2 and "error[output-unsafe]" in err and "mylib.yaml" in err, err
    no_search(monkeypatch)
    rc, err = modc(capsys, "design", project / "cell.mod", "-o", out, "--force", "--no-render")
    assert rc == 2 and "error[output-unsafe]" in err and "mylib.yaml" in err, err
    # --library names it on the command line: the same
    rc, err = modc(capsys, "compile", QUICK, "--library", lib, "-o", out, "--force")
    assert rc == 2 and "error[output-unsafe]" in err, err
    assert unchanged(before) and sorted(p.name for p in out.iterdir()) == ["mylib.yaml"]


def test_compile_onto_the_input_file_or_a_link_to_it(project, capsys):
    arm = project / "arm.mod"
    before = snapshot(*project.iterdir())
    Path("alias.mod").symlink_to(arm)
    for out in (arm, Path("alias.mod"), project / "x" / ".." / "arm.mod"):
        for force in ((), ("--force",)):
            rc, err = modc(capsys, arm, "-o", out, *force)
            assert rc == 2 and "error[output-unsafe]" in err and "the input" in err, (out, err)
    assert unchanged(before)


def test_a_plain_file_as_out_gets_one_message_with_or_without_force(project, capsys):
    """Item 12: the hint never sends the user to --force when --force cannot help."""
    plain = project / "arm.urdf"
    plain.write_text("<robot name='mine'/>\n")
    before = snapshot(*project.iterdir())
    rc1, err1 = modc(capsys, project / "arm.mod", "-o", plain)
    rc2, err2 = modc(capsys, project / "arm.mod", "-o", plain, "--force")
    assert rc1 == rc2 == 2 and err1 == err2, (err1, err2)
    assert "error[output-unsafe]" in err1 and "not a directory" in err1 and "--force" not in err1
    assert "hint:" in err1 and "-o build/out" in err1
    assert unchanged(before)


def test_check_output_dir_is_the_writes_own_check(project, tmp_path):
    """The call a command makes before its work raises exactly what the write would."""
    from modc.compiler import InputError, inputs_of
    from modc.outputs import check_output_dir, write_tree

    inputs = inputs_of(project / "arm.mod")
    foreign = tmp_path / "foreign"
    foreign.mkdir()
    (foreign / "thesis.tex").write_text("x")
    for out, force in ((project, True), (foreign, False), (project / "notes.txt", True)):
        with pytest.raises(InputError) as early:
            check_output_dir(out, inputs, force)
        with pytest.raises(InputError) as late:
            write_tree({"a.txt": "1"}, out, force, inputs)
        assert early.value.diagnostic == late.value.diagnostic
    check_output_dir(tmp_path / "new", inputs, False)  # fine: nothing there yet
    assert not (tmp_path / "new").exists()


# --- item 1: render, play --record ---------------------------------------------------------------


def test_render_never_replaces_its_source(project, capsys):
    arm = project / "arm.mod"
    before = snapshot(*project.iterdir())
    Path("arm.png").symlink_to(arm)
    os.link(arm, "hard.png")  # a second name of the same file: PIL would write through it
    for out in (arm, Path("arm.png"), Path("hard.png"), project / "nowhere" / ".." / "arm.mod", project):
        rc, err = modc(capsys, "render", arm, "-o", out)
        assert rc == 2 and "error[output-unsafe]" in err and "-o arm.png" in err, (out, err)
    assert unchanged(before)


def test_play_never_records_onto_its_trajectory_or_source(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    src = tmp_path / "spatial.mod"
    src.write_bytes(SPATIAL.read_bytes())
    traj = tmp_path / "traj.json"
    traj.write_text(json.dumps(SWEEP))
    before = snapshot(src, traj)
    Path("motion.gif").symlink_to(traj)
    for record in (traj, src, Path("motion.gif"), tmp_path / "x" / ".." / "traj.json"):
        rc, err = modc(capsys, "play", src, "--traj", traj, "--headless", "--record", record)
        assert rc == 2 and "error[output-unsafe]" in err and "--record motion.gif" in err, (record, err)
    assert unchanged(before)


# --- item 2: leftovers ---------------------------------------------------------------------------


def test_a_user_folder_named_like_a_leftover_is_kept(project, capsys):
    out = Path("out")
    assert modc(capsys, project / "arm.mod", "-o", out, "--only", "urdf")[0] == 0
    mine = Path(".out.modc-old-backup")
    mine.mkdir()
    (mine / "notes.txt").write_text("precious")
    assert modc(capsys, project / "arm.mod", "-o", out, "--only", "urdf")[0] == 0
    assert (mine / "notes.txt").read_text() == "precious"
    assert sorted(p.name for p in Path(".").iterdir()) == [".out.modc-old-backup", "out"]


# --- item 3: fmt ---------------------------------------------------------------------------------


def test_fmt_never_loses_a_concurrent_save(tmp_path, capsys, monkeypatch):
    from modc.syntax import format as fmt

    src = tmp_path / "a.mod"
    src.write_text("robot a {\nchain H1 - L1\n}\n")
    src.chmod(0o640)
    saved = b"robot a {\n    chain H1 - L3   # the user's edit, saved while modc formatted\n}\n"
    real = fmt.format_text

    def editor_saves_meanwhile(text, path):
        result = real(text, path)
        Path(path).write_bytes(saved)
        return result

    monkeypatch.setattr(fmt, "format_text", editor_saves_meanwhile)
    rc, err = modc(capsys, "fmt", src)
    assert rc == 2 and str(src) in err and "changed on disk" in err, err
    assert src.read_bytes() == saved
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.mod"], "no temporary file left"
    monkeypatch.setattr(fmt, "format_text", real)
    src.write_text("robot a {\nchain H1 - L1\n}\n")
    assert modc(capsys, "fmt", src)[0] == 0  # without a concurrent save: formatted, mode kept
    assert src.read_text() == "robot a {\n    chain H1 - L1\n}\n"
    assert src.stat().st_mode & 0o777 == 0o640


# --- the caches ----------------------------------------------------------------------------------


def test_a_cache_dir_holding_an_input_is_not_written(project, capsys, monkeypatch):
    before = snapshot(*project.iterdir())
    for cache in (project, project / "arm.mod"):
        monkeypatch.setenv("MODC_CACHE_DIR", str(cache))
        rc, err = modc(capsys, project / "arm.mod", "-o", Path("out"), "--only", "urdf,srdf")
        assert rc == 0, err
        assert err.count(f"not caching in {cache}: it is or holds the input") == 1, err
        assert unchanged(before) and sorted(project.iterdir()) == sorted(before)


def test_the_cache_writes_only_inside_its_directory(tmp_path, monkeypatch):
    from modc import cache

    outside = tmp_path / "outside"
    outside.mkdir()
    root = tmp_path / "cache"
    root.mkdir()
    (root / "meshes").symlink_to(outside)  # a link leading out of the cache
    monkeypatch.setenv("MODC_CACHE_DIR", str(root))
    monkeypatch.delenv("MODC_NO_CACHE", raising=False)
    cache.put("meshes", "k.stl", b"data")
    for kind, name in (("..", "x"), ("torque", "../x"), ("torque", "/tmp/x")):
        cache.put(kind, name, b"data")
    assert list(outside.iterdir()) == [] and not (tmp_path / "x").exists()
    assert sorted(p.name for p in root.iterdir()) == ["meshes", "torque"]
    cache.put("torque", "k.json", b"[1]")
    assert cache.get("torque", "k.json") == b"[1]"
    os.mkfifo(root / "torque" / "fifo.json")  # a planted FIFO never blocks a read
    assert cache.get("torque", "fifo.json") is None


def test_one_file_is_replaced_whole_or_not_at_all(tmp_path):
    """outputs.replace_file, the one temporary-file-then-rename writer (fmt's rewrite, the cache):
    the new contents and mode in one rename; a link named like the file is replaced, not
    followed; a refusal just before the rename keeps the old file; no temporary file stays."""
    from modc.outputs import replace_file

    f = tmp_path / "a.mod"
    f.write_text("old")
    replace_file(f, b"new", mode=0o640)
    assert f.read_bytes() == b"new" and (f.stat().st_mode & 0o777) == 0o640

    def refuse() -> None:
        raise RuntimeError("changed on disk")

    with pytest.raises(RuntimeError):
        replace_file(f, b"newer", before_rename=refuse)
    assert f.read_bytes() == b"new"
    target = tmp_path / "target"
    target.write_text("keep")
    link = tmp_path / "entry"
    os.symlink(target, link)
    replace_file(link, b"entry", durable=True)
    assert target.read_text() == "keep" and not link.is_symlink() and link.read_bytes() == b"entry"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.mod", "entry", "target"]
