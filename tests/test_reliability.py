"""Issue 10: OUT holds what modc wrote or nothing of the user's is touched; replacement is atomic
under SIGKILL at any moment; refused or failed calls leave nothing behind."""
from __future__ import annotations

import json
import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from conftest import ROOT, run_cpu

from modc.compiler import InputError, write_tree
from modc.files import MANIFEST, manifest_text

QUICK = ROOT / "examples" / "quickstart.mod"
PROC = pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="reads CPU times from /proc")


def tree(root: Path) -> dict[str, bytes]:
    return {p.relative_to(root).as_posix(): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}


def listing(d: Path) -> list[str]:
    return sorted(p.name for p in d.iterdir())


def refused(files, out, **kw) -> str:
    with pytest.raises(InputError) as e:
        write_tree(files, out, **kw)
    return e.value.diagnostic.code + ": " + e.value.diagnostic.message


def test_report_json_does_not_make_a_directory_modcs(tmp_path):
    """The data-loss case of the issue: report.json beside thesis.tex was wiped with exit 0."""
    out = tmp_path / "work"
    out.mkdir()
    (out / "report.json").write_text("{}")
    (out / "thesis.tex").write_text("precious")
    msg = refused({"a.txt": "x"}, out)
    assert msg.startswith("output-not-modc") and "thesis.tex" in msg and "report.json" in msg
    assert tree(out) == {"report.json": b"{}", "thesis.tex": b"precious"}
    assert listing(tmp_path) == ["work"], "a refused call leaves no sibling directories"


def test_manifest_lists_every_file_with_its_hash(tmp_path):
    out = tmp_path / "out"
    files = {"b/x.bin": b"\x00\x01", "a.txt": "é\n", "report.json": "{}\n"}
    write_tree(files, out)
    doc = json.loads((out / MANIFEST).read_text())
    import hashlib

    assert doc["files"] == {k: hashlib.sha256(v if isinstance(v, bytes) else v.encode()).hexdigest()
                            for k, v in sorted(files.items())}
    assert (out / MANIFEST).read_text() == manifest_text(dict(reversed(list(files.items())))), "deterministic"
    assert set(tree(out)) == {*files, MANIFEST}


def test_only_an_unchanged_modc_tree_is_replaced(tmp_path):
    out = tmp_path / "out"
    write_tree({"a.txt": "one", "d/b.txt": "two"}, out)
    write_tree({"c.txt": "three"}, out)  # unchanged: replaced, stale files gone
    assert set(tree(out)) == {"c.txt", MANIFEST}
    (out / "c.txt").write_text("edited by hand")
    assert "c.txt (modified)" in refused({"c.txt": "four"}, out)
    (out / "c.txt").write_text("three")
    (out / "notes.md").write_text("mine")
    assert "notes.md" in refused({"c.txt": "four"}, out)
    (out / "notes.md").unlink()
    os.symlink("/etc/passwd", out / "link")
    assert "link" in refused({"c.txt": "four"}, out)
    (out / "link").unlink()
    (out / MANIFEST).write_text("not json")
    assert "c.txt" in refused({"c.txt": "four"}, out)
    assert listing(tmp_path) == ["out"]


def test_force_replaces_anything_but_never_the_working_directory_or_the_input(tmp_path, monkeypatch):
    out = tmp_path / "out"
    out.mkdir()
    (out / "thesis.tex").write_text("x")
    write_tree({"a.txt": "1"}, out, force=True)
    assert set(tree(out)) == {"a.txt", MANIFEST}
    # a symbolic link as OUT: refused without --force; with it the link is replaced, its target kept
    target = tmp_path / "target"
    target.mkdir()
    (target / "keep.txt").write_text("k")
    link = tmp_path / "link"
    link.symlink_to(target)
    assert "symbolic link" in refused({"a.txt": "1"}, link)
    write_tree({"a.txt": "1"}, link, force=True)
    assert not link.is_symlink() and tree(target) == {"keep.txt": b"k"}
    # `-o .` and its parents, and a directory holding the input: refused even with --force
    monkeypatch.chdir(out)
    for o in (".", "..", str(out), str(tmp_path)):
        assert refused({"a.txt": "2"}, o, force=True).startswith("output-unsafe")
    src = tmp_path / "src"
    src.mkdir()
    (src / "arm.mod").write_text("robot a { chain H1 - L1 }\n")
    assert refused({"a.txt": "2"}, src, force=True, inputs=[src / "arm.mod"]).startswith("output-unsafe")
    assert listing(tmp_path) == ["link", "out", "src", "target"]


@pytest.mark.slow
def test_dot_with_force_from_the_command_line(tmp_path):
    r = subprocess.run([sys.executable, "-m", "modc", str(QUICK), "-o", ".", "--force"], cwd=tmp_path,
                       capture_output=True, text=True)
    assert r.returncode == 2 and "error[output-unsafe]" in r.stderr and "Traceback" not in r.stderr
    assert listing(tmp_path) == []


@pytest.mark.slow
def test_unwritable_out_is_a_clean_exit_2(tmp_path):
    long = tmp_path / ("x" * 300)  # "file name too long" while writing
    r = subprocess.run([sys.executable, "-m", "modc", str(QUICK), "-o", str(long)], capture_output=True, text=True)
    assert r.returncode == 2 and "cannot write" in r.stderr and "Traceback" not in r.stderr, r.stderr
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    try:
        if not os.access(ro, os.W_OK):  # (root ignores permissions)
            r = subprocess.run([sys.executable, "-m", "modc", str(QUICK), "-o", str(ro / "out")],
                               capture_output=True, text=True)
            assert r.returncode == 2 and "cannot write" in r.stderr and "Traceback" not in r.stderr
    finally:
        ro.chmod(0o700)
    assert listing(ro) == [] and listing(tmp_path) == ["ro"]


def test_leftovers_of_a_killed_run_are_removed_and_nothing_else(tmp_path):
    """A leftover is recognised by the marker modc writes inside it, never by its name alone."""
    from modc.files import TEMP_MARKER, _marker_text

    out = tmp_path / "out"
    write_tree({"a.txt": "1"}, out)
    for name in (".out.modc-new-abc123", ".out.modc-old-x_y"):  # what a killed run leaves
        (tmp_path / name).mkdir()
        (tmp_path / name / TEMP_MARKER).write_text(_marker_text("out"))
        (tmp_path / name / "tree").mkdir()
        (tmp_path / name / "tree" / "f").write_text("partial")
    for name in (".out.modc-new-keep", ".other.modc-new-abc", "out.modc-new-abc"):
        (tmp_path / name).write_text("not a directory" if name.endswith("keep") else "")
    (tmp_path / ".other.modc-new-dir").mkdir()
    # the user's own folders named like leftovers: no marker, or a marker for another OUT, or a link
    for name in (".out.modc-new-mine", ".out.modc-old-thesis", ".out.modc-new-other"):
        (tmp_path / name).mkdir()
        (tmp_path / name / "notes.txt").write_text("precious")
    (tmp_path / ".out.modc-new-other" / TEMP_MARKER).write_text(_marker_text("elsewhere"))
    (tmp_path / ".out.modc-old-link").symlink_to(tmp_path / ".out.modc-new-mine")
    write_tree({"a.txt": "2"}, out)
    assert listing(tmp_path) == [".other.modc-new-abc", ".other.modc-new-dir", ".out.modc-new-keep",
                                 ".out.modc-new-mine", ".out.modc-new-other", ".out.modc-old-link",
                                 ".out.modc-old-thesis", "out", "out.modc-new-abc"]
    for name in (".out.modc-new-mine", ".out.modc-old-thesis", ".out.modc-new-other"):
        assert (tmp_path / name / "notes.txt").read_text() == "precious"
    assert tree(out) == {"a.txt": b"2", MANIFEST: tree(out)[MANIFEST]}, "the marker never enters OUT"


def siblings(d: Path) -> list[str]:
    """d's entries but empty folders: a run killed between creating its sibling and marking it
    (microseconds) leaves an empty unmarked folder, which modc leaves alone like any user folder."""
    return [n for n in listing(d) if not ((d / n).is_dir() and n.startswith(".") and not any((d / n).iterdir()))]


# --- SIGKILL at random moments ---------------------------------------------------------------------

WORKER = r"""
import sys, time
from modc.compiler import write_tree
out, n = sys.argv[1], int(sys.argv[2])
trees = [{f"d{i % 7}/f{i}.txt": f"{tag} {i}\n" * 200 for i in range(n)} for tag in ("A", "B")]
for k in range(10**6):
    write_tree(trees[k % 2], out)
    print("AB"[k % 2], time.process_time(), flush=True)  # the event the killer waits for
"""


def cpu_seconds(pid: int) -> float:
    """CPU time a running process has used so far (utime + stime from /proc)."""
    fields = Path(f"/proc/{pid}/stat").read_text().rpartition(")")[2].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def kill_after_cpu(p: subprocess.Popen, seconds: float) -> None:
    """SIGKILL p once it has used `seconds` of CPU time: a moment in its work that does not move
    with the machine's load, as a sleep's would (or at once if it has ended)."""
    try:
        while p.poll() is None and cpu_seconds(p.pid) < seconds:
            time.sleep(0.002)
    except (FileNotFoundError, ProcessLookupError):
        pass
    p.send_signal(signal.SIGKILL)
    p.wait()


def _state(out: Path, n: int) -> str:
    """'A' or 'B' when out is exactly one complete tree, else a description of what is wrong."""
    got = tree(out)
    for tag in "AB":
        want = {f"d{i % 7}/f{i}.txt": (f"{tag} {i}\n" * 200).encode() for i in range(n)}
        if {k: v for k, v in got.items() if k != MANIFEST} == want and MANIFEST in got:
            return tag
    return f"broken: {len(got)} files"


@pytest.mark.slow
@PROC
def test_sigkill_at_random_moments_leaves_old_or_new_tree(tmp_path):
    """A process replacing OUT over and over is killed at 15 seeded random moments inside a write
    (after 1 to 4 complete writes, at a random point of the next write's CPU time); after each, OUT
    is one complete tree, and the next write succeeds and leaves no siblings behind."""
    out, n = tmp_path / "out", 150
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    write_tree({f"d{i % 7}/f{i}.txt": f"A {i}\n" * 200 for i in range(n)}, out)
    rng = random.Random(10)
    phases = set()
    for r in range(15):
        p = subprocess.Popen([sys.executable, "-c", WORKER, str(out), str(n)], env=env, stdout=subprocess.PIPE,
                             text=True)
        cpu = [0.0]
        for _ in range(1 + r % 4):  # wait for complete writes: events, not a guess at the start-up time
            tag, t = p.stdout.readline().split()
            cpu.append(float(t))
        per_write = cpu[-1] - cpu[-2] if len(cpu) > 2 else 0.1
        kill_after_cpu(p, cpu[-1] + rng.random() * per_write)
        p.stdout.close()
        phases.add(tag)
        state = _state(out, n)
        assert state in "AB", state
        write_tree({f"d{i % 7}/f{i}.txt": f"{state} {i}\n" * 200 for i in range(n)}, out)
        assert siblings(tmp_path) == ["out"]
    assert phases == {"A", "B"}, "the kills should land in both phases of the loop"


@pytest.mark.slow
@PROC
def test_sigkill_of_the_compiler_itself(tmp_path):
    """Killed at seeded random points of its CPU time (start-up, compile, write), the compiler
    leaves OUT as it was."""
    out = tmp_path / "out"
    r, total = run_cpu([sys.executable, "-m", "modc", str(QUICK), "-o", str(out)])
    assert r.returncode == 0
    before = tree(out)
    rng = random.Random(3)
    for _ in range(4):
        p = subprocess.Popen([sys.executable, "-m", "modc", str(QUICK), "-o", str(out)],
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        kill_after_cpu(p, rng.random() * total)
        assert tree(out) == before
    r = subprocess.run([sys.executable, "-m", "modc", str(QUICK), "-o", str(out)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert tree(out) == before and siblings(tmp_path) == ["out"]


# --- crash sites: diagnostics within seconds, bounded memory ------------------------------------

def lint(*args: str, cwd: Path | None = None, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "modc", "lint", *args], capture_output=True, text=True,
                          timeout=timeout, cwd=cwd)


def test_devices_and_fifos_are_refused_at_once(tmp_path):
    zero = tmp_path / "zero.mod"
    zero.symlink_to("/dev/zero")
    fifo = tmp_path / "fifo.mod"
    os.mkfifo(fifo)
    for path in (zero, fifo):
        r = lint(str(path), timeout=120)  # a FIFO used to block forever, /dev/zero to read 3.8 GB
        assert r.returncode == 2 and "error[file-not-found]" in r.stderr and "not a regular file" in r.stderr
        assert "Traceback" not in r.stderr


def test_size_limit_counts_bytes_and_reads_no_more(tmp_path):
    from modc.compiler import check_file, check_text
    from modc.syntax.parser import MAX_BYTES

    body = "robot farm {\n    chain H1 - L4(port=45deg) - L1\n}\n"
    accents = body + "# " + "é" * (MAX_BYTES // 2) + "\n"  # fewer characters than the limit, more bytes
    assert len(accents) < MAX_BYTES < len(accents.encode())
    assert [d.code for d in check_text(accents, "a.mod").diagnostics] == ["input-too-large"]
    big = tmp_path / "big.mod"
    big.write_text(accents, encoding="utf-8")
    [d] = check_file(big).diagnostics
    assert d.code == "input-too-large" and f"{len(accents.encode()):,} bytes" in d.message


def test_library_files_have_a_size_limit(tmp_path):
    from modc.model.library import MAX_LIBRARY_BYTES

    lib = tmp_path / "huge.yaml"
    lib.write_text("name: huge\n" + "# padding\n" * (MAX_LIBRARY_BYTES // 10 + 1))
    src = tmp_path / "a.mod"
    src.write_text('robot a {\n    library "huge.yaml"\n    chain H1 - L1\n}\n')
    r = lint(str(src))
    assert r.returncode == 1 and "error[library-invalid]" in r.stderr and "too large" in r.stderr, r.stderr


def test_deep_yaml_and_huge_unit_numbers_are_diagnostics(tmp_path):
    from modc.compiler import check_text

    deep = "robots:\n  - name: a\n    chain: " + "[" * 500 + "]" * 500 + "\n"
    assert [d.code for d in check_text(deep, "deep.yaml").diagnostics] == ["yaml-syntax"]
    lib = tmp_path / "deep-lib.yaml"
    lib.write_text("name: " + "[" * 2000 + "]" * 2000 + "\n")
    c = check_text(f'robot a {{\n    library "{lib}"\n    chain H1 - L1\n}}\n', "a.mod")
    assert [d.code for d in c.diagnostics] == ["library-invalid"]
    # names past the identifier rule's 64 characters never reach the library or joint lookup
    c = check_text("robot a {\n    chain H1 - L" + "1" * 5000 + "\n}\n", "a.mod")
    assert [d.code for d in c.diagnostics] == ["invalid-name"]
    c = check_text("robot a {\n    chain H1 - L" + "1" * 60 + "\n}\n", "a.mod")
    assert [d.code for d in c.diagnostics] == ["unknown-module"]
    c = check_text("robot a {\n    chain H1 - L1²\n}\n", "a.mod")
    assert [d.code for d in c.diagnostics] == ["unexpected-character"]
    c = check_text("robot a {\n    chain H1 - L1\n    limit joint_" + "9" * 5000 + " (0, 1) deg\n}\n", "a.mod")
    assert [d.code for d in c.diagnostics] == ["invalid-name"]
    c = check_text("robot a {\n    chain H1 - L1\n    limit joint_" + "9" * 50 + " (0, 1) deg\n}\n", "a.mod")
    assert [d.code for d in c.diagnostics] == ["unknown-joint"]


@pytest.mark.slow
def test_lint_without_files_is_a_usage_error(tmp_path):
    (tmp_path / "empty").mkdir()
    for arg, what in (("empty", "holds no .mod file"), ("src/**/*.mod", "matches no file")):
        r = lint(arg, cwd=tmp_path)
        assert r.returncode == 2 and what in r.stderr and "Traceback" not in r.stderr


def test_bad_encoding_is_an_error_in_the_file(tmp_path):
    src = tmp_path / "latin1.mod"
    src.write_bytes("robot farm {\n    chain H1 - L1   # 45°\n}\n".encode("latin-1"))
    r = lint(str(src))
    assert r.returncode == 1 and f"{src}:2:25: error[bad-encoding]" in r.stderr and "chain H1" in r.stderr


@pytest.mark.slow
def test_fmt_formats_the_issues_8000_unit_chain():
    """(Its speed, linear in the chain, is measured by benchmarks/bench_fmt.py.)"""
    import gc

    from modc.syntax.format import format_text

    text = "robot a {\n    chain H1 - " + " - ".join(["L4(port=45deg)"] * 8000) + "\n}\n"
    out, errors = format_text(text, "long.mod")
    assert out is not None and not errors and out.count("\n") > 1000  # wrapped at 100 columns
    assert format_text(out, "long.mod")[0] == out
    assert gc.isenabled()
    assert format_text("robot a {\r    chain H1 - L1\r}\r", "cr.mod")[0] == "robot a {\n    chain H1 - L1\n}\n"


def test_no_file_is_written_outside_out(tmp_path):
    out = tmp_path / "out"
    for rel in ("../escape.txt", "/tmp/abs.txt", "a/../../b.txt", MANIFEST):
        with pytest.raises(ValueError):
            write_tree({"ok.txt": "x", rel: "y"}, out)
        assert listing(tmp_path) == [], rel


@pytest.mark.slow
def test_concurrent_writers_to_one_out_are_serialised(tmp_path):
    """Two processes replacing the same OUT at once: both succeed (the flock on the parent keeps
    one from removing the other's sibling as a leftover), OUT is one complete tree, nothing left over."""
    out, n = tmp_path / "out", 150
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    once = WORKER.replace("for k in range(10**6):", "for k in range(int(sys.argv[3]), int(sys.argv[3]) + 6):")
    procs = [subprocess.Popen([sys.executable, "-c", once, str(out), str(n), str(start)], env=env,
                              stderr=subprocess.PIPE, text=True) for start in (0, 1)]
    for p in procs:
        _, err = p.communicate(timeout=120)
        assert p.returncode == 0, err
    assert _state(out, n) in ("A", "B") and listing(tmp_path) == ["out"]
