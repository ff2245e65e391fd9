"""Lowering: AST -> model. Converts units to SI and reports what is wrong with quantities and
statement structure. Anything needing the module library is left to the passes."""
from __future__ import annotations

import difflib
import math
from pathlib import Path
from typing import Any, Literal

from .. import names
from ..diagnostics import REGISTRY, Diagnostic, codes
from ..syntax import ast
from . import quantities as Q
from .robot import Design, DHRow, JointLimit, Obstacle, Payload, Pose, Problem, Robot, Target, Transform, UnitSpec, Vec3

UNIT_PARAMS = {"pivot": "an angle", "port": "an angle", "link": "a length"}
DH_PARAMS = {"a": "a length", "alpha": "an angle", "d": "a length", "theta": "an angle"}
ONCE = ("chain", "dh", "library", "base", "tool", "payload")


def magnitude_error(values, what: str, span, kind: str | None = None, scale: float = 1.0) -> Diagnostic | None:
    """not-finite or out-of-range for values (in the unit `scale` converts to SI), else None.
    The one range check of every quantity: .mod and YAML text, and DH tables read by dh2mod."""
    if not all(math.isfinite(v) for v in values):
        return codes.NOT_FINITE.at(span, what=what)
    if kind is not None:
        limit = Q.LIMIT[kind]
        worst = max((abs(v * scale) for v in values), default=0.0)
        if worst > limit:
            unit = Q.SI[kind]
            return codes.OUT_OF_RANGE.at(span, what=what, value=f"{worst:g} {unit}", limit=f"{limit:g} {unit}")
    return None


class _Lowerer:
    def __init__(self, diags: list[Diagnostic]):
        self.diags = diags

    def error(self, d: Diagnostic) -> None:
        self.diags.append(d)

    def name(self, n: ast.Name, what: str) -> bool:
        """The one identifier rule (modc.names), for both input forms: the .mod grammar already
        lexes names this way but not their length; the YAML form takes any string."""
        problem = names.identifier_problem(n.text)
        if problem:
            self.error(codes.INVALID_NAME.at(n.span, what=what, name=names.shown(n.text), problem=problem,
                                             rule=names.IDENTIFIER_RULE))
        return problem is None

    def _scale(self, unit: str | None, kind: str, what: str, span) -> float | None:
        table = Q.KINDS[kind]
        if unit is None:
            self.error(codes.MISSING_UNIT.at(span, what=what, example=Q.EXAMPLE[kind]))
            return None
        if unit in table:
            return table[unit]
        if unit in Q.ALL:
            self.error(codes.WRONG_UNIT.at(span, what=what, kind=kind, unit=unit, allowed=", ".join(table)))
        else:
            self.error(codes.UNKNOWN_UNIT_OF_MEASURE.at(span, unit=unit, allowed=", ".join(table)))
        return None

    def _finite(self, values, what, span, kind: str | None = None, scale: float = 1.0) -> bool:
        d = magnitude_error(values, what, span, kind, scale)
        if d is not None:
            self.error(d)
        return d is None

    def quantity(self, q: ast.Quantity, kind: str, what: str) -> float | None:
        s = self._scale(q.unit, kind, what, q.span)
        if s is None or not self._finite([q.value], what, q.span, kind, s):
            return None
        return q.value * s

    def vector(self, v: ast.Vector, kind: str, what: str, n: int | None = 3) -> tuple[float, ...] | None:
        s = self._scale(v.unit, kind, what, v.span)
        if n is not None and len(v.values) != n:
            example = "(" + ", ".join(["0"] * n) + ") " + next(iter(Q.KINDS[kind]))
            self.error(codes.VECTOR_ARITY.at(v.span, what=what, expected=n, got=len(v.values), example=example))
            return None
        if s is None or not self._finite(v.values, what, v.span, kind, s):
            return None
        return tuple(x * s for x in v.values)

    def vec3(self, v: ast.Vector, kind: str, what: str) -> Vec3 | None:
        t = self.vector(v, kind, what)
        return None if t is None else (t[0], t[1], t[2])

    def params(self, params: tuple[ast.Param, ...], allowed: dict[str, str]) -> tuple[dict[str, float], dict]:
        """Named quantities -> SI values (and their spans), reporting unknown and repeated names."""
        values: dict[str, float] = {}
        spans = {}
        for p in params:
            key = p.name.text
            if key not in allowed:
                close = difflib.get_close_matches(key, list(allowed), n=1)
                suggest = f"; did you mean '{close[0]}'?" if close else ""
                self.error(
                    codes.UNKNOWN_PARAMETER.at(p.name.span, name=key, allowed=", ".join(allowed), suggest=suggest)
                )
                continue
            if key in spans:
                self.error(codes.DUPLICATE_PARAMETER.at(p.span, name=key))
                continue
            spans[key] = p.span
            v = self.quantity(p.value, allowed[key], f"'{key}'")
            if v is not None:
                values[key] = v
        return values, spans

    def unit(self, u: ast.Unit) -> UnitSpec | None:
        values, spans = self.params(u.params, UNIT_PARAMS)
        if not self.name(u.name, "unit"):
            return None
        return UnitSpec(name=u.name.text, span=u.span, param_spans=spans, **values)  # type: ignore[arg-type]

    def dh(self, table: ast.DH) -> tuple[DHRow, ...]:
        rows, complete = [], True
        for i, row in enumerate(table.rows, start=1):
            values, spans = self.params(row.params, DH_PARAMS)
            missing = [k for k in ("a", "alpha", "d") if k not in spans]
            if missing:
                self.error(codes.DH_ROW_INCOMPLETE.at(row.span, row=i, missing=" and ".join(missing)))
                complete = False
            elif len(values) == len(spans):
                rows.append(DHRow(span=row.span, **values))
            else:
                complete = False
        if not table.rows:
            self.error(codes.DH_EMPTY.at(table.span))
        # a table with a bad row is not converted: a chain from the other rows would only mislead
        return tuple(rows) if complete else ()

    def placement(self, p: ast.Placement) -> Transform:
        xyz = self.vec3(p.at, "a length", f"{p.keyword} position") if p.at else None
        rpy = self.vec3(p.rpy, "an angle", f"{p.keyword} orientation") if p.rpy else None
        return Transform(xyz=xyz or (0.0, 0.0, 0.0), rpy=rpy or (0.0, 0.0, 0.0))

    def target(self, st: ast.Target) -> Target | None:
        what = f"target '{_say(st.name)}'"
        xyz = self.vec3(st.at, "a length", what)
        rpy = self.vec3(st.rpy, "an angle", f"orientation of {what}") if st.rpy else None
        tol: dict[str, float] = {}
        if st.within is not None:
            w = st.within
            pos = self.quantity(w.position, "a length", f"position tolerance of {what}")
            ang = (
                self.quantity(w.orientation, "an angle", f"orientation tolerance of {what}") if w.orientation else None
            )
            for key, value, q in (
                ("position_tolerance", pos, w.position),
                ("orientation_tolerance", ang, w.orientation),
            ):
                if value is not None and value <= 0 and q is not None:
                    self.error(codes.NONPOSITIVE_SIZE.at(q.span, what=f"the {key.replace('_', ' ')} of {what}",
                                                         value=f"{q.value:g} {q.unit}"))
                elif value is not None:
                    tol[key] = value
        from .lower_task import direction

        pointing = direction(self, st.pointing, f"approach of {what}")
        if not self.name(st.name, "target") or xyz is None or (st.rpy is not None and rpy is None) or \
                (st.pointing is not None and pointing is None):
            return None
        return Target(name=st.name.text, xyz=xyz, rpy=rpy, pointing=pointing, span=st.span, **tol)

    def cell_statement(self, st, block: str, fields: dict, seen: dict, acc: dict) -> None:
        """Statements robots and design blocks share (library, placements, payload, poses,
        limits, obstacles, targets, allow), into fields and the acc lists."""
        kind = {ast.Chain: "chain", ast.DH: "dh", ast.Library: "library", ast.Payload: "payload"}.get(type(st))
        if isinstance(st, ast.Placement):
            kind = st.keyword
        if kind in ONCE:
            if kind in seen:
                self.error(codes.DUPLICATE_STATEMENT.at(st.span, what=kind, block=block))
                return
            seen[kind] = st
        if kind is not None:
            self._robot_field(st, fields, acc)
        else:
            self._cell_item(st, acc)

    def _robot_field(self, st, fields: dict, acc: dict) -> None:
        """A statement that sets one field of the robot: chain, dh, library, placements, payload."""
        match st:
            case ast.Chain():
                units = [self.unit(u) for u in st.units]
                # a chain with a bad unit name is not checked further: the rest would only mislead
                acc["named"] = acc["named"] and None not in units
                fields["units"] = tuple(u for u in units if u is not None)
            case ast.DH():
                fields["dh"] = self.dh(st)
                fields["dh_fit_links"] = st.fit_links
            case ast.Library():
                fields["library_ref"] = st.ref
                fields["library_dir"] = acc["source_dir"] if st.is_path else None
                fields["library_span"] = st.span
            case ast.Placement():
                fields[st.keyword] = self.placement(st)
            case ast.Payload():
                mass = self.quantity(st.mass, "a mass", "payload mass")
                com = self.vec3(st.at, "a length", "payload centre of mass") if st.at else (0.0, 0.0, 0.0)
                if mass is not None and com is not None:
                    fields["payload"] = Payload(mass=mass, com=com, span=st.span)

    def _cell_item(self, st, acc: dict) -> None:
        """A statement that adds to one of the cell's lists: poses, limits, obstacles, targets,
        regions, tasks and paths, base placement, allowed codes."""
        match st:
            case ast.Pose():
                q = self.vector(st.values, "an angle", f"pose '{_say(st.name)}'", n=None)
                if self.name(st.name, "pose") and q is not None:
                    acc["poses"].append(Pose(name=st.name.text, q=q, span=st.span))
            case ast.Limit():
                v = self.vector(st.values, "an angle", f"limit of '{_say(st.joint)}'", n=2)
                if self.name(st.joint, "joint") and v is not None:
                    acc["limits"].append(JointLimit(joint=st.joint.text, lower=v[0], upper=v[1], span=st.span))
            case ast.Box() | ast.Sphere() | ast.Cylinder():
                o = self.obstacle(st)
                if o is not None:
                    acc["obstacles"].append(o)
            case ast.Target():
                t = self.target(st)
                if t is not None:
                    acc["targets"].append(t)
            case ast.Region():
                from .lower_task import region

                reg = region(self, st)
                if reg is not None:
                    acc["regions"].append(reg)
                else:  # reported already: tasks naming it are not reported again
                    acc["bad_regions"].add(st.name.text)
            case ast.Task() | ast.StraightPath():
                acc["task_statements"].append(st)  # resolved once every target and region is known
            case ast.BaseWithin():
                acc["base_within"].append(st)
            case ast.Allow():
                for c in st.codes:
                    if c.text in REGISTRY and REGISTRY[c.text].allowable:
                        acc["allow"].add(c.text)
                    else:
                        allowable = ", ".join(sorted(k for k, v in REGISTRY.items() if v.allowable))
                        self.error(codes.UNKNOWN_ALLOW.at(c.span, name=_say(c), allowable=allowable))

    @staticmethod
    def _acc(source_dir: str | None) -> dict:
        return {"poses": [], "limits": [], "obstacles": [], "targets": [], "allow": set(), "source_dir": source_dir,
                "named": True, "regions": [], "task_statements": [], "base_within": [],
                "bad_regions": set()}

    @staticmethod
    def _lists(acc: dict) -> dict:
        return {"poses": tuple(acc["poses"]), "limits": tuple(acc["limits"]), "obstacles": tuple(acc["obstacles"]),
                "targets": tuple(acc["targets"]), "allow": frozenset(acc["allow"]),
                "regions": tuple(acc["regions"]), "tasks": acc["tasks"], "paths": acc["paths"]}

    def _tasks(self, acc: dict, block: str) -> None:
        from .lower_task import tasks

        acc["tasks"], acc["paths"] = tasks(self, acc["task_statements"], acc["targets"], acc["regions"], block,
                                          acc["bad_regions"])

    def robot(self, r: ast.Robot, source_dir: str | None) -> Robot | None:
        """The robot, or None when its name or a unit's is invalid (its statements are still checked)."""
        named = self.name(r.name, "robot")
        rname = _say(r.name)
        fields: dict = {}
        seen: dict[str, Any] = {}
        acc = self._acc(source_dir)
        for st in r.body:
            self.cell_statement(st, f"robot '{rname}'", fields, seen, acc)
        self._tasks(acc, f"robot '{rname}'")
        for st in acc["base_within"]:
            self.error(codes.BASE_WITHIN_ROBOT.at(st.span, robot=rname))
        if "chain" in seen and "dh" in seen:
            self.error(codes.CHAIN_AND_DH.at(seen["dh"].span, robot=rname))
            fields.pop("dh")
        elif "chain" not in seen and "dh" not in seen:
            self.error(codes.MISSING_CHAIN.at(r.name.span, robot=rname))
        if not (named and acc["named"]):
            return None
        return Robot(name=r.name.text, span=r.span, name_span=r.name.span, **self._lists(acc), **fields)

    def problem(self, d: ast.DesignBlock, source_dir: str | None) -> Problem | None:
        """The design problem, or None when its name is invalid (its statements are still checked)."""
        from .problem_bounds import lower_bounds

        named = self.name(d.name, "design")
        block = f"design '{_say(d.name)}'"  # as duplicate messages name the block
        fields: dict = {}
        seen: dict[str, object] = {}
        acc = self._acc(source_dir)
        search: list = []
        compare: list[ast.Compare] = []
        for st in d.body:
            if isinstance(st, ast.Units | ast.Modules | ast.Links | ast.Rank):
                search.append(st)
            elif isinstance(st, ast.Compare):
                compare.append(st)
            else:
                self.cell_statement(st, block, fields, seen, acc)
        if not acc["targets"] and not any(isinstance(st, ast.Target | ast.Region) for st in d.body):
            self.error(codes.DESIGN_NO_TARGETS.at(d.name.span, name=_say(d.name)))
        bounds = lower_bounds(self, search, block)
        self._tasks(acc, block)
        self._task_objectives(bounds, acc, _say(d.name))
        if len(acc["base_within"]) > 1:
            self.error(codes.DUPLICATE_STATEMENT.at(acc["base_within"][1].span, what="base within", block=block))
        elif acc["base_within"]:
            from .lower_task import base_grid

            bounds["base_grid"] = base_grid(self, acc["base_within"][0])
        if not (named and acc["named"]):
            return None
        cell = Robot(name=d.name.text, span=d.span, name_span=d.name.span, **self._lists(acc), **fields)
        reference = self._reference(compare, cell, block)
        if reference is False:
            return None
        bounds["reference"] = reference
        return Problem(name=d.name.text, cell=cell, span=d.span, name_span=d.name.span, **bounds)

    def _task_objectives(self, bounds: dict, acc: dict, name: str) -> None:
        """An objective measured on the cell's tasks (cycle time, energy) needs one to measure."""
        from ..objectives import REGISTRY

        if acc["task_statements"]:
            return
        for key in bounds.get("rank", ()):
            span = bounds["bound_spans"].get(f"rank:{key}")
            if REGISTRY[key].needs_task and span is not None:
                static = ", ".join(k for k, o in REGISTRY.items() if not o.task)
                self.error(codes.OBJECTIVE_NEEDS_TASK.at(span, name=key, block=name, static=static))

    def _reference(self, compare: list[ast.Compare], cell: Robot, block: str) -> Robot | None | bool:
        """`compare with chain …`: the cell with that chain (its checks are the robot chain's,
        once the library is known: modc.passes.check_problems); False when a unit name is invalid."""
        for st in compare[1:]:
            self.error(codes.DUPLICATE_STATEMENT.at(st.span, what="compare with", block=block))
        if not compare:
            return None
        units = [self.unit(u) for u in compare[0].chain.units]
        if None in units:
            return False
        return cell.model_copy(update={"name": "reference", "units": tuple(u for u in units if u is not None),
                                       "span": compare[0].span, "name_span": compare[0].chain.span})

    def obstacle(self, st) -> Obstacle | None:
        name = _say(st.name)
        at = self.vec3(st.at, "a length", f"position of '{name}'")
        rpy = (
            self.vec3(st.rpy, "an angle", f"orientation of '{name}'") if getattr(st, "rpy", None) else (0.0, 0.0, 0.0)
        )
        match st:
            case ast.Box():
                size: tuple[float, ...] | None = self.vec3(st.size, "a length", f"size of box '{name}'")
                shape: Literal["box", "sphere", "cylinder"] = "box"
            case ast.Sphere():
                r = self.quantity(st.radius, "a length", f"radius of sphere '{name}'")
                size, shape = (None if r is None else (r,)), "sphere"
            case ast.Cylinder():
                r = self.quantity(st.radius, "a length", f"radius of cylinder '{name}'")
                h = self.quantity(st.length, "a length", f"length of cylinder '{name}'")
                size, shape = (None if r is None or h is None else (r, h)), "cylinder"
        if not self.name(st.name, shape) or at is None or rpy is None or size is None:
            return None
        return Obstacle(name=st.name.text, shape=shape, size=size, origin=Transform(xyz=at, rpy=rpy), span=st.span)


def _say(n: ast.Name) -> str:
    """A name as messages quote it: as written when valid, else escaped and cut short."""
    return n.text if names.identifier_problem(n.text) is None else names.shown(n.text)


def lower(file: ast.File, diags: list[Diagnostic]) -> Design:
    source_dir = str(Path(file.path).parent) if not file.path.startswith("<") else None
    low = _Lowerer(diags)
    robots = (low.robot(r, source_dir) for r in file.robots)
    problems = (low.problem(d, source_dir) for d in file.designs)
    return Design(path=file.path, robots=tuple(r for r in robots if r is not None),
                  problems=tuple(p for p in problems if p is not None))
