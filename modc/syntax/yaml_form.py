"""Read the YAML form into the same AST as .mod text, keeping YAML line/column spans."""
from __future__ import annotations

from ..diagnostics import Diagnostic, Span, codes
from ..diagnostics.plain_words import plain_words
from . import ast
from .parser import too_large


def _span(file: str, node) -> Span:
    s, e = node.start_mark, node.end_mark
    return Span(file, s.line + 1, s.column + 1, e.line + 1, max(e.column + 1, s.column + 2), s.index, e.index)


class _Unsupported(Exception):
    def __init__(self, node, detail: str, code=codes.YAML_SCHEMA):
        super().__init__(detail)
        self.node, self.detail, self.code = node, detail, code


def _plain(node, path: tuple, spans: dict, file: str, seen: set | None = None):
    """YAML node -> Python data, recording each value's span by its path. Anchors/aliases are
    refused (a recursive alias never ends, nested ones grow exponentially), as are non-scalar keys
    and a key given twice in one mapping (YAML forbids it; PyYAML would keep the last silently, as
    a repeated .mod statement is refused)."""
    import yaml

    seen = set() if seen is None else seen
    if isinstance(node, (yaml.MappingNode, yaml.SequenceNode)):
        if id(node) in seen:
            raise _Unsupported(node, "anchors and aliases (&name, *name) are not supported; write the value out")
        seen.add(id(node))
    spans[path] = _span(file, node)
    if isinstance(node, yaml.MappingNode):
        out = {}
        for k, v in node.value:
            if not isinstance(k, yaml.ScalarNode):
                raise _Unsupported(k, "mapping keys must be plain names")
            key = k.value
            if key in out:
                from ..names import shown

                first = spans[path + (key, "__key__")].line
                raise _Unsupported(k, f"key '{shown(key)}' is given twice in one mapping (first on line {first})",
                                   codes.YAML_SYNTAX)
            spans[path + (key, "__key__")] = _span(file, k)
            out[key] = _plain(v, path + (key,), spans, file, seen)
        return out
    if isinstance(node, yaml.SequenceNode):
        return [_plain(v, path + (i,), spans, file, seen) for i, v in enumerate(node.value)]
    value = node.value
    if node.tag.endswith(":int") or node.tag.endswith(":float"):
        try:
            return float(value)
        except ValueError:
            return value
    if node.tag.endswith(":null"):
        return None
    return value


class _Reader:
    def __init__(self, file: str, spans: dict, diags: list[Diagnostic]):
        self.file, self.spans, self.diags = file, spans, diags

    def span(self, path: tuple) -> Span:
        while path not in self.spans and path:
            path = path[:-1]
        return self.spans.get(path, Span.point(self.file))

    def _sub(self, rule: str, text, path: tuple):
        """Parse one .mod fragment (a unit, quantity or vector) written in a YAML scalar."""
        from lark.exceptions import UnexpectedInput

        from .parser import _lark
        from .transform import ToAst

        span = self.span(path)
        if isinstance(text, float):
            return ast.Quantity(text, None, span) if rule == "quantity_text" else ast.Vector((text,), None, span)
        try:
            tree = _lark().parse(str(text), start=rule)
        except UnexpectedInput:
            what = {
                "unit_text": "a unit such as H4(pivot=-90deg)",
                "quantity_text": "a number with a unit such as 45deg",
                "vector_text": "a vector such as (0.3, 0, 0.25) m",
            }[rule]
            self.diags.append(codes.YAML_SCHEMA.at(span, detail=f"{_dotted(path)}: expected {what}, got {text!r}"))
            return None
        node = ToAst(self.file).transform(tree).children[0]
        return _respan(node, span)

    def robot(self, r, path: tuple) -> ast.Robot:
        body: list = [self._chain(r.chain, path + ("chain",))]
        body += self._cell(r, path)
        for name, text in r.poses.items():
            v = self._vec(text, path + ("poses", name))
            if v is not None:
                body.append(
                    ast.Pose(
                        ast.Name(name, self.span(path + ("poses", name, "__key__"))),
                        v,
                        self.span(path + ("poses", name)),
                    )
                )
        for name, text in r.limits.items():
            v = self._vec(text, path + ("limits", name))
            if v is not None:
                body.append(
                    ast.Limit(
                        ast.Name(name, self.span(path + ("limits", name, "__key__"))),
                        v,
                        self.span(path + ("limits", name)),
                    )
                )
        return ast.Robot(ast.Name(r.name, self.span(path + ("name",))), tuple(body), self.span(path))

    def design(self, d, path: tuple) -> ast.DesignBlock:
        body = self._cell(d, path)
        if d.units is not None:
            p = path + ("units",)
            parts = [x.strip() for x in str(d.units).split(" to ")] if isinstance(d.units, str) else [str(d.units)]
            nums = [self._count(x, p) for x in parts[:2]]
            if all(n is not None for n in nums):
                body.append(ast.Units(nums[0], nums[1] if len(nums) > 1 else None, self.span(p)))
        if d.modules is not None:
            p = path + ("modules",)
            body.append(
                ast.Modules(tuple(ast.Name(m, self.span(p + (i,))) for i, m in enumerate(d.modules)), self.span(p))
            )
        if d.links is not None:
            p = path + ("links",)
            import re

            parts = re.split(r"\s+(?:to|step)\s+", d.links)
            qs = [self._sub("quantity_text", x, p) for x in parts[:3]]
            if all(q is not None for q in qs):
                qs += [None] * (3 - len(qs))
                body.append(ast.Links(qs[0], qs[1], qs[2], self.span(p)))
        if d.base_within is not None:
            bw = self._base_within(d.base_within, path + ("base_within",))
            if bw is not None:
                body.append(bw)
        if d.rank is not None:
            p = path + ("rank",)
            body.append(ast.Rank(tuple(ast.Name(k, self.span(p + (i,))) for i, k in enumerate(d.rank)), self.span(p)))
        if d.compare_with is not None:
            p = path + ("compare_with",)
            body.append(ast.Compare(self._chain(d.compare_with, p), self.span(p)))
        return ast.DesignBlock(ast.Name(d.name, self.span(path + ("name",))), tuple(body), self.span(path))

    def _count(self, text: str, path: tuple):
        try:
            return ast.Quantity(float(text), None, self.span(path))
        except ValueError:
            self.diags.append(
                codes.YAML_SCHEMA.at(
                    self.span(path),
                    detail=f'{_dotted(path)}: expected a number of units such as 3 or "2 to 4", got {text!r}',
                )
            )
            return None

    def _target(self, name: str, value, p: tuple):
        from .document import TargetDoc

        key = ast.Name(name, self.span(p + ("__key__",)))
        if not isinstance(value, TargetDoc):
            v = self._vec(value, p)
            return None if v is None else ast.Target(key, v, self.span(p))
        at, rpy = self._vec(value.at, p + ("at",)), self._vec(value.rpy, p + ("rpy",))
        within = None
        if value.within is not None:
            qs = [self._sub("quantity_text", x.strip(), p + ("within",)) for x in value.within.split(",")[:2]]
            if all(q is not None for q in qs):
                within = ast.Within(qs[0], qs[1] if len(qs) > 1 else None, self.span(p + ("within",)))
        pointing = self._vec(value.pointing, p + ("pointing",))
        if value.rpy is not None and value.pointing is not None:
            self.diags.append(codes.YAML_SCHEMA.at(self.span(p), detail=f"{_dotted(p)}: rpy or pointing, not both"))
            return None
        if at is None or (value.rpy is not None and rpy is None) or (value.pointing is not None and pointing is None):
            return None
        return ast.Target(key, at, self.span(p), rpy, within, pointing)

    def _chain(self, items, path: tuple) -> ast.Chain:
        units = []
        for i, item in enumerate(items):
            p = path + (i,)
            if isinstance(item, str):
                u = self._sub("unit_text", item, p)
            else:
                params = []
                for key in ("pivot", "port", "link"):
                    val = getattr(item, key)
                    if val is not None:
                        q = self._sub("quantity_text", val, p + (key,))
                        if q is not None:
                            params.append(
                                ast.Param(ast.Name(key, self.span(p + (key, "__key__"))), q, self.span(p + (key,)))
                            )
                u = ast.Unit(ast.Name(item.unit, self.span(p + ("unit",))), tuple(params), self.span(p))
            if u is not None:
                units.append(u)
        return ast.Chain(tuple(units), self.span(path))

    def _cell(self, r, path: tuple) -> list:
        """Statements robots and designs share: library, placements, payload, obstacles, targets, allow."""
        body: list = []
        if r.library is not None:
            is_path = r.library.endswith((".yaml", ".yml")) or "/" in r.library
            body.append(ast.Library(r.library, is_path, self.span(path + ("library",))))
        for key in ("base", "tool"):
            pl = getattr(r, key)
            if pl is not None:
                at = self._vec(pl.at, path + (key, "at"))
                rpy = self._vec(pl.rpy, path + (key, "rpy"))
                body.append(ast.Placement(key, at, rpy, self.span(path + (key,))))
        if r.payload is not None:
            m = self._sub("quantity_text", r.payload.mass, path + ("payload", "mass"))
            if m is not None:
                body.append(
                    ast.Payload(m, self._vec(r.payload.at, path + ("payload", "at")), self.span(path + ("payload",)))
                )
        for i, o in enumerate(r.obstacles):
            body.extend(self._obstacle(o, path + ("obstacles", i)))
        for name, value in r.targets.items():
            t = self._target(name, value, path + ("targets", name))
            if t is not None:
                body.append(t)
        if r.allow:
            names = tuple(ast.Name(c, self.span(path + ("allow", i))) for i, c in enumerate(r.allow))
            body.append(ast.Allow(names, self.span(path + ("allow",))))
        body += self._tasks(r, path)
        return body

    def _tasks(self, r, path: tuple) -> list:
        """regions, tasks and paths, as the .mod statements."""
        body: list = []
        for name, reg in r.regions.items():
            p = path + ("regions", name)
            size, at = self._vec(reg.size, p + ("size",)), self._vec(reg.at, p + ("at",))
            rpy = self._vec(reg.rpy, p + ("rpy",))
            grid = self._grid(reg.grid, p + ("grid",))
            within = self._within(reg.within, p + ("within",))
            pointing = self._vec(reg.pointing, p + ("pointing",))
            turned = self._vec(reg.turned, p + ("turned",))
            if reg.rpy is not None and reg.pointing is not None:
                self.diags.append(codes.YAML_SCHEMA.at(self.span(p), detail=f"{_dotted(p)}: rpy or pointing, not both"))
                continue
            given = (reg.rpy, rpy), (reg.pointing, pointing), (reg.turned, turned)
            if size is not None and at is not None and grid is not None and all(v is None or a is not None
                                                                                 for v, a in given):
                body.append(ast.Region(ast.Name(name, self.span(p + ("__key__",))), size, at, grid, self.span(p), rpy,
                                       within, pointing, turned))
        for name, visits in r.tasks.items():
            p = path + ("tasks", name)
            refs = [self._ref(v, p + (i,)) for i, v in enumerate(visits)]
            if not visits:
                self.diags.append(codes.YAML_SCHEMA.at(self.span(p), detail=f"{_dotted(p)}: list the targets to visit"))
            elif None not in refs:
                body.append(ast.Task(ast.Name(name, self.span(p + ("__key__",))), tuple(refs), self.span(p)))
        for name, doc in r.paths.items():
            p = path + ("paths", name)
            a, b = self._ref(doc.start, p + ("from",)), self._ref(doc.to, p + ("to",))
            if not doc.straight:
                self.diags.append(codes.YAML_SCHEMA.at(self.span(p + ("straight",)),
                                                       detail=f"{_dotted(p)}: only straight paths are supported"))
            elif a is not None and b is not None:
                body.append(ast.StraightPath(ast.Name(name, self.span(p + ("__key__",))), a, b, self.span(p)))
        return body

    def _within(self, text, p: tuple):
        if text is None:
            return None
        qs = [self._sub("quantity_text", x.strip(), p) for x in str(text).split(",")[:2]]
        if any(q is None for q in qs):
            return None
        return ast.Within(qs[0], qs[1] if len(qs) > 1 else None, self.span(p))

    def _grid(self, grid, p: tuple):
        import re

        parts = [float(v) for v in grid] if isinstance(grid, list) else None
        if parts is None:
            m = re.fullmatch(r"\s*(\S+)\s*x\s*(\S+)\s*x\s*(\S+)\s*", str(grid))
            try:
                parts = [float(v) for v in m.groups()] if m else None
            except ValueError:
                parts = None
        if parts is None or len(parts) != 3:
            self.diags.append(codes.YAML_SCHEMA.at(self.span(p), detail=f'{_dotted(p)}: expected "NX x NY x NZ" such '
                                                                        f"as \"3 x 2 x 1\", got {grid!r}"))
            return None
        span = self.span(p)
        return (ast.Quantity(parts[0], None, span), ast.Quantity(parts[1], None, span),
                ast.Quantity(parts[2], None, span))

    def _ref(self, text, p: tuple):
        """A target or region point: `plant`, `tray`, `tray[1,0,0]`."""
        import re

        span = self.span(p)
        m = re.fullmatch(r"([^\[\]\s]+)(?:\[\s*(\d+)\s*,\s*(\d+)\s*,\s*(\d+)\s*\])?", str(text).strip())
        if m is None:
            self.diags.append(codes.YAML_SCHEMA.at(span, detail=f"{_dotted(p)}: expected a target or region point "
                                                                f"such as tray[1,0,0], got {text!r}"))
            return None
        index = None
        if m.group(2) is not None:
            v = [ast.Quantity(float(m.group(i)), None, span) for i in (2, 3, 4)]
            index = (v[0], v[1], v[2])
        return ast.PointRef(ast.Name(m.group(1), span), index, span)

    def _base_within(self, doc, p: tuple):
        size, at = self._vec(doc.size, p + ("size",)), self._vec(doc.at, p + ("at",))
        step = self._sub("quantity_text", doc.step, p + ("step",))
        yaw = None
        if doc.yaw is not None:
            import re

            parts = re.split(r"\s+(?:to|step)\s+", str(doc.yaw).strip())
            qs = [self._sub("quantity_text", x, p + ("yaw",)) for x in parts] if len(parts) == 3 else None
            if qs is None:
                self.diags.append(codes.YAML_SCHEMA.at(self.span(p + ("yaw",)), detail=f"{_dotted(p + ('yaw',))}: "
                                                       f'expected "LOW to HIGH step STEP" such as "0 to 90 deg step '
                                                       f'45 deg", got {doc.yaw!r}'))
                return None
            if any(q is None for q in qs):
                return None
            yaw = ast.Range(qs[0], qs[1], qs[2], self.span(p + ("yaw",)))
        if size is None or at is None or step is None:
            return None
        return ast.BaseWithin(size, at, step, self.span(p), yaw)

    def _vec(self, text, path):
        return None if text is None else self._sub("vector_text", text, path)

    def _obstacle(self, o, p):
        from .document import BoxDoc, SphereDoc

        at = self._vec(o.at, p + ("at",))
        rpy = self._vec(getattr(o, "rpy", None), p + ("rpy",))
        if isinstance(o, BoxDoc):
            size = self._vec(o.size, p + ("size",))
            if at is not None and size is not None:
                yield ast.Box(ast.Name(o.box, self.span(p + ("box",))), size, at, rpy, self.span(p))
        elif isinstance(o, SphereDoc):
            r = self._sub("quantity_text", o.radius, p + ("radius",))
            if at is not None and r is not None:
                yield ast.Sphere(ast.Name(o.sphere, self.span(p + ("sphere",))), r, at, self.span(p))
        else:
            r = self._sub("quantity_text", o.radius, p + ("radius",))
            h = self._sub("quantity_text", o.length, p + ("length",))
            if at is not None and r is not None and h is not None:
                yield ast.Cylinder(ast.Name(o.cylinder, self.span(p + ("cylinder",))), r, h, at, rpy, self.span(p))


def _dotted(path: tuple) -> str:
    return ".".join(str(p) for p in path if p != "__key__") or "document"


def _respan(node, span: Span):
    """Fragments were parsed out of context: point all their spans at the YAML scalar."""
    from ..records import Record, fields, replace

    changes: dict[str, object] = {}
    for name in fields(node):
        v = getattr(node, name)
        if isinstance(v, Span):
            changes[name] = span
        elif isinstance(v, Record):
            changes[name] = _respan(v, span)
        elif isinstance(v, tuple) and v and isinstance(v[0], Record):
            changes[name] = tuple(_respan(x, span) for x in v)
    return replace(node, **changes)


def parse_yaml(text: str, file: str) -> tuple[ast.File, list[Diagnostic]]:
    import yaml
    from pydantic import ValidationError

    from .document import Document

    diags: list[Diagnostic] = []
    big = too_large(text, file)
    if big is not None:
        return ast.File(file, ()), [big]
    try:
        node = yaml.compose(text, Loader=yaml.SafeLoader)
    except RecursionError:  # nesting hundreds deep: PyYAML composes recursively
        detail = "nested hundreds of levels deep (a robot file needs five)"
        diags.append(codes.YAML_SYNTAX.at(Span.point(file), detail=detail))
        return ast.File(file, ()), diags
    except yaml.YAMLError as e:
        mark = getattr(e, "problem_mark", None) or getattr(e, "context_mark", None)
        line, col = (mark.line + 1, mark.column + 1) if mark else (1, 1)
        detail = getattr(e, "problem", None) or str(e).splitlines()[0]
        index = mark.index if mark else 0
        diags.append(codes.YAML_SYNTAX.at(Span(file, line, col, line, col + 1, index, index + 1), detail=detail))
        return ast.File(file, ()), diags
    if node is None:
        diags.append(codes.EMPTY_FILE.at(Span.point(file)))
        return ast.File(file, ()), diags
    spans: dict = {}
    try:
        data = _plain(node, (), spans, file)
    except _Unsupported as e:
        diags.append(e.code.at(_span(file, e.node), detail=e.detail))
        return ast.File(file, ()), diags
    try:
        doc = Document.model_validate(data)
    except ValidationError as e:
        seen = set()
        for err in e.errors():
            loc = tuple(p for p in err["loc"] if not (isinstance(p, str) and p[:1].isupper() or p in ("str", "float")))
            key = (loc, err["msg"])
            if key in seen:
                continue
            seen.add(key)
            reader = _Reader(file, spans, diags)
            diags.append(codes.YAML_SCHEMA.at(reader.span(loc), detail=f"{_dotted(loc)}: {plain_words(err)}"))
        return ast.File(file, ()), diags
    reader = _Reader(file, spans, diags)
    robots = tuple(reader.robot(r, ("robots", i)) for i, r in enumerate(doc.robots))
    designs = tuple(reader.design(d, ("designs", i)) for i, d in enumerate(doc.designs))
    if not robots and not designs:
        diags.append(codes.EMPTY_FILE.at(Span.point(file)))
    return ast.File(file, robots, designs), diags
