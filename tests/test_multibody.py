"""The in-memory physical model (modc.physical.multibody) against pinocchio's reading of the
files modc emits: what the analyses compute on equals what a user loads.

The reference is built here from the emitted text only: pinocchio.buildModelFromXML on the URDF
backend's output, pinocchio.buildGeomFromUrdf (assimp reading the STL files) on a written tree.
"""
from __future__ import annotations

import numpy as np
import pytest
from conftest import EXAMPLES, compile_file

from modc.compiler import check_file
from modc.physical import collisions, multibody
from modc.physical.assembly import describe

pin = pytest.importorskip("pinocchio")

ATOL = 1e-12
TEXT_ATOL = 1e-10  # the emitted URDF carries 12 significant digits (an rpy of pi/2 is off by 5e-12)


def _robots():
    for ex in EXAMPLES:
        for r in check_file(ex).design.robots:
            yield pytest.param(ex, r.name, id=f"{ex.stem}-{r.name}")


def _robot(path, name):
    return next(r for r in check_file(path).design.robots if r.name == name)


def _emitted(path, robot, tmp_path):
    out = tmp_path / "out"
    compile_file(path, out)
    return out / "urdf" / f"{robot.file_stem}.urdf"


def _full_precision_urdf(robot, monkeypatch) -> str:
    """The URDF backend's text with every number in 17 significant digits (round-trip exact), so
    that the comparison measures the model, not the text's rounding."""
    from modc.backends import Build, common, urdf
    from modc.model import Design

    monkeypatch.setattr(common, "num", lambda x: repr(float(x)))  # the URDF's context is built in common
    monkeypatch.setattr(common, "vec", lambda xs: " ".join(repr(float(x)) for x in xs))
    return urdf.urdf_text(Build(Design(path="t.mod", robots=(robot,))), robot)


def _same_model(mine, ref, atol: float) -> None:
    assert mine.name == ref.name
    assert list(mine.names) == list(ref.names)
    assert [(f.name, f.type, f.parentJoint, f.parentFrame) for f in mine.frames] == \
        [(f.name, f.type, f.parentJoint, f.parentFrame) for f in ref.frames]
    assert np.allclose([f.inertia.mass for f in mine.frames], [f.inertia.mass for f in ref.frames], rtol=0, atol=atol)
    for a, b in zip(mine.inertias, ref.inertias, strict=True):
        assert np.allclose(a.toDynamicParameters(), b.toDynamicParameters(), rtol=0, atol=atol)
    for field in ("lowerPositionLimit", "upperPositionLimit", "effortLimit", "velocityLimit"):
        assert np.allclose(getattr(mine, field), getattr(ref, field), rtol=0, atol=atol * 10), field
    da, db = mine.createData(), ref.createData()
    rng = np.random.default_rng(11)
    for q in rng.uniform(ref.lowerPositionLimit, ref.upperPositionLimit, size=(20, ref.nq)):
        pin.framesForwardKinematics(mine, da, q)
        pin.framesForwardKinematics(ref, db, q)
        for k in range(len(ref.frames)):
            assert np.allclose(da.oMf[k].homogeneous, db.oMf[k].homogeneous, rtol=0, atol=atol), ref.frames[k].name
        assert np.allclose(pin.crba(mine, da, q), pin.crba(ref, db, q), rtol=0, atol=atol)
        assert np.allclose(pin.computeGeneralizedGravity(mine, da, q), pin.computeGeneralizedGravity(ref, db, q),
                           rtol=0, atol=atol)


@pytest.mark.parametrize("path, name", list(_robots()))
def test_direct_model_equals_the_model_of_the_same_urdf_text(path, name, monkeypatch):
    """Frames (FK at random q), inertias, limits, M(q) and g(q) to 1e-12."""
    robot = _robot(path, name)
    _same_model(multibody.model(describe(robot)), pin.buildModelFromXML(_full_precision_urdf(robot, monkeypatch)), ATOL)


@pytest.mark.parametrize("stem", ["farm", "cellarm", "table3_raven"])
def test_direct_model_equals_the_model_of_the_emitted_file(stem, tmp_path):
    path = next(e for e in EXAMPLES if e.stem == stem)
    (robot,) = check_file(path).design.robots
    ref = pin.buildModelFromUrdf(str(_emitted(path, robot, tmp_path)))
    _same_model(multibody.model(describe(robot)), ref, TEXT_ATOL)


def _triangles(geometry) -> set[tuple[tuple[float, ...], ...]]:
    """The triangles as sets of corner coordinates (independent of vertex and face order)."""
    v = np.asarray(geometry.vertices())
    out = set()
    for i in range(geometry.num_tris):
        t = geometry.tri_indices(i)
        out.add(tuple(sorted(tuple(v[t[k]]) for k in range(3))))
    return out


@pytest.mark.parametrize("stem", ["farm", "example_b", "table3_wrist"])
def test_collision_geometry_is_what_pinocchio_loads_from_the_files(stem, tmp_path):
    path = next(e for e in EXAMPLES if e.stem == stem)
    (robot,) = check_file(path).design.robots
    urdf = _emitted(path, robot, tmp_path)
    ref_model = pin.buildModelFromUrdf(str(urdf))
    ref = pin.buildGeomFromUrdf(ref_model, str(urdf), pin.GeometryType.COLLISION, package_dirs=[str(urdf.parent)])
    desc = describe(robot)
    mine = multibody.geometry(desc, multibody.model(desc))
    assert len(mine.geometryObjects) == len(ref.geometryObjects)
    for a, b in zip(mine.geometryObjects, ref.geometryObjects, strict=True):
        assert (a.name, a.parentJoint, a.parentFrame) == (b.name, b.parentJoint, b.parentFrame)
        assert np.allclose(a.placement.homogeneous, b.placement.homogeneous, rtol=0, atol=TEXT_ATOL), a.name
        assert np.array_equal(a.meshScale, b.meshScale)
        # the same float32 vertices; assimp reorders triangles for cache locality, the set is the same
        assert np.array_equal(np.asarray(a.geometry.vertices()), np.asarray(b.geometry.vertices())), a.name
        assert _triangles(a.geometry) == _triangles(b.geometry), a.name


@pytest.mark.parametrize("path", EXAMPLES, ids=[e.stem for e in EXAMPLES])
def test_collision_matrix_equals_the_one_computed_on_the_emitted_files(path):
    from modc.compiler import build

    c = check_file(path)
    files = build(c, ["urdf", "meshes"])
    for robot in c.design.robots:
        ref = collisions.compute(collisions.load(files, f"urdf/{robot.file_stem}.urdf"), samples=3000, seed=5)
        mine = collisions.compute(collisions.geometry(describe(robot)), samples=3000, seed=5)
        assert (mine.links, mine.geometry_links, mine.disabled, mine.enabled) == \
            (ref.links, ref.geometry_links, ref.disabled, ref.enabled)
        assert mine.counts == ref.counts  # not only the verdicts: every pair collided in the same samples
