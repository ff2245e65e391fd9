"""xacro backend: a module macro library and a xacro form of every robot (docs/outputs.md).

    urdf/modc_modules.xacro          the macro library: one macro per unit type (1..4) of every
                                     module library the file's robots use, parameterised by variant
    urdf/mod<n>_<name>_macro.xacro   the arm as one macro (prefix, optional parent mount, mesh_root)
    urdf/mod<n>_<name>.urdf.xacro    the robot: args prefix and mesh_root, one instance of the arm
    config/mod<n>_<name>_macro.srdf.xacro   its SRDF collision pairs, a macro (prefix): xacro_srdf.py

`xacro urdf/mod<n>_<name>.urdf.xacro` expands to a URDF equivalent to urdf/mod<n>_<name>.urdf:
same joints (joint_1..joint_n, limits), same base_link/link_i/tool0/payload frames, same rigid
bodies. It has more links: a unit's parts are split into bodies whose inertia is constant in one
of the paper's frames, joined by fixed joints whose origins carry the twists (see LINKS below);
consumers that merge fixed joints (pinocchio, KDL, MoveIt's planning) see the same dynamics.

All numbers are prepared here from modc.physical (parts.unit_parts, inertia.part_inertial and
combine, assembly.describe); the Jinja templates in templates/xacro/ only place them. The one
thing xacro computes is what a macro parameter changes: the link module's mass and inertia as a
function of its length and port twist (box formulas below, checked against parts.py's part).
"""
from __future__ import annotations

import keyword
import math
import re
from typing import Any

import numpy as np
from markupsafe import Markup

from .._version import __version__
from ..kinematics import A_J, matrix_rpy
from ..model import ResolvedRobot
from ..model.library import Library
from ..physical.inertia import Inertial, combine, part_inertial
from ..physical.parts import Part, Primitive, unit_parts
from ..records import Record
from .build import Build
from .common import MATERIALS
from .format import num, vec
from .registry import register
from .templates import comment, render
from .xacro_srdf import macro_srdf_text

LIBRARY_FILE = "modc_modules.xacro"
DEFAULT_MESH_ROOT = "../meshes"  # relative to the expanded URDF placed in OUT/urdf/, like the .urdf

# LINKS: what each unit macro emits (n = the unit's joint number, all names after ${prefix}).
#   unit_<n>_base     frame: unit base (the previous unit's last frame)  body: twist unit
#   unit_<n>_twist1   frame: twist1 (eq. 4, pivot)                       body: input casing + actuator
#   link_<n>          frame: joint (eq. 5, turns with joint_<n>)         body: output casing
#   unit_<n>_twist2   frame: twist2 (eq. 6, port), types 3/4 only        body: link module
# A unit's last frame is link_<n> (types 1/2) or unit_<n>_twist2 (types 3/4): the next unit's parent.
BODIES = ("base", "twist1", "link")


def last_frame(n: int, has_link: bool) -> str:
    """Name (without prefix) of the link whose frame is unit n's last frame."""
    return f"unit_{n}_twist2" if has_link else f"link_{n}"


# The link module as xacro computes it, in the twist2 frame, from the macro's `link` (length L)
# and `port` (p) and the variant's bar data lm (mass_per_length, width w, height h). parts.py
# makes the bar one uniform box (L, w, h) centred at (L/2, 0, h/2) in the joint frame (checked
# by _check_link_module); twist2 = joint frame . [Rx(p) | (L, 0, 0)], so in twist2 the box
# centre is Rx(-p) (-L/2, 0, h/2) and its inertia Rx(-p) diag(Dxx, Dyy, Dzz) Rx(p).
LINK_MODULE = {
    "properties": [
        ("_m", "${lm['mass_per_length'] * link}"),
        ("_c", "${cos(port)}"),
        ("_s", "${sin(port)}"),
        ("_dxx", "${_m * (lm['width']**2 + lm['height']**2) / 12}"),
        ("_dyy", "${_m * (link**2 + lm['height']**2) / 12}"),
        ("_dzz", "${_m * (link**2 + lm['width']**2) / 12}"),
    ],
    "mass": "${_m}",
    "xyz": "${-link / 2} ${_s * lm['height'] / 2} ${_c * lm['height'] / 2}",
    "ixx": "${_dxx}", "ixy": "0", "ixz": "0",
    "iyy": "${_c**2 * _dyy + _s**2 * _dzz}",
    "iyz": "${_s * _c * (_dzz - _dyy)}",
    "izz": "${_s**2 * _dyy + _c**2 * _dzz}",
    # the mesh is the bar at unit length along x of the joint frame, scaled to L
    "visual_xyz": "${-link} 0 0", "visual_rpy": "${-port} 0 0", "scale": "${link} 1 1",
}


# ------------------------------------------------------------------------------------------------
# formatting helpers

_UNSAFE = re.compile(r"[{}$\"<>&\\]")


def _ident(name: str) -> str:
    """A library name as a macro/property prefix: mark2-strict -> mark2_strict."""
    s = re.sub(r"[^0-9A-Za-z_]", "_", name)
    return s if s and not s[0].isdigit() else f"lib_{s}"


# Library data reaches xacro expressions (${...}), which xacro evaluates as Python. Strings go in
# only through _str and keys only through _key, which refuse anything that could end the literal or
# the expression; the library schema (modc.names) already keeps such values out, these make it hold
# by construction. Their results are Markup: trusted xacro source that autoescape leaves as is.

def _str(s: str) -> str:
    if _UNSAFE.search(s) or "'" in s or not s.isprintable():
        raise ValueError(f"cannot place {s!r} in a xacro expression")
    return f"'{s}'"


def _key(k: str) -> str:
    """A keyword argument of dict(...): an ASCII identifier that is not a Python keyword."""
    if not (k.isascii() and k.isidentifier()) or keyword.iskeyword(k):
        raise ValueError(f"cannot use {k!r} as a key in a xacro expression")
    return k


def _pydict(d: dict) -> Markup:
    """A Python dict(...) expression (xacro expressions may not contain braces)."""
    items = []
    for k, v in d.items():
        if isinstance(v, dict):
            v = _pydict(v)
        elif isinstance(v, str):
            v = _str(v)
        else:
            v = num(v)
        items.append(f"{_key(k)}={v}")
    return Markup("dict(" + ", ".join(items) + ")")


def _trusted(value):
    """modc's own xacro source (LINK_MODULE) as Markup, so autoescape keeps its quotes."""
    if isinstance(value, dict):
        return {k: _trusted(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return type(value)(_trusted(v) for v in value)
    return Markup(value) if isinstance(value, str) else value


def _inertial(i: Inertial) -> dict:
    inertia = i.inertia
    return {"mass": i.mass, "xyz": vec(i.com), "ixx": inertia[0, 0], "ixy": inertia[0, 1], "ixz": inertia[0, 2],
            "iyy": inertia[1, 1], "iyz": inertia[1, 2], "izz": inertia[2, 2]}


def _inertial_strings(i: Inertial) -> dict:
    return {k: (v if isinstance(v, str) else num(v)) for k, v in _inertial(i).items()}


def _pose(T: np.ndarray) -> dict:
    return {"xyz": vec(T[:3, 3]), "rpy": vec(matrix_rpy(T[:3, :3]))}


def _deg(rad: float) -> str:
    """An angle as xacro source in degrees: ${radians(45)}; 0 stays 0."""
    d = num(math.degrees(rad))
    return "0" if d == "0" else f"${{radians({d})}}"


# ------------------------------------------------------------------------------------------------
# the macro library


def _role(part: Part) -> str:
    """twist_unit_H1 -> twist_unit, actuator_H -> actuator, link_H -> link_module."""
    role = part.mesh.rsplit("_", 1)[0]
    return "link_module" if role == "link" else role


def _check_link_module(lib: Library, variant: str, part: Part, length: float) -> None:
    """LINK_MODULE's formulas assume parts.py's bar; fail loudly if that ever changes."""
    lm = lib.variants[variant].link_module
    want = (Primitive("box", (length, lm.width, lm.height), (length / 2, 0.0, lm.height / 2)),)
    ok = (part.frame == "joint" and part.primitives == want and part.scale_x == length
          and math.isclose(part.mass, lm.mass_per_length * length, rel_tol=1e-12))
    if not ok:
        raise AssertionError(
            f"link module {part.mesh} is no longer the box LINK_MODULE assumes; update modc/backends/xacro.py"
        )


def unit_data(lib: Library, variant: str, kind: int) -> dict:
    """Everything the unit macro needs about one unit (e.g. H3), as plain numbers and strings.

    Bodies (inertial in the body's frame, see LINKS): base = twist unit (unit frame), twist1 =
    input casing (twist1 frame) + actuator housing (joint frame at theta = 0), link = output
    casing (joint frame). Each part carries its mesh, material and pose in its body.
    """
    t = lib.units[kind]
    v = lib.variants[variant]
    length = t.x23 if t.link else 0.0
    parts = unit_parts(lib, variant, kind, length)
    in_frame = {"unit": ("base", np.eye(4)), "twist1": ("twist1", np.eye(4)), "joint": ("twist1", A_J(0.0, t.z12))}
    bodies: dict[str, list[Inertial]] = {b: [] for b in BODIES}
    placed: dict[str, dict] = {}
    link_module = None
    for p in parts:
        role = _role(p)
        if role == "link_module":
            _check_link_module(lib, variant, p, length)
            link_module = p
            continue
        body, T = ("link", np.eye(4)) if role == "output_casing" else in_frame[p.frame]
        bodies[body].append(part_inertial(p, T))
        placed[role] = {"body": body, "mesh": p.mesh, "material": p.color, **_pose(T)}
    expected = {"twist_unit": "base", "input_casing": "twist1", "actuator": "twist1", "output_casing": "link"}
    if {r: d["body"] for r, d in placed.items()} != expected or (link_module is not None) != t.link:
        raise AssertionError(f"unit {variant}{kind}: parts changed ({sorted(placed)}); update modc/backends/xacro.py")
    lo, hi = v.joint_range
    data: dict[str, Any] = {"effort": v.actuator.torque_peak, "velocity": v.actuator.velocity, "lower": lo, "upper": hi}
    for b in BODIES:
        data[b] = _inertial(combine(bodies[b]))
    for role in expected:
        data[role] = {k: placed[role][k] for k in ("mesh", "material", "xyz", "rpy")}
    if link_module is not None:
        lm = v.link_module
        data["link_module"] = {"mesh": link_module.mesh, "material": link_module.color,
                               "mass_per_length": lm.mass_per_length, "width": lm.width, "height": lm.height}
    return data


class LibraryEntry(Record, kw_only=False):
    ident: str  # macro/property prefix
    library: Library


def library_entries(robots) -> dict[int, LibraryEntry]:
    """id(robot) -> the entry of its library. Entries are made in order of first use; equal
    libraries share one, different libraries with the same name get _2, _3, ... suffixes."""
    entries: list[LibraryEntry] = []
    by_robot: dict[int, LibraryEntry] = {}
    for r in robots:
        lib = r.library
        hit = next((e for e in entries if e.library is lib or e.library == lib), None)
        if hit is None:
            base = _ident(lib.name)
            taken = {e.ident for e in entries}
            ident, k = base, 1
            while ident in taken:
                k += 1
                ident = f"{base}_{k}"
            hit = LibraryEntry(ident, lib)
            entries.append(hit)
        by_robot[id(r)] = hit
    return by_robot


# Library objects are immutable and loaded once per file (model.library caches them), so the
# formatted unit data is kept per library object: repeated compiles skip the inertia sums.
_UNITS_CACHE: dict[int, tuple[Library, list[dict]]] = {}
_UNITS_CACHE_SIZE = 8


def library_units(lib: Library) -> list[dict]:
    """Every unit of the library (H1..L4): its name and the formatted fields of unit_data."""
    hit = _UNITS_CACHE.get(id(lib))
    if hit is not None and hit[0] is lib:
        return hit[1]
    units = []
    for v in lib.variants:
        for k in sorted(lib.units):
            data = unit_data(lib, v, k)
            units.append({"name": _key(f"{v}{k}"), "fields": [(key, _pydict(val) if isinstance(val, dict) else num(val))
                                                         for key, val in data.items()]})
    if len(_UNITS_CACHE) >= _UNITS_CACHE_SIZE:
        _UNITS_CACHE.clear()
    _UNITS_CACHE[id(lib)] = (lib, units)
    return units


def library_context(entry: LibraryEntry) -> dict:
    lib = entry.library
    units = library_units(lib)
    kinds = []
    for k in sorted(lib.units):
        t = lib.units[k]
        kinds.append({
            "kind": k, "port": t.port, "link": t.link, "macro": f"{entry.ident}_unit{k}",
            "twist1": vec((t.x01, 0.0, t.z01)), "joint": vec((0.0, 0.0, t.z12)),
            "x23": num(t.x23), "units": ", ".join(f"{v}{k}" for v in lib.variants),
        })
    return {"ident": entry.ident, "name": comment(lib.name), "description": comment(lib.description),
            "units_property": f"{entry.ident}_units", "units": units, "kinds": kinds}


def modules_text(entries: list[LibraryEntry], source: str) -> str:
    return render("xacro/modc_modules.xacro.j2", {
        "version": __version__, "source": comment(source),
        "libraries": [library_context(e) for e in entries],
        "library_names": comment(", ".join(e.library.name for e in entries)),
        "materials": _pydict({k: vec(v) for k, v in MATERIALS.items()}),
        "link_module": _trusted(LINK_MODULE), "mesh_root": DEFAULT_MESH_ROOT,
    })


# ------------------------------------------------------------------------------------------------
# robots


def macro_name(robot: ResolvedRobot) -> str:
    return _ident(robot.file_stem)


def robot_context(build: Build, robot: ResolvedRobot, entry: LibraryEntry, source: str) -> dict:
    desc = build.description(robot)
    lib = robot.library
    units = []
    parent = "base_link"
    for i, u in enumerate(robot.units):
        n = i + 1
        t = lib.units[u.kind]
        params = [("pivot", _deg(u.pivot))]
        if t.link:
            params += [("port", _deg(u.port)), ("link", num(robot.link_length(u)))]
        lo, hi = robot.joint_range(n)
        if (lo, hi) != robot.hardware_range(n):  # narrowed by `limit`
            params += [("lower", num(lo)), ("upper", num(hi))]
        units.append({"n": n, "name": u.name, "macro": f"{entry.ident}_unit{u.kind}", "variant": _key(u.variant),
                      "parent": parent, "params": params})
        parent = last_frame(n, t.link)
    links = {link.name: link for link in desc.links}
    joints = {j.name: j for j in desc.joints}
    payload = None
    if "payload" in links:
        payload_inertial = links["payload"].inertial
        assert payload_inertial is not None  # a payload has a mass
        payload = {
            "inertial": _inertial_strings(payload_inertial),
            **_pose(joints["payload_joint"].T_parent_child),
        }
    tool = robot.tool
    tool_inertial = links["tool0"].inertial
    assert tool_inertial is not None  # tool0 carries a placeholder inertial
    return {
        "version": __version__, "source": comment(source), "robot": robot.name, "sequence": robot.sequence,
        "name": robot.file_stem, "macro": macro_name(robot), "library": comment(lib.name),
        "library_file": LIBRARY_FILE, "macro_file": f"{robot.file_stem}_macro.xacro",
        "mesh_root": DEFAULT_MESH_ROOT, "units": units,
        "tool": {"parent": parent, "xyz": vec(tool.xyz), "rpy": vec(tool.rpy),
                 "inertial": _inertial_strings(tool_inertial)},
        "payload": payload,
    }


def xacro_files(build: Build) -> dict[str, str]:
    robots = build.robots
    if not robots:
        return {}
    source = build.source_name
    by_robot = library_entries(robots)
    entries = list({id(e): e for e in by_robot.values()}.values())
    files = {f"urdf/{LIBRARY_FILE}": modules_text(entries, source)}
    for r in robots:
        ctx = robot_context(build, r, by_robot[id(r)], source)
        files[f"urdf/{ctx['macro_file']}"] = render("xacro/robot_macro.xacro.j2", ctx)
        files[f"urdf/{r.file_stem}.urdf.xacro"] = render("xacro/robot.urdf.xacro.j2", ctx)
        files[f"config/{r.file_stem}_macro.srdf.xacro"] = macro_srdf_text(build, r, ctx["macro"], source)
    return files


@register("xacro", "xacro: module macro library urdf/modc_modules.xacro + urdf/mod<n>_<name>.urdf.xacro")
def emit(build: Build):
    return xacro_files(build)
