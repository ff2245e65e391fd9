"""The command line as people meet it: the light install (lint, fmt, lsp without the heavy
extras), a clear line when a command needs `modc[full]`, a mistyped command, the help text."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import ROOT

# Blocks the `full` extra's modules on import, as if they were not installed: the light install
# tested without building a second venv (which is too slow for CI).
BLOCKER = """
import sys
BLOCKED = {"pinocchio", "coal", "hppfcl", "pybullet", "pybullet_data", "ompl", "trimesh", "PIL", "mujoco"}
class _Blocker:
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] in BLOCKED:
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)
        return None
sys.meta_path.insert(0, _Blocker())
"""
FARM = ROOT / "examples" / "farm.mod"


def modc(
    *args: str, cwd: Path = ROOT, light: Path | None = None, stdin: str | None = None
) -> subprocess.CompletedProcess:
    env = dict(os.environ)
    if light is not None:  # a sitecustomize on PYTHONPATH runs before modc
        (light / "sitecustomize.py").write_text(BLOCKER, encoding="utf-8")
        env["PYTHONPATH"] = os.pathsep.join([str(light), str(ROOT), env.get("PYTHONPATH", "")])
        # an empty cache: a compile whose torque search and collision matrix are cached needs no
        # pinocchio at all (test_startup), and this test is about a first compile
        env["MODC_CACHE_DIR"] = str(light / "cache")
    return subprocess.run(
        [sys.executable, "-m", "modc", *args],
        capture_output=True,
        text=True,
        cwd=cwd,
        env=env,
        input=stdin,
        timeout=300,
    )


@pytest.fixture
def light(tmp_path) -> Path:
    d = tmp_path / "light"
    d.mkdir()
    return d


def test_the_blocker_blocks(light):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(light), str(ROOT)]))
    (light / "sitecustomize.py").write_text(BLOCKER, encoding="utf-8")
    r = subprocess.run([sys.executable, "-c", "import pybullet"], capture_output=True, text=True, env=env)
    assert r.returncode != 0 and "No module named 'pybullet'" in r.stderr


@pytest.mark.slow
def test_lint_and_fmt_work_from_the_light_install(light, tmp_path):
    r = modc("lint", "examples", light=light)
    assert r.returncode == 0, r.stderr
    assert "0 errors" in r.stderr and "Traceback" not in r.stderr
    messy = tmp_path / "messy.mod"
    messy.write_text("robot   a {chain H1-L1\n  pose p (0,0) deg }\n", encoding="utf-8")
    r = modc("fmt", str(messy), light=light)
    assert r.returncode == 0, r.stderr
    assert messy.read_text(encoding="utf-8") == FARM.read_text(encoding="utf-8") or "chain H1 - L1" in messy.read_text()
    r = modc("lint", "--format", "sarif", str(messy), light=light)
    assert r.returncode == 0 and json.loads(r.stdout)["version"] == "2.1.0"


@pytest.mark.slow
def test_lsp_works_from_the_light_install(light):
    """`modc lsp` over stdio with the heavy modules blocked: diagnostics and hover."""
    from modc.lsp.client import Client

    (light / "sitecustomize.py").write_text(BLOCKER, encoding="utf-8")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(light), str(ROOT)]))
    with Client([sys.executable, "-m", "modc", "lsp"], cwd=str(ROOT), env=env) as c:
        c.initialize()
        uri = "file:///tmp/light.mod"
        c.open(uri, "robot a { chain H1 - L4(port=40deg) }\n")
        # generous timeouts: guards against a hang, not a speed limit (a loaded machine takes seconds)
        assert [d["code"] for d in c.diagnostics(uri, timeout=300)] == ["twist-not-realisable"]
        hover = c.at("textDocument/hover", uri, 0, 22)
        assert "KA-58" in json.dumps(hover)
        assert c.shutdown(timeout=300) == 0
    assert b"Traceback" not in b"".join(c.stderr)


@pytest.mark.slow
@pytest.mark.parametrize(
    "command",
    [
        ["sim", str(FARM)],
        ["plan", str(FARM), "--to", "plant"],
        ["design", str(ROOT / "examples" / "farm_cell.mod"), "-o", "OUT", "-q"],
    ],
)
def test_a_command_that_needs_the_full_extra_says_so(light, tmp_path, command):
    """sim and plan need pybullet/pinocchio/OMPL, design coal and pinocchio: a light install says
    how to get them, exit 2 (design before its search: no progress line)."""
    command = [str(tmp_path / "out") if a == "OUT" else a for a in command]
    r = modc(*command, light=light)
    assert r.returncode == 2, r.stderr
    assert "Traceback" not in r.stderr
    line = r.stderr.strip().splitlines()[-1]
    assert "pip install 'CHECKOUT[full]'" in line and "light install" in line
    assert not (tmp_path / "out").exists() and "shapes" not in r.stderr


def test_pyproject_light_and_full():
    tomllib = pytest.importorskip("tomllib")
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    core = {d.split(">")[0].split("<")[0].split("=")[0].strip() for d in project["dependencies"]}
    assert core == {"lark", "pydantic", "jinja2", "numpy", "pyyaml", "click", "rich", "pygls"}
    full = {d.split(">")[0].split("<")[0].strip() for d in project["optional-dependencies"]["full"]}
    assert {"pin", "pybullet", "ompl", "pillow", "mujoco", "viser", "dask", "distributed", "toppra"} <= full
    for doc in ("README.md", ".ci/run"):  # the documented setup still installs everything
        assert ".[full" in (ROOT / doc).read_text(encoding="utf-8"), doc


# --- routing and help --------------------------------------------------------------------------


def test_a_mistyped_command_gets_did_you_mean():
    r = modc("lnt", "examples/farm.mod")
    assert r.returncode == 2
    assert r.stderr.strip() == "modc: no command or file 'lnt': did you mean 'lint'?"
    r = modc("zzzz")
    assert r.returncode == 2 and "no command or file 'zzzz'" in r.stderr and "modc --help" in r.stderr


@pytest.mark.slow
def test_a_file_is_still_compiled_without_the_command(tmp_path):
    from modc.cli.app import route

    commands = ["compile", "lint", "sim"]
    assert route(["farm.mod", "-o", "out"], commands) == ["compile", "farm.mod", "-o", "out"]
    assert route(["dir/arm", "-o", "out"], commands) == ["compile", "dir/arm", "-o", "out"]
    assert route(["lint", "x.mod"], commands) == ["lint", "x.mod"]
    assert route(["--version"], commands) == ["--version"]
    (tmp_path / "lnt").write_text("robot a { chain H1 - L1 }\n")
    r = modc("lnt", "-o", str(tmp_path / "out"), cwd=tmp_path)  # an existing file named like a typo
    assert "did you mean" not in r.stderr


@pytest.mark.parametrize(
    "command", ["", "compile", "lint", "fmt", "check", "plan", "sim", "render", "play", "dh2mod", "dh"]
)
def test_help_has_plain_metavars_and_defaults(command):
    r = modc(*([command] if command else []), "--help")
    assert r.returncode == 0, r.stderr
    text = r.stdout
    assert "<str>" not in text and "<list[str]>" not in text and "<int" not in text, text
    assert not any(f"{{{w}" in text for w in ("file", "FILE", "files", "FILES", "table", "TABLE")), text
    if command == "":
        assert "modc FILE -o OUT" in text
    if command == "lint":
        assert "[default: text]" in text and "--format text|json|github|sarif" in text and "FILES..." in text
    if command == "compile":
        assert "--out OUT" in text and "[default: 10000" in text


def test_every_command_lists_its_arguments_and_options_plainly():
    """Help of every registered command, as click renders it: each argument under "Arguments"
    with its help, each option with a metavar of its own (no TEXT/INTEGER/[a|b] type names)."""
    import click
    from click.testing import CliRunner

    from modc.cli import app

    runner = CliRunner()
    root = runner.invoke(app, ["--help"])
    assert root.exit_code == 0, root.output
    listed = [line.split()[0] for line in root.output.split("Commands:\n")[1].splitlines() if line.startswith("  ")]
    assert listed == list(app.commands) and listed != sorted(listed)  # registration order, not click's sort
    for name, command in app.commands.items():
        r = runner.invoke(app, [name, "--help"])
        assert r.exit_code == 0, r.output
        text = r.output
        assert not any(w in text.split() for w in ("TEXT", "INTEGER", "FLOAT", "BOOLEAN")), text
        for param in command.params:
            if isinstance(param, click.Argument):
                assert param.help and f"\n  {param.name.upper()}  {param.help.split()[0]}" in text, (name, text)
            elif isinstance(param, click.Option) and param.name != "help":
                shown = ", ".join(param.opts) if param.is_flag else f"{', '.join(param.opts)} {param.metavar}"
                assert f"  {shown}" in text, (name, shown, text)
                assert param.metavar is None or "[" not in param.metavar, (name, param.metavar)


def test_version_and_bare_modc():
    from modc import __version__

    r = modc("--version")
    assert r.returncode == 0 and r.stdout == f"modc {__version__}\n"
    r = modc()
    assert r.returncode == 2 and "Usage: modc [OPTIONS] COMMAND" in r.stderr and "Commands:" in r.stderr


@pytest.mark.slow
def test_a_first_compile_and_the_torque_check_run_on_a_light_install(light, tmp_path):
    """The worst-case torques run on modc's numpy statics and the farm's collision matrix is
    decided by its bounding spheres and boxes: neither needs the full extra."""
    r = modc(str(FARM), "-o", str(tmp_path / "out"), light=light)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "out" / "urdf").is_dir() or any((tmp_path / "out").iterdir())
    r = modc("check", str(FARM), light=light)
    assert r.returncode == 0 and "joint_2" in r.stdout and "Traceback" not in r.stderr
