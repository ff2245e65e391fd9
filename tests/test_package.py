"""The package as users get it: one version, the generated ROS package's license and maintainer
chosen by the user, and the wheel built from this checkout installed into a fresh virtualenv
outside it, where it compiles an example (offline: no index, the dependencies reused)."""
from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

import pytest

from modc.backends import Build
from modc.backends.ros_target import PLACEHOLDER_LICENSE, PLACEHOLDER_MAINTAINER, RosOptionError, resolve
from modc.compiler import build, check_file

ROOT = Path(__file__).resolve().parent.parent
FARM = ROOT / "examples" / "farm.mod"


# --- one version ---------------------------------------------------------------------------------

def test_the_version_is_written_once():
    from modc import __version__
    from modc._version import __version__ as written

    assert __version__ == written and re.fullmatch(r"\d+\.\d+\.\d+\S*", written)
    pyproject = (ROOT / "pyproject.toml").read_text(encoding="utf-8")
    assert 'dynamic = ["version"]' in pyproject and 'path = "modc/_version.py"' in pyproject
    assert not re.search(r'(?m)^version\s*=', pyproject)
    others = [p for p in (ROOT / "modc").rglob("*.py")
              if p.name != "_version.py" and re.search(r"__version__\s*=", p.read_text(encoding="utf-8"))]
    assert others == []


def test_importing_modc_loads_neither_the_api_nor_the_compiler():
    code = "import sys, modc; modc.__version__; print(sorted(m for m in sys.modules if m.startswith('modc')))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         cwd=ROOT, env={**os.environ, "PYTHONPATH": str(ROOT)}).stdout
    assert out.strip() == "['modc', 'modc._version']"


# --- package.xml: the user's license and maintainer ----------------------------------------------

def _package_xml(**options) -> str:
    checked = check_file(FARM)
    return build(checked, ["ros"], **options)["package.xml"]  # type: ignore[return-value]


def test_package_xml_placeholders_say_so():
    xml = _package_xml()
    assert f"<license>{PLACEHOLDER_LICENSE}</license>" in xml
    assert f'<maintainer email="{PLACEHOLDER_MAINTAINER[1]}">{PLACEHOLDER_MAINTAINER[0]}</maintainer>' in xml
    assert ("<!-- TODO: the license and maintainer below are placeholders; set them with the modc options "
            "package-license and maintainer -->") in xml
    assert "BSD" not in xml


@pytest.mark.parametrize("distro", ["jazzy", "noetic"])
def test_package_xml_takes_the_users_license_and_maintainer(distro):
    xml = _package_xml(ros_distro=distro, package_license="Apache-2.0 OR MIT",
                       maintainer="Ana Pérez <ana@lab.example.org>")
    assert "<license>Apache-2.0 OR MIT</license>" in xml
    assert '<maintainer email="ana@lab.example.org">Ana Pérez</maintainer>' in xml
    assert "TODO" not in xml
    catkin_pkg = pytest.importorskip("catkin_pkg.package")
    pkg = catkin_pkg.parse_package_string(xml)
    pkg.validate()
    assert [m.email for m in pkg.maintainers] == ["ana@lab.example.org"] and pkg.licenses == ["Apache-2.0 OR MIT"]


def test_only_one_placeholder_left_is_named():
    xml = _package_xml(package_license="MIT")
    assert "<!-- TODO: the maintainer below is a placeholder; set it with the modc option maintainer -->" in xml
    assert "package-license" not in xml and "<license>MIT</license>" in xml


@pytest.mark.parametrize("field,value", [
    ("package_license", "MIT</license><x>"), ("package_license", ""), ("package_license", "MIT\nBSD"),
    ("maintainer", "no email"), ("maintainer", "x: y <a@b.cd>"), ("maintainer", "Ana <not-an-email>"),
    ("maintainer", "Ana\n <ana@lab.example.org>"), ("maintainer", "# Ana <ana@lab.example.org>"),
])
def test_bad_license_or_maintainer_is_refused(field, value):
    with pytest.raises(RosOptionError):
        resolve(Build(check_file(FARM).design, **{field: value}))


def test_cli_flags_and_a_bad_maintainer_is_a_usage_error(tmp_path):
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    ok = subprocess.run([sys.executable, "-m", "modc", str(FARM), "-o", str(tmp_path / "out"),
                         "--only", "urdf,srdf,ros", "--package-license", "MIT",
                         "--maintainer", "Ana <ana@lab.example.org>"],
                        capture_output=True, text=True, env=env, cwd=tmp_path)
    assert ok.returncode == 0, ok.stderr
    assert "<license>MIT</license>" in (tmp_path / "out" / "package.xml").read_text(encoding="utf-8")
    bad = subprocess.run([sys.executable, "-m", "modc", str(FARM), "-o", str(tmp_path / "bad"), "--maintainer", "Ana"],
                         capture_output=True, text=True, env=env, cwd=tmp_path)
    assert bad.returncode == 2 and "Traceback" not in bad.stderr and "Name <email>" in bad.stderr
    assert not (tmp_path / "bad").exists()


# --- the wheel, installed outside the checkout -----------------------------------------------------

SOURCE = ("pyproject.toml", "README.md", "LICENSE", "modc", "grammar", "templates", "libraries")


def _deps_dir(tmp_path: Path) -> Path:
    """This interpreter's installed packages minus modc itself (its editable install would shadow the
    wheel): symlinks, so that the fresh venv reuses them without downloading anything."""
    deps = tmp_path / "deps"
    deps.mkdir()
    for lib in dict.fromkeys([sysconfig.get_paths()["purelib"], sysconfig.get_paths()["platlib"]]):
        for entry in Path(lib).iterdir():
            own = entry.name.lower().startswith(("modc", "_editable_impl_modc", "__editable__"))
            if own or (deps / entry.name).exists():
                continue
            (deps / entry.name).symlink_to(entry)
    return deps


@pytest.mark.slow
def test_the_wheel_installs_and_compiles_outside_the_checkout(tmp_path):
    pytest.importorskip("hatchling", reason="building the wheel offline needs hatchling in this environment")
    src = tmp_path / "src"  # a copy: building writes nothing into the checkout
    src.mkdir()
    for name in SOURCE:
        if (ROOT / name).is_dir():
            shutil.copytree(ROOT / name, src / name, ignore=shutil.ignore_patterns("__pycache__"))
        else:
            shutil.copy2(ROOT / name, src / name)
    dist = tmp_path / "dist"
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PIP_INDEX_URL", "PIP_EXTRA_INDEX_URL")}
    env["PIP_NO_INDEX"] = "1"
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--no-build-isolation", "--no-index",
                    "-w", str(dist), str(src)], check=True, capture_output=True, text=True, env=env, cwd=tmp_path)
    wheels = list(dist.glob("modc-*.whl"))
    assert len(wheels) == 1

    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True)
    py = venv / "bin" / "python"
    site = Path(subprocess.run([str(py), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                               check=True, capture_output=True, text=True).stdout.strip())
    deps = _deps_dir(tmp_path)
    # addsitedir also runs the dependencies' own .pth files (pinocchio's cmeel prefix)
    (site / "zz_reused_deps.pth").write_text(f"import site; site.addsitedir({str(deps)!r})\n", encoding="utf-8")
    # pip itself comes from the reused packages; it installs into the fresh venv (its sys.prefix)
    subprocess.run([str(py), "-m", "pip", "install", "--no-index", "--find-links", str(dist), "modc"],
                   check=True, capture_output=True, text=True, env=env, cwd=tmp_path)

    work = tmp_path / "work"  # far from the checkout: nothing of it on the path
    work.mkdir()
    shutil.copy2(FARM, work / "farm.mod")
    env["MODC_CACHE_DIR"] = str(tmp_path / "cache")
    where = subprocess.run([str(py), "-c", "import modc; print(modc.__file__, modc.__version__)"],
                           check=True, capture_output=True, text=True, env=env, cwd=work).stdout
    assert where.startswith(str(site)) and str(ROOT) not in where
    from modc import __version__
    assert where.split()[1] == __version__
    r = subprocess.run([str(venv / "bin" / "modc"), "farm.mod", "-o", "out"], capture_output=True, text=True,
                       env=env, cwd=work)
    assert r.returncode == 0, r.stderr
    assert (work / "out" / "urdf" / "mod3_farm.urdf").is_file() and (work / "out" / "package.xml").is_file()
    assert (work / "out" / "mjcf" / "mod3_farm.xml").is_file()
