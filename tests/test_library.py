"""The module library is data: the paper's numbers, validated, replaceable by the user's own."""
from __future__ import annotations

import math
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
    (("mass: 0.57", "mass: -1"), "mass: must be greater than 0"),
    (("epsilon: 3", "epsilon: 0"), "epsilon: must be at least 1"),
    (("max_dof: 6", 'max_dof: "six"'), "max_dof: expected a whole number"),
    (("first_variant: H", "first_variant: X"), "variant 'X'"),
    (("lower_deg: -170", "lower_deg: 200"), "lower_deg"),
])
def test_invalid_library_is_a_diagnostic(tmp_path, mutation, fragment):
    text = (ROOT / "libraries" / "mark2.yaml").read_text().replace(*mutation, 1)
    (tmp_path / "bad.yaml").write_text(text)
    c = check_text('robot r { library "bad.yaml" chain H1 - L1 }', str(tmp_path / "r.mod"))
    assert [d.code for d in c.diagnostics] == ["library-invalid"]
    assert fragment in c.diagnostics[0].message
    assert "Input should" not in c.diagnostics[0].message  # the author's words, not pydantic's
