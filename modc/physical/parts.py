"""Representative geometry of the Mark-2 parts as primitives (the paper ships no STL files).

A part is a few primitives (solid cylinder, tube, box), each placed in the part's own frame.
The same primitives give the mesh (meshes.py) and the inertia (inertia.py), so the two agree.
Part frames:
  twist unit                       unit base frame   (origin on the previous module's port)
  input casing                     twist1 frame      (origin on the pivot axis)
  actuator, output casing, link    joint frame       (origin on the output face, z = joint axis)
"""
from __future__ import annotations

import math

import numpy as np

from ..model.library import Library
from ..records import Record

Z_TO_Y = ((1.0, 0.0, 0.0), (0.0, 0.0, -1.0), (0.0, 1.0, 0.0))  # Rx(90°): a z-axis cylinder lying along y
IDENTITY = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


# A part's colour (Part.color) -> RGBA: one home for the URDF's materials, the MJCF and the viewer
MATERIALS = {
    "heavy": (0.20, 0.33, 0.55, 1.0),
    "light": (0.90, 0.50, 0.15, 1.0),
    "twist": (0.75, 0.75, 0.75, 1.0),
    "actuator": (0.12, 0.12, 0.12, 1.0),
    "link": (0.92, 0.92, 0.88, 1.0),
}



class Primitive(Record, kw_only=False):
    shape: str  # "cylinder" (r, h) | "tube" (r_in, r_out, h) | "box" (x, y, z); cylinders along local z
    dims: tuple[float, ...]
    center: tuple[float, float, float]
    rotation: tuple[tuple[float, ...], ...] = IDENTITY

    @property
    def volume(self) -> float:
        if self.shape == "cylinder":
            r, h = self.dims
            return math.pi * r * r * h
        if self.shape == "tube":
            ri, ro, h = self.dims
            return math.pi * (ro * ro - ri * ri) * h
        x, y, z = self.dims
        return x * y * z

    def inertia(self, mass: float) -> np.ndarray:
        """Inertia about the primitive's centroid, in the part frame's axes (uniform density)."""
        if self.shape == "cylinder":
            r, h = self.dims
            d = (mass * (3 * r * r + h * h) / 12, mass * (3 * r * r + h * h) / 12, mass * r * r / 2)
        elif self.shape == "tube":
            ri, ro, h = self.dims
            s = ri * ri + ro * ro
            d = (mass * (3 * s + h * h) / 12, mass * (3 * s + h * h) / 12, mass * s / 2)
        else:
            x, y, z = self.dims
            d = (mass * (y * y + z * z) / 12, mass * (x * x + z * z) / 12, mass * (x * x + y * y) / 12)
        R = np.array(self.rotation)
        return R @ np.diag(d) @ R.T


class Part(Record, kw_only=False):
    mesh: str  # mesh file stem, shared by every unit using the same part
    frame: str  # "unit", "twist1" or "joint"
    mass: float
    primitives: tuple[Primitive, ...]
    scale_x: float = 1.0  # link bars: the mesh is 1 m long and scaled to the unit's link length
    color: str = "grey"


def unit_parts(lib: Library, variant: str, kind: int, link_length: float) -> list[Part]:
    """All parts of one modular unit (paper section 3.1), in their own frames."""
    v = lib.variants[variant]
    t = lib.units[kind]
    a, c, tw, lm = v.actuator, v.casings, v.twist_unit, v.link_module
    R = a.diameter / 2
    Rc = R + c.wall
    bottom = -(c.output_thickness + a.length)  # actuator bottom, joint frame
    color = "heavy" if variant == lib.rules.first_variant else "light"

    cheek_h = t.z01 + 1.5 * c.boss_radius
    cheek_y = Rc + tw.cheek_thickness / 2 + 0.001
    twist = Part(f"twist_unit_{variant}{kind}", "unit", tw.mass, (
        Primitive("cylinder", (Rc, tw.plate), (0.0, 0.0, tw.plate / 2)),
        Primitive("box", (tw.cheek_width, tw.cheek_thickness, cheek_h), (t.x01, cheek_y, cheek_h / 2)),
        Primitive("box", (tw.cheek_width, tw.cheek_thickness, cheek_h), (t.x01, -cheek_y, cheek_h / 2)),
    ), color="twist")

    cup = 0.02
    z_bottom = t.z12 + bottom  # actuator bottom in the twist1 frame
    casing_in = Part(f"input_casing_{variant}{kind}", "twist1", c.input_mass, (
        Primitive("cylinder", (Rc, c.wall), (0.0, 0.0, z_bottom - c.wall / 2)),
        Primitive("tube", (R, Rc, cup), (0.0, 0.0, z_bottom + cup / 2)),
        Primitive("cylinder", (c.boss_radius, 2 * cheek_y), (0.0, 0.0, 0.0), Z_TO_Y),
    ), color=color)

    actuator = Part(f"actuator_{variant}", "joint", a.mass, (
        Primitive("cylinder", (R, a.length), (0.0, 0.0, bottom + a.length / 2)),
    ), color="actuator")

    casing_out = Part(f"output_casing_{variant}", "joint", c.output_mass, (
        Primitive("cylinder", (Rc, c.output_thickness), (0.0, 0.0, -c.output_thickness / 2)),
    ), color=color)

    parts = [twist, casing_in, actuator, casing_out]
    if t.link:
        parts.append(Part(f"link_{variant}", "joint", lm.mass_per_length * link_length, (
            Primitive("box", (link_length, lm.width, lm.height), (link_length / 2, 0.0, lm.height / 2)),
        ), scale_x=link_length, color="link"))
    return parts


def unit_mass(lib: Library, variant: str, kind: int, link_length: float) -> float:
    return sum(p.mass for p in unit_parts(lib, variant, kind, link_length))


def mesh_primitives(part: Part) -> tuple[Primitive, ...]:
    """The primitives as meshed: link bars at unit length (the URDF scales them)."""
    if part.scale_x == 1.0:
        return part.primitives
    (box,) = part.primitives
    _, w, h = box.dims
    return (Primitive("box", (1.0, w, h), (0.5, 0.0, h / 2)),)
