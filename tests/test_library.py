"""The module library is data: the paper's numbers, validated, replaceable by the user's own."""
from __future__ import annotations

import math
import re
import subprocess
import sys

import pytest
from conftest import ROOT, checked_ok

from modc.compiler import check_text
from modc.model import library


def test_paper_table1_and_section31_numbers():
    lib = library.default()
    H, L = lib.variants["H"].actuator, lib.variants["L"].actuator
    assert (H.model, H.mass, H.rpm, H.torque_nominal, H.torque_peak, H.epsilon) == ("KA-75+", 0.57, 12.2, 12, 30.5, 3)
    assert (L.model, L.mass, L.rpm, L.torque_nominal, L.torque_peak, L.epsilon) == ("KA-58", 0.357, 20.3, 3.6, 6.8, 3)
    geo = {k: (u.port, u.link, u.x01, u.z01, u.z12, u.x23) for k, u in lib.units.items()}
    assert geo == {
        1: ("Ip1", False, 0.0, 0.074, 0.073, 0.0),
        2: ("Ip2", False, -0.0297, 0.075, 0.073, 0.0),
        3: ("Ip1", True, 0.0, 0.074, 0.073, 0.22),
        4: ("Ip2", True, -0.0297, 0.075, 0.073, 0.22),
    }
    assert (lib.control.p, lib.control.i, lib.control.d) == (2, 0, 0.05)
    assert lib.rules.first_variant == "H" and lib.rules.last_variant == "L"
    assert lib.rules.may_follow == {"H": ["H", "L"], "L": ["L"]}


def test_urdf_limits_come_from_the_library(tmp_path):
    from modc.compiler import build

    urdf = build(checked_ok("robot r { chain H1 - L1 }"), ["urdf"])["urdf/mod2_r.urdf"]
    assert f'effort="30.5" velocity="{12.2 * 2 * math.pi / 60:.12g}"' in urdf
    assert f'effort="6.8" velocity="{20.3 * 2 * math.pi / 60:.12g}"' in urdf
    assert f'lower="{math.radians(-170):.12g}"' in urdf


def test_default_library_realises_the_spec_twist_sets():
    lib = library.default()
    assert all(lib.twists.pivot.realisable(a) for a in range(-90, 91, 15))
    assert not lib.twists.pivot.realisable(105) and not lib.twists.pivot.realisable(52)
    assert lib.twists.pivot.nearest(52) == 45 and lib.twists.pivot.nearest(120) == 90
    assert all(lib.twists.port.realisable(a) for a in range(-720, 721, 15))


def test_strict_library_rejects_what_the_hardware_cannot_set():
    c = check_text("robot r { library mark2-strict chain H1 - H4(pivot=-90deg, port=45deg) - L4 }", "s.mod")
    msgs = {d.code: d for d in c.diagnostics}
    assert [d.code for d in c.diagnostics] == ["twist-not-realisable", "twist-not-realisable"]
    assert "-45deg..90deg" in c.diagnostics[0].message and "nearest realisable value: -45deg" in c.diagnostics[0].hint
    assert "30deg" in c.diagnostics[1].message and "60deg" in c.diagnostics[1].hint
    assert msgs


def test_user_library_file_is_used(tmp_path):
    text = (ROOT / "libraries" / "mark2.yaml").read_text().replace("torque_peak: 30.5", "torque_peak: 40.0")
    (tmp_path / "mine.yaml").write_text(text)
    src = tmp_path / "arm.mod"
    src.write_text('robot r {\n  library "mine.yaml"\n  chain H1 - L1\n}\n')
    r = subprocess.run(
        [sys.executable, "-m", "modc", str(src), "-o", str(tmp_path / "out")], capture_output=True, text=True
    )
    assert r.returncode == 0, r.stderr
    assert 'effort="40"' in (tmp_path / "out" / "urdf" / "mod2_r.urdf").read_text()
    # the command-line override wins over the file
    r = subprocess.run([sys.executable, "-m", "modc", str(src), "-o", str(tmp_path / "o2"), "--library", "mark2"],
                       capture_output=True, text=True)
    assert r.returncode == 0 and 'effort="30.5"' in (tmp_path / "o2" / "urdf" / "mod2_r.urdf").read_text()


@pytest.mark.parametrize("mutation, fragment", [
    (("mass: 0.57", "mass: -1"), "mass: must be at least 1e-06"),
    (("epsilon: 3", "epsilon: 0"), "epsilon: must be at least 1"),
    (("max_dof: 6", 'max_dof: "six"'), "max_dof: expected a whole number"),
    (("first_variant: H", "first_variant: X"), "variant 'X'"),
    (("lower_deg: -170", "lower_deg: 200"), "lower_deg"),
    # found by the fuzz campaign: 1e-400 reads as 0.0, a link bar without length or inertia
    (("x23: 0.22}", "x23: 1e-400}"), "x23 of a unit with a link module must be at least 0.1 mm"),
    (("x23: 0.22}", "x23: 0}"), "x23 of a unit with a link module must be at least 0.1 mm"),
])
def test_invalid_library_is_a_diagnostic(tmp_path, mutation, fragment):
    text = (ROOT / "libraries" / "mark2.yaml").read_text().replace(*mutation, 1)
    (tmp_path / "bad.yaml").write_text(text)
    c = check_text('robot r { library "bad.yaml" chain H1 - L1 }', str(tmp_path / "r.mod"))
    assert [d.code for d in c.diagnostics] == ["library-invalid"]
    assert fragment in c.diagnostics[0].message
    assert "Input should" not in c.diagnostics[0].message  # the author's words, not pydantic's


# --- a file that is not a module library is never quoted (issue 21, item 6) ---------------------

SECRET = "hunter2-do-not-print"
NOT_LIBRARIES = {
    "passwd": f"root:x:0:0:{SECRET}:/root:/bin/bash\ndaemon:x:1:1::/:/sbin/nologin\n",
    "dotenv": f"API_TOKEN={SECRET}\nDEBUG=1\n",
    "yaml-secrets": f"password: {SECRET}\nuser: admin\n",
    "yaml-secret-key": f"{SECRET}: 1\nname: x\n",  # library keys beside a foreign one: still not a library
    "yaml-list": f"- {SECRET}\n- b\n",
    "broken-yaml": f"token: [{SECRET}\nother: {{\n",
    "bad-character": f"key: {SECRET}\n\tx: @{SECRET}\n",
    "json": f'{{"token": "{SECRET}"}}\n',
    "empty": "",
}


@pytest.mark.parametrize("kind", NOT_LIBRARIES)
def test_a_file_that_is_not_a_library_is_never_quoted(tmp_path, kind):
    """`library "PATH"` in an untrusted .mod (lint in pre-commit or CI) may name /etc/passwd or a
    .env file: the diagnostic says what kind of file it is not, and no line, key or character of
    it reaches any output format."""
    from modc.diagnostics.render import render_github, render_json, render_sarif, render_text

    (tmp_path / "lib.txt").write_text(NOT_LIBRARIES[kind])
    src = tmp_path / "arm.mod"
    src.write_text('robot r {\n    library "lib.txt"\n    chain H1 - L1\n}\n')
    c = check_text(src.read_text(), str(src))
    assert [d.code for d in c.diagnostics] == ["library-invalid"]
    d = c.diagnostics[0]
    assert "not a module library" in d.message
    assert (d.span.file, d.span.line) == (str(src), 2)  # at the reference, not inside the file
    assert str(tmp_path / "lib.txt") not in c.sources
    outputs = [render_text(c.diagnostics, c.sources), render_json(c.diagnostics), render_github(c.diagnostics),
               render_sarif(c.diagnostics, "0", tmp_path, c.sources)]
    assert not any(SECRET in out for out in outputs)
    r = subprocess.run([sys.executable, "-m", "modc", "lint", str(src)], capture_output=True, text=True)
    assert r.returncode == 1 and "not a module library" in r.stderr and SECRET not in r.stderr + r.stdout


def test_a_file_that_is_not_utf8_is_not_quoted(tmp_path):
    (tmp_path / "lib.bin").write_bytes(b"name: \xff\xfe" + SECRET.encode())
    c = check_text('robot r { library "lib.bin" chain H1 - L1 }', str(tmp_path / "a.mod"))
    assert [d.code for d in c.diagnostics] == ["library-invalid"]
    assert "not UTF-8" in c.diagnostics[0].message and SECRET not in c.diagnostics[0].message


def test_a_library_is_quoted_once_it_parses(tmp_path):
    """A file with the library's keys is the user's library: its lines are shown with a caret."""
    text = (ROOT / "libraries" / "mark2.yaml").read_text().replace("epsilon: 3", "epsilon: 0", 1)
    (tmp_path / "lib.yaml").write_text(text)
    c = check_text('robot r { library "lib.yaml" chain H1 - L1 }', str(tmp_path / "a.mod"))
    from modc.diagnostics.render import render_text

    assert "epsilon: 0" in render_text(c.diagnostics, c.sources)


# --- every library number has a range (issue 21, item 8) -----------------------------------------

_NUMBER_LINE = re.compile(r"^(\s*[a-z_0-9]+:\s*)(-?[0-9][0-9.e+-]*)(\s*(#.*)?)$")
MARK2 = (ROOT / "libraries" / "mark2.yaml").read_text()
NUMBER_LINES = [i for i, line in enumerate(MARK2.split("\n")) if _NUMBER_LINE.match(line)]
EXTREMES = ["1e308", "-1e308", "1e-320", ".nan", "-.inf", "1e400", str(10**30), str(10**400)]


def _with(line: int, value: str) -> str:
    lines = MARK2.split("\n")
    m = _NUMBER_LINE.match(lines[line])
    assert m is not None
    lines[line] = m.group(1) + value + m.group(3)
    return "\n".join(lines)


@pytest.mark.parametrize("value", EXTREMES)
def test_extreme_library_numbers_are_diagnostics(tmp_path, value):
    """Every number of the library set to an extreme: a diagnostic or a working arm, never a
    traceback (the torque analysis crashed on a 1e-320 kg mass and on a 1e308 kg one)."""
    src = 'robot r {\n    library "lib.yaml"\n    chain H1 - L4(port=45deg) - L1\n}\n'
    for line in NUMBER_LINES:
        (tmp_path / "lib.yaml").write_text(_with(line, value))
        library._load_path.cache_clear()
        c = check_text(src, str(tmp_path / "a.mod"), analyses={"torque"})
        errors = [d for d in c.diagnostics if d.is_error]
        where = MARK2.split("\n")[line].strip()
        if errors:
            assert errors[0].code in ("library-invalid", "out-of-range", "not-finite"), (where, errors[0])
            assert errors[0].span.file == str(tmp_path / "lib.yaml"), where
        assert not any(re.search(r"\b(inf|nan)\b", d.message) for d in c.diagnostics), where


def test_a_huge_peak_torque_is_out_of_range(tmp_path):
    """Its servo gain (kp = torque / 0.005 rad) would be infinite in the MJCF."""
    (tmp_path / "lib.yaml").write_text(MARK2.replace("torque_peak: 30.5 ", "torque_peak: 1e300", 1))
    c = check_text('robot r { library "lib.yaml" chain H1 - L1 }', str(tmp_path / "a.mod"))
    assert [d.code for d in c.diagnostics] == ["out-of-range"]
    assert c.diagnostics[0].message == (
        "variants.H.actuator.torque_peak = 1e+300 N·m is out of range (at most 1e+06 N·m)")
    assert c.diagnostics[0].span.file == str(tmp_path / "lib.yaml")


def test_the_smallest_accepted_sizes_still_build(tmp_path):
    """A 0.1 mm actuator (the smallest length accepted) still has a mesh: a 1 µm one left no
    triangles and crashed the collision matrix."""
    from modc.compiler import build

    (tmp_path / "lib.yaml").write_text(MARK2.replace("diameter: 0.075 ", f"diameter: {library.SMALLEST_LENGTH}", 1))
    c = checked_ok('robot r { library "lib.yaml" chain H1 - L4(port=45deg) - L1 }', str(tmp_path / "a.mod"))
    assert "urdf/mod3_r.urdf" in build(c, only=["urdf", "srdf"])


@pytest.mark.parametrize("field, value, code", [
    ("step_deg: 15}", "step_deg: 1e-320}", "library-invalid"),  # design's twist enumeration: OverflowError
    ("step_deg: 15}", "step_deg: 1e-300}", "library-invalid"),  # … and 1e302 values: memory exhausted
    ("step_deg: 15}", "step_deg: 0.5}", "library-invalid"),
    ("min_deg: -90,", "min_deg: -1e308,", "library-invalid"),
    ("max_deg: 90,", "max_deg: 1e308,", "out-of-range"),
])
def test_twist_sets_have_a_range(tmp_path, field, value, code):
    """`modc design` enumerates every realisable twist: a step of at least 1° within ±360°."""
    (tmp_path / "lib.yaml").write_text(MARK2.replace(field, value, 1))
    c = check_text('design c { library "lib.yaml"\n    target t at (0.2, 0.1, 0.2) m\n}\n', str(tmp_path / "a.mod"))
    assert [d.code for d in c.diagnostics] == [code], [(d.code, d.message) for d in c.diagnostics]
    assert "twists.pivot." in c.diagnostics[0].message


def test_a_design_blocks_library_is_looked_up_as_a_robots(tmp_path):
    """check_problems takes the robots' lookup (resolve_library.load_for): a problem inside a
    design block's library file is pointed at there, with its line quoted, as for a robot (the
    block's own copy of the lookup pointed at the `library` statement)."""
    from modc.diagnostics.render import render_text

    (tmp_path / "lib.yaml").write_text(MARK2.replace("torque_peak: 30.5 ", "torque_peak: 1e300", 1))
    src = 'design d {\n    library "lib.yaml"\n    target t at (0.3, 0, 0.2) m\n    units 2\n}\n'
    c = check_text(src, str(tmp_path / "a.mod"))
    assert [d.code for d in c.diagnostics] == ["out-of-range"]
    assert c.diagnostics[0].span.file == str(tmp_path / "lib.yaml")
    assert "torque_peak: 1e300" in render_text(c.diagnostics, c.sources)
