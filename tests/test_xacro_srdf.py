"""The xacro macro form's SRDF (config/<stem>_macro.srdf.xacro, modc/backends/xacro_srdf.py).

The macro form splits each URDF link into the bodies of its parts. Its SRDF must disable every
pair of those bodies that touch at the arm's rest poses (pinocchio + coal find 3 such pairs for the
farm arm and 6 for Example B at the zero pose that the URDF's SRDF leaves enabled: each unit's
input casing against its output casing), and may disable nothing the URDF's SRDF keeps checking.
Checked with the real consumers: the PyPI xacro expands both files, pinocchio + coal collide the
expanded macro form's meshes.
"""
from __future__ import annotations

import xml.etree.ElementTree as ET
from itertools import combinations

import numpy as np
import pytest
from conftest import EXAMPLES

from modc.backends.xacro_srdf import body_of
from modc.compiler import build, check_file

xacro = pytest.importorskip("xacro")
pin = pytest.importorskip("pinocchio")


def compiled(stem: str, tmp_path):
    (ex,) = [e for e in EXAMPLES if e.stem == stem]
    c = check_file(ex)
    files = build(c)
    for rel, content in files.items():
        p = tmp_path / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_bytes(content) if isinstance(content, bytes) else p.write_text(content, encoding="utf-8")
    return c.design.robots[0], files, tmp_path


def expand_srdf(d, robot, prefix: str = "") -> set[frozenset[str]]:
    """The macro instantiated in a robot's SRDF, as a user would."""
    top = d / "config" / "top.srdf.xacro"
    top.write_text(f'<robot name="{robot.file_stem}" xmlns:xacro="http://www.ros.org/wiki/xacro">'
                   f'<xacro:include filename="{robot.file_stem}_macro.srdf.xacro"/>'
                   f'<xacro:{robot.file_stem}_srdf prefix="{prefix}"/></robot>')
    doc = ET.fromstring(xacro.process_file(str(top)).toxml())
    return {frozenset((e.get("link1"), e.get("link2"))) for e in doc.findall("disable_collisions")}


def touching(model, geom_model, q) -> set[frozenset[str]]:
    """Pairs of links whose collision meshes intersect at q (pinocchio + coal)."""
    geom_model = geom_model.copy()
    geom_model.addAllCollisionPairs()
    data, gdata = model.createData(), pin.GeometryData(geom_model)
    pin.computeCollisions(model, data, geom_model, gdata, q, False)
    out = set()
    for k, cp in enumerate(geom_model.collisionPairs):
        if gdata.collisionResults[k].isCollision():
            a = model.frames[geom_model.geometryObjects[cp.first].parentFrame].name
            b = model.frames[geom_model.geometryObjects[cp.second].parentFrame].name
            if a != b:
                out.add(frozenset((a, b)))
    return out


@pytest.mark.parametrize("stem, dof", [("farm", 3), ("example_b", 6)])
def test_macro_form_srdf_disables_every_touching_pair(stem, dof, tmp_path):
    robot, files, d = compiled(stem, tmp_path)
    urdf = d / "urdf" / f"{robot.file_stem}_expanded.urdf"
    urdf.write_text(xacro.process_file(str(d / f"urdf/{robot.file_stem}.urdf.xacro")).toxml())
    model = pin.buildModelFromUrdf(str(urdf))
    geom = pin.buildGeomFromUrdf(model, str(urdf), pin.GeometryType.COLLISION, package_dirs=[str(urdf.parent)])
    with_geometry = {model.frames[g.parentFrame].name for g in geom.geometryObjects}
    assert with_geometry == set(body_of(robot)), "body_of must list exactly the macro links with geometry"
    plain = {frozenset((e.get("link1"), e.get("link2")))
             for e in ET.fromstring(files[f"config/{robot.file_stem}.srdf"]).findall("disable_collisions")}
    macro = expand_srdf(d, robot)
    rest = [np.zeros(model.nq), np.array(robot.home())]
    at_rest = set().union(*(touching(model, geom, q) for q in rest))
    # the finding, reproduced: the URDF's SRDF leaves these pairs enabled at the zero pose
    assert touching(model, geom, rest[0]) - plain == {frozenset((f"unit_{n}_twist1", f"link_{n}"))
                                                      for n in range(1, dof + 1)}
    assert at_rest - macro == set()
    # and nothing the URDF's SRDF keeps checking is switched off for the bodies of those links
    bodies = body_of(robot)
    for a, b in combinations(sorted(bodies), 2):
        if bodies[a] != bodies[b] and frozenset((bodies[a], bodies[b])) not in plain:
            assert frozenset((a, b)) not in macro, (a, b)


def test_macro_srdf_takes_the_prefix(tmp_path):
    robot, files, d = compiled("farm", tmp_path)
    pairs = expand_srdf(d, robot, prefix="left_")
    assert pairs and all(name.startswith("left_") for pair in pairs for name in pair)
