"""A compile of an unchanged file is served from modc's cache (modc.compiler.build_cached): the
very files a fresh build gives, a damaged entry never trusted, anything build reads in the key."""
from __future__ import annotations

import pytest
from conftest import ROOT

from modc import compiler
from modc.compiler import COMPILE_ANALYSES, build, build_cached, check_file


@pytest.fixture
def cache_dir(tmp_path, monkeypatch):
    monkeypatch.setenv("MODC_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.delenv("MODC_NO_CACHE", raising=False)
    return tmp_path / "cache"


def _checked(path=ROOT / "examples" / "farm.mod"):
    return check_file(path, analyses=COMPILE_ANALYSES)


def test_a_hit_gives_the_files_a_fresh_build_gives(cache_dir, monkeypatch):
    checked = _checked()
    fresh = build(checked)
    assert build_cached(checked) == fresh  # a miss builds and stores
    (entry,) = (cache_dir / "builds").glob("*.build")
    calls = []
    monkeypatch.setattr(compiler, "build", lambda *a, **k: calls.append(1) or {})
    assert build_cached(_checked()) == fresh and not calls  # a hit: nothing built
    assert entry.exists()


@pytest.mark.parametrize("damage", ["torn", "flipped", "not a dict"])
def test_a_damaged_entry_is_built_again(cache_dir, damage):
    import hashlib
    import marshal

    checked = _checked()
    fresh = build_cached(checked)
    (entry,) = (cache_dir / "builds").glob("*.build")
    blob = entry.read_bytes()
    if damage == "torn":
        blob = blob[: len(blob) // 2]
    elif damage == "flipped":
        blob = blob[:-10] + bytes([blob[-10] ^ 1]) + blob[-9:]
    else:  # a valid digest over something that is not a build
        payload = marshal.dumps(["urdf/x.urdf"])
        blob = hashlib.sha256(payload).hexdigest().encode() + b"\n" + payload
    entry.write_bytes(blob)
    assert build_cached(_checked()) == fresh


def test_what_build_reads_is_in_the_key(cache_dir, tmp_path):
    checked = _checked()
    first = build_cached(checked)
    other = build_cached(checked, collision_samples=200)  # an option: another entry, its own files
    assert len(list((cache_dir / "builds").glob("*.build"))) == 2
    assert other == build(checked, collision_samples=200)
    src = tmp_path / "farm.mod"
    text = (ROOT / "examples" / "farm.mod").read_text(encoding="utf-8")
    src.write_text(text.replace("robot farm", "robot barn"), encoding="utf-8")
    renamed = build_cached(_checked(src))  # another design: its own files, not the farm's
    assert any("barn" in rel for rel in renamed) and not any("barn" in rel for rel in first)
    assert len(list((cache_dir / "builds").glob("*.build"))) == 3


def test_old_builds_are_pruned(cache_dir, monkeypatch, tmp_path):
    monkeypatch.setattr(compiler, "KEEP_BUILDS", 2)
    text = (ROOT / "examples" / "farm.mod").read_text(encoding="utf-8")
    for k in range(4):
        src = tmp_path / f"arm{k}.mod"
        src.write_text(text.replace("robot farm", f"robot arm{k}"), encoding="utf-8")
        build_cached(_checked(src), only=["urdf"])
    assert len(list((cache_dir / "builds").glob("*.build"))) == 2


def test_the_code_stamp_names_every_file_of_modc_with_its_size_and_time(tmp_path, monkeypatch):
    """modc's own code is in the key: every file (templates too, not bytecode), and a change of one
    file's size or time changes the stamp."""
    import os

    stamp = compiler._code_stamp().splitlines()
    root = os.path.dirname(compiler.__file__)
    expected = sorted(os.path.relpath(os.path.join(d, n), root).replace(os.sep, "/")
                      for d, dirs, names in os.walk(root) if "__pycache__" not in d.split(os.sep)
                      for n in names if not n.endswith((".pyc", ".pyo")))
    assert sorted(line.rsplit(":", 2)[0] for line in stamp) == expected
    st = os.stat(compiler.__file__)
    assert f"compiler.py:{st.st_size}:{st.st_mtime_ns}" in stamp
    tree = tmp_path / "modc"
    (tree / "backends" / "__pycache__").mkdir(parents=True)
    (tree / "backends" / "urdf.py").write_text("x = 1\n")
    (tree / "backends" / "__pycache__" / "urdf.cpython-311.pyc").write_bytes(b"code")
    (tree / "templates").mkdir()
    (tree / "templates" / "a.j2").write_text("{{ x }}")
    before = compiler._code_stamp(str(tree))
    assert [line.rsplit(":", 2)[0] for line in before.splitlines()] == ["backends/urdf.py", "templates/a.j2"]
    os.utime(tree / "templates" / "a.j2", ns=(0, 12345))
    assert compiler._code_stamp(str(tree)) != before
