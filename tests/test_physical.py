"""Meshes, masses and inertias agree: one set of primitives makes both mesh and inertia."""
from __future__ import annotations

import io

import numpy as np
import pytest
import trimesh
from conftest import checked_ok

from modc.model import library
from modc.physical.assembly import describe, library_mass
from modc.physical.inertia import part_inertial
from modc.physical.meshes import SECTIONS, build
from modc.physical.parts import mesh_primitives, unit_parts


@pytest.mark.parametrize("variant", ["H", "L"])
@pytest.mark.parametrize("kind", [1, 2, 3, 4])
def test_mesh_mass_properties_match_the_analytic_inertia(variant, kind):
    """The generated STL, filled with the part's mass, has the inertia the URDF declares (within
    the faceting of 48-sided cylinders)."""
    lib = library.default()
    for part in unit_parts(lib, variant, kind, 0.22):
        mesh = trimesh.load(io.BytesIO(build(part)), file_type="stl")
        mesh.apply_scale((part.scale_x, 1, 1))
        # STL merges touching primitives' vertices, so test the volume integrals, not manifoldness
        assert mesh.volume == pytest.approx(sum(p.volume for p in part.primitives), rel=0.02), part.mesh
        mesh.density = part.mass / mesh.volume
        expected = part_inertial(part, np.eye(4))
        assert np.allclose(mesh.center_mass, expected.com, atol=2e-4), part.mesh
        assert np.allclose(mesh.moment_inertia, expected.inertia, rtol=0.03, atol=1e-7), part.mesh


def _trimesh_stl(part) -> bytes:
    """The part's STL as trimesh makes it (how modc made them before meshes.py did it in numpy)."""
    from trimesh.creation import annulus, box, cylinder

    meshes = []
    for prim in mesh_primitives(part):
        T = np.eye(4)
        T[:3, :3] = np.array(prim.rotation)
        T[:3, 3] = prim.center
        if prim.shape == "cylinder":
            meshes.append(cylinder(radius=prim.dims[0], height=prim.dims[1], sections=SECTIONS, transform=T))
        elif prim.shape == "tube":
            meshes.append(annulus(r_min=prim.dims[0], r_max=prim.dims[1], height=prim.dims[2], sections=SECTIONS,
                                  transform=T))
        else:
            meshes.append(box(extents=prim.dims, transform=T))
    return trimesh.exchange.stl.export_stl(trimesh.util.concatenate(meshes))


@pytest.mark.parametrize("variant", ["H", "L"])
@pytest.mark.parametrize("kind", [1, 2, 3, 4])
def test_stl_bytes_are_trimesh_s(variant, kind):
    """meshes.py tessellates and writes STL without trimesh; the bytes are trimesh's own (the
    goldens' SHA-256 did not change when trimesh left the compile path)."""
    lib = library.default()
    for length in (0.22, 0.18):
        for part in unit_parts(lib, variant, kind, length):
            assert build(part) == _trimesh_stl(part), part.mesh


def test_link_mass_scales_with_printed_length():
    lib = library.default()
    short = sum(p.mass for p in unit_parts(lib, "H", 3, 0.10))
    long = sum(p.mass for p in unit_parts(lib, "H", 3, 0.30))
    assert long - short == pytest.approx(0.20 * lib.variants["H"].link_module.mass_per_length)


def test_described_mass_is_the_library_mass():
    r = checked_ok("robot r { chain H1 - H4(pivot=-90deg) - L4(link=300mm) payload 0.3 kg }").design.robots[0]
    d = describe(r)
    assert d.total_mass == pytest.approx(library_mass(r), abs=1e-12)
    assert library_mass(r) == pytest.approx(0.57 * 2 + 0.357 + 0.3 + sum(
        p.mass - (p.mass if p.mesh.startswith("actuator") else 0)
        for u in r.units for p in unit_parts(r.library, u.variant, u.kind, r.link_length(u))))


def test_inertias_are_physical():
    r = checked_ok("robot r { chain H1 - H4(pivot=-90deg, port=45deg) - H3(pivot=30deg) - L4 - L2 }").design.robots[0]
    for link in describe(r).links:
        inertia = link.inertial.inertia
        ev = np.linalg.eigvalsh(inertia)
        assert ev.min() > 0, link.name
        assert ev[0] + ev[1] >= ev[2] - 1e-15, link.name  # triangle inequality


def test_fingerprint_follows_every_input_of_the_description():
    """The key of the cached collision matrix and torque search: equal for equal arms, different
    when anything they depend on differs."""
    base = "robot r {\n    chain H1 - H4(pivot=-90deg) - L3\n%s}\n"
    variants = ["", "    payload 0.2 kg\n", "    limit joint_2 (-90, 90) deg\n", "    tool at (0.05, 0, 0) m\n"]
    prints = [describe(checked_ok(base % v).design.robots[0]).fingerprint() for v in variants]
    prints.append(describe(checked_ok(base.replace("L3", "L3(link=200mm)") % "").design.robots[0]).fingerprint())
    prints.append(describe(checked_ok(base.replace("-90deg", "-75deg") % "").design.robots[0]).fingerprint())
    assert len(set(prints)) == len(prints)
    assert describe(checked_ok(base % "").design.robots[0]).fingerprint() == prints[0]
