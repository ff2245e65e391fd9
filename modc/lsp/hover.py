"""Hover: what the word under the cursor is (a keyword, a unit and its actuator, a parameter, a
diagnostic code, a library, `joint_N`, a declared name), as Markdown. The unit and parameter
texts are also completion's documentation."""

from __future__ import annotations

import math

from lsprotocol import types

from ..diagnostics import REGISTRY
from ..model import ResolvedRobot
from ..model.library import Library
from .document import Analysis, Tok, joint_number
from .language import MEASURES, PARAMS, REFERS, UNIT_PARAMS, keyword_doc, name_takers
from .language import all_keywords as language_keywords


def _g(x: float) -> str:
    return f"{x:g}"


def unit_markdown(lib: Library, name: str, spec=None) -> str | None:
    split = lib.split(name)
    if split is None:
        return None
    v, k = split
    var, typ = lib.variants[v], lib.units[k]
    a = var.actuator
    lines = [
        f"**{name}** — {var.description}; unit type {k} (library {lib.name})",
        "",
        f"- actuator **{a.model}**: {_g(a.mass)} kg, {_g(a.rpm)} rpm ({a.velocity:.3g} rad/s), "
        f"nominal torque {_g(a.torque_nominal)} N·m, peak torque {_g(a.torque_peak)} N·m, "
        f"ε = {a.epsilon} (at most {a.epsilon} {v} modules per arm)",
        f"- type {k}: input port **{typ.port}**, link module **{'yes' if typ.link else 'no'}**",
        f"- x01 = {_g(typ.x01)} m, z01 = {_g(typ.z01)} m, z12 = {_g(typ.z12)} m"
        + (f", x23 = {_g(typ.x23)} m (default link length)" if typ.link else ""),
        f"- joint range {_g(var.lower_deg)}° … {_g(var.upper_deg)}°",
        "- parameters: " + ", ".join(f"`{p}`" for p in (UNIT_PARAMS if typ.link else ("pivot",))),
    ]
    if spec is not None:
        parts = [f"pivot {_g(round(math.degrees(spec.pivot), 9))}°"]
        if typ.link:
            parts.append(f"port {_g(round(math.degrees(spec.port), 9))}°")
            parts.append(f"link {_g(spec.link if spec.link is not None else typ.x23)} m")
        lines.append(f"- here: {', '.join(parts)}")
    return "\n".join(lines)


def param_markdown(name: str, lib: Library) -> str:
    kind, text = PARAMS[name]
    extra = ""
    if name == "pivot":
        t = lib.twists.pivot
        extra = f" Realisable in {lib.name}: {_g(t.min_deg)}° … {_g(t.max_deg)}° in {_g(t.step_deg)}° steps."
    elif name == "port":
        t = lib.twists.port
        extra = f" Realisable in {lib.name}: multiples of {_g(t.step_deg)}°" + (
            "." if t.wraps else f" in {_g(t.min_deg)}° … {_g(t.max_deg)}°."
        )
    elif name == "link":
        default = lib.units[max(lib.units)].x23
        extra = (
            f" Printable in {lib.name}: {_g(lib.link_length_min)} … {_g(lib.link_length_max)} m;"
            f" default {_g(default)} m."
        )
    return f"**{name}** ({kind}) — {text}{extra}"


def code_markdown(name: str) -> str:
    c = REGISTRY[name]
    tail = " — may be silenced with `allow`" if c.allowable else ""
    return f"**{name}** ({c.severity.value}{tail}): {c.summary}"


def hover(an: Analysis, offset: int) -> types.Hover | None:
    tok = an.name_at(offset)
    if tok is None:
        return None
    md = _markdown(an, tok)
    if md is None:
        return None
    return types.Hover(
        contents=types.MarkupContent(kind=types.MarkupKind.Markdown, value=md), range=an.index.range(tok.start, tok.end)
    )


def _markdown(an: Analysis, tok) -> str | None:
    """What the token under the cursor is, by its neighbours: a declared name, a unit parameter,
    a library, a diagnostic code, a joint, a unit, a keyword, a unit of measure."""
    prev, nxt = an.neighbours(tok)
    text = tok.text
    robot = an.robot_at(tok.start)
    lib = an.library_for(robot)
    md = None
    if prev is not None and prev.text in name_takers() - REFERS and tok.kind == "word":
        md = _decl_markdown(an, text, robot, prev.text)
    elif text in PARAMS and nxt is not None and nxt.text in ("=", ":"):
        md = param_markdown(text, lib)
    elif prev is not None and prev.text == "library":
        md = _library_markdown(an, text, robot)
    elif tok.kind == "code" and text in REGISTRY:
        md = code_markdown(text)
    elif (n := joint_number(text)) is not None:
        md = _joint_markdown(an, robot, n)
    elif tok.kind == "word" and lib.split(text) is not None:
        md = unit_markdown(lib, text, _unit_spec_at(an, robot, tok))
    elif text in language_keywords():
        md = keyword_doc(text)
    elif text in MEASURES and prev is not None and (prev.kind == "number" or prev.text == ")"):
        kind, word = MEASURES[text]
        md = f"**{text}**: {word} ({kind})"
    else:
        decl = next((d for d in an.decls if d.name == text and (d.robot == robot or d.kind == "robot")), None)
        if decl is not None:
            md = _decl_markdown(an, text, decl.robot, decl.kind)
    return md


def _decl_markdown(an: Analysis, name: str, robot: str | None, kind: str) -> str | None:
    if kind == "robot":
        r = an.model_robot(name)
        seq = f": {r.sequence} ({r.dof} joints)" if r is not None and r.units else ""
        return f"**robot {name}**{seq}"
    for d in an.decls:
        if d.name == name and d.kind == kind and d.robot == robot:
            source = " ".join(an.text[d.range[0] : d.range[1]].split())
            return f"**{kind} {name}** (robot {robot})\n\n```\n{source}\n```"
    return f"**{kind} {name}**"


def _library_markdown(an: Analysis, ref: str, robot: str | None) -> str | None:
    r = an.model_robot(robot)
    lib: Library | None
    if isinstance(r, ResolvedRobot) and r.library_ref == ref.strip('"'):
        lib = r.library  # the robot's own statement: the library the check resolved
    else:
        lib = an.library_ref(ref)  # another block's (a design block's cell): loaded here
    if lib is None:
        return None
    return f"**library {lib.name}** — {lib.description}\n\nunits: {', '.join(lib.unit_names())}; source: {lib.source}"


def _joint_markdown(an: Analysis, robot: str | None, n: int) -> str | None:
    r = an.model_robot(robot)
    # the range needs the library and the unit's variant: a robot whose library did not load, or
    # a unit the library does not know, gets the plain text
    if not isinstance(r, ResolvedRobot) or not 1 <= n <= r.dof or not r.units[n - 1].variant:
        units = an.units_of(robot) if robot else []
        if 1 <= n <= len(units):
            return f"**joint_{n}**: the joint of unit {n} ({units[n - 1][0]})"
        return None
    u = r.units[n - 1]
    lo, hi = r.joint_range(n)
    return (
        f"**joint_{n}**: the joint of unit {n} ({u.name}); range {_g(round(math.degrees(lo), 6))}° … "
        f"{_g(round(math.degrees(hi), 6))}° with limits applied"
    )


def _unit_spec_at(an: Analysis, robot: str | None, tok: Tok):
    r = an.model_robot(robot)
    if r is None:
        return None
    for u in r.units:
        if u.span.file == an.path:
            a, b = an.offsets(u.span)
            if a <= tok.start < b:
                return u
    return None
