"""The module library: a validated data file (docs/conventions.md), never code.

All lengths in metres, masses in kilograms, torques in N·m; fields ending in _deg are degrees.
"""
from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from functools import cache
from pathlib import Path
from typing import Annotated, Literal

from pydantic import AfterValidator, BaseModel, ConfigDict, Field, model_validator

from .. import names
from ..diagnostics import Span
from ..diagnostics.plain_words import plain_words

BUILTIN = {"mark2": "mark2.yaml", "mark2-strict": "mark2-strict.yaml"}


def _rule(problem: Callable[[str], str | None]) -> AfterValidator:
    def check(text: str) -> str:
        why = problem(text)
        if why:
            raise ValueError(why)
        return text
    return AfterValidator(check)


# A library file is input like a .mod file: every string in it reaches outputs (XML, xacro, YAML
# comments, mesh file names), so each obeys one of modc.names' rules.
VariantName = Annotated[str, _rule(names.variant_problem)]
Label = Annotated[str, _rule(names.label_problem)]
Text = Annotated[str, _rule(names.text_problem)]


class _Frozen(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False)


class Actuator(_Frozen):
    model: Text
    mass: float = Field(gt=0, description="kg (paper Table 1)")
    rpm: float = Field(gt=0, description="rated speed, rev/min (paper Table 1)")
    torque_nominal: float = Field(gt=0, description="N·m (paper Table 1)")
    torque_peak: float = Field(gt=0, description="N·m (paper Table 1)")
    epsilon: int = Field(ge=1, description="modules of this kind one module can carry (paper Table 1)")
    diameter: float = Field(gt=0, description="m, housing diameter")
    length: float = Field(gt=0, description="m, housing length along the joint axis")

    @property
    def velocity(self) -> float:
        """Rated speed in rad/s."""
        return self.rpm * 2.0 * math.pi / 60.0


class Part(_Frozen):
    mass: float = Field(gt=0, description="kg")


class Casings(_Frozen):
    input_mass: float = Field(gt=0)
    output_mass: float = Field(gt=0)
    wall: float = Field(gt=0, description="m, casing wall thickness")
    output_thickness: float = Field(gt=0, description="m, output casing (flange) thickness")
    boss_radius: float = Field(gt=0, description="m, radius of the pivotal extension")


class TwistUnit(_Frozen):
    mass: float = Field(gt=0)
    plate: float = Field(gt=0, description="m, base plate thickness")
    cheek_thickness: float = Field(gt=0)
    cheek_width: float = Field(gt=0)


class LinkModule(_Frozen):
    mass_per_length: float = Field(gt=0, description="kg/m of a printed link bar")
    width: float = Field(gt=0, description="m, along y of the joint frame")
    height: float = Field(gt=0, description="m, along z of the joint frame")


class Variant(_Frozen):
    description: Text
    actuator: Actuator
    casings: Casings
    twist_unit: TwistUnit
    link_module: LinkModule
    lower_deg: float = Field(description="joint position limit")
    upper_deg: float

    @model_validator(mode="after")
    def _limits(self):
        if not self.lower_deg < self.upper_deg:
            raise ValueError("lower_deg must be below upper_deg")
        return self


class UnitType(_Frozen):
    """One of the paper's four modular units (section 3.1, eqs. 7-10)."""

    port: Literal["Ip1", "Ip2"]
    link: bool
    x01: float
    z01: float
    z12: float
    x23: float = Field(0.0, description="default link length for units with a link module")


class TwistSet(_Frozen):
    """Realisable twist values: min..max in steps of step (all degrees)."""

    min_deg: float
    max_deg: float
    step_deg: float = Field(gt=0)
    wraps: bool = Field(False, description="angles are taken modulo 360 (ports)")

    def nearest(self, deg: float) -> float:
        if not math.isfinite(deg):
            return self.max_deg if deg > 0 else self.min_deg
        v = _wrap(deg) if self.wraps else deg
        k = round((v - self.min_deg) / self.step_deg)
        top = math.floor((self.max_deg - self.min_deg) / self.step_deg + 1e-9)
        k = min(max(k, 0), top)
        return _clean(self.min_deg + k * self.step_deg)

    def realisable(self, deg: float) -> bool:
        if not math.isfinite(deg):
            return False
        v = _wrap(deg) if self.wraps else deg
        return abs(self.nearest(v) - v) < 1e-6


def _wrap(deg: float) -> float:
    """To (-180, 180]."""
    v = math.fmod(deg, 360.0)
    if v <= -180.0:
        v += 360.0
    elif v > 180.0:
        v -= 360.0
    return v


def _clean(x: float) -> float:
    return 0.0 if abs(x) < 1e-12 else x


class Twists(_Frozen):
    pivot: TwistSet
    port: TwistSet


class Rules(_Frozen):
    """Assembly rules (paper section 3, rules 1-4)."""

    first_variant: VariantName
    last_variant: VariantName
    may_follow: dict[VariantName, list[VariantName]]
    min_dof: int = Field(1, ge=1)
    max_dof: int = Field(ge=1)


class Control(_Frozen):
    p: float = Field(gt=0, description="proportional gain, actuator units (paper section 4.4)")
    i: float = Field(ge=0)
    d: float = Field(ge=0)


class Library(_Frozen):
    name: Label
    description: Text
    source: Text
    variants: dict[VariantName, Variant]
    units: dict[Annotated[int, Field(ge=1, le=99)], UnitType]  # unit type numbers: H1..H4
    twists: Twists
    link_length_min: float = Field(gt=0)
    link_length_max: float = Field(gt=0)
    rules: Rules
    control: Control

    @model_validator(mode="after")
    def _consistent(self):
        for v in (self.rules.first_variant, self.rules.last_variant, *self.rules.may_follow):
            if v not in self.variants:
                raise ValueError(f"rules name variant '{v}' that is not defined")
        for succ in self.rules.may_follow.values():
            for v in succ:
                if v not in self.variants:
                    raise ValueError(f"rules name variant '{v}' that is not defined")
        if not self.units:
            raise ValueError("no unit types defined")
        return self

    def unit_names(self) -> list[str]:
        return [f"{v}{k}" for v in self.variants for k in sorted(self.units)]

    def split(self, name: str) -> tuple[str, int] | None:
        """'H4' -> ('H', 4) if the library defines it."""
        for v in sorted(self.variants, key=len, reverse=True):
            digits = name[len(v):]
            # ASCII and short: int() refuses 4,300+ digits and some Unicode digits ('²')
            if name.startswith(v) and digits.isascii() and digits.isdigit() and len(digits) <= 9:
                k = int(digits)
                if k in self.units:
                    return v, k
        return None


class LibraryError(Exception):
    """A library that cannot be used; span points into the library file when the problem has a
    place there (text is that file, for the caret excerpt), else it is None."""

    def __init__(self, message: str, span: Span | None = None, text: str | None = None):
        super().__init__(message)
        self.span, self.text = span, text


def _node_span(file: str, node) -> Span:
    s, e = node.start_mark, node.end_mark
    if e.line != s.line:  # a block: point at its first line only
        return Span(file, s.line + 1, s.column + 1, s.line + 1, s.column + 2, s.index, s.index + 1)
    end_col, end = max(e.column + 1, s.column + 2), max(e.index, s.index + 1)
    return Span(file, s.line + 1, s.column + 1, e.line + 1, end_col, s.index, end)


def _where(text: str, file: str, loc: tuple) -> Span:
    """Where a validation error's location (pydantic's loc) is in the library's YAML: the value
    when it is a scalar, else its key; the deepest part of loc the file has."""
    import yaml

    try:
        node = yaml.compose(text, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
    except yaml.YAMLError:
        node = None
    if node is None:
        return Span.point(file)
    key = None
    for part in loc:
        if part == "[key]" and key is not None:
            return _node_span(file, key)
        if isinstance(node, yaml.MappingNode):
            hit = next(((k, v) for k, v in node.value if k.value == str(part)), None)
        elif isinstance(node, yaml.SequenceNode) and isinstance(part, int) and 0 <= part < len(node.value):
            hit = (key, node.value[part])
        else:
            hit = None
        if hit is None:
            break
        key, node = hit
    return _node_span(file, node if isinstance(node, yaml.ScalarNode) or key is None else key)


MAX_LIBRARY_BYTES = 1_000_000  # the shipped libraries are 4 kB; a 6 MB one took 30 s and 550 MB


@cache
def _load_path(path: str, mtime: float) -> Library:
    import yaml

    from ..files import read_bounded
    from ..resources import data_dir  # noqa: F401  (keeps import graph obvious)

    try:
        raw, size = read_bounded(path, MAX_LIBRARY_BYTES)
        if size > MAX_LIBRARY_BYTES:
            raise LibraryError(f"the file is too large ({size:,} bytes; the limit is {MAX_LIBRARY_BYTES:,})")
        text = raw.decode("utf-8")
        data = yaml.load(text, Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
    except (OSError, UnicodeDecodeError) as e:
        raise LibraryError(str(e)) from None
    except RecursionError:
        raise LibraryError("the YAML is nested too deeply") from None
    except yaml.YAMLError as e:
        mark = getattr(e, "problem_mark", None) or getattr(e, "context_mark", None)
        span = Span.point(path, mark.line + 1, mark.column + 1, mark.index) if mark else None
        raise LibraryError(f"YAML error: {getattr(e, 'problem', None) or e}", span, text) from None
    from pydantic import ValidationError

    try:
        return Library.model_validate(data)
    except ValidationError as e:
        first = e.errors()[0]
        loc = ".".join(str(p) for p in first["loc"] if p != "[key]")
        message = plain_words(first)
        raise LibraryError(f"{loc}: {message}" if loc else message, _where(text, path, first["loc"]), text) from None


def resolve(ref: str, relative_to: Path | None = None) -> Path | None:
    """A built-in library name or a path (relative to the including file) -> file path."""
    from ..resources import data_dir

    if ref in BUILTIN:
        return data_dir("libraries") / BUILTIN[ref]
    p = Path(ref)
    if not p.is_absolute() and relative_to is not None:
        p = relative_to / p
    return p if p.is_file() else None


@cache
def _builtin(ref: str) -> Library:
    path = resolve(ref)
    assert path is not None, ref  # a built-in library ships with modc
    return _load_path(str(path.resolve()), path.stat().st_mtime)


def load(ref: str = "mark2", relative_to: Path | None = None) -> Library:
    if ref in BUILTIN:  # shipped files do not change while modc runs: no path work per robot
        return _builtin(ref)
    path = resolve(ref, relative_to)
    if path is None:
        raise LibraryError(f"library '{ref}' not found")
    try:
        return _load_path(str(path.resolve()), path.stat().st_mtime)
    except LibraryError as e:  # point at the file as the user named it, not at its resolved path
        if e.span is not None:
            e.span = dataclasses.replace(e.span, file=str(path))
        raise


def default() -> Library:
    return load("mark2")
