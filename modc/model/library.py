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
from ..diagnostics.plain_words import plain_words
from . import quantities as Q
from .library_file import LIBRARY_KEYS, MAX_LIBRARY_BYTES, LibraryError, read_library, where  # noqa: F401 (re-exported)

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


@dataclasses.dataclass(frozen=True)
class Unit:
    """The unit of a library number (for out-of-range messages)."""

    symbol: str


# Every library number has a range, as .mod quantities do (quantities.LIMIT): nothing beyond it
# is a module, and beyond it arithmetic overflows (a 1e308 kg mass, a 1e-320 kg inertia, a peak
# torque whose servo gain is infinite). Below SMALLEST_LENGTH (0.1 mm) a part's mesh has no
# triangles left; below SMALLEST (a milligram, a millionth of a N·m) a number is a typo.
SMALLEST = 1e-6
SMALLEST_LENGTH = 1e-4
MAX_TORQUE = 1e6  # N·m
MAX_RPM = 1e6
MAX_JOINT_DEG = 3600.0  # ten turns either way
MAX_GAIN = 1e9
MAX_COUNT = 32  # modules per arm (the paper's arms have 1-6)


_LENGTH, _MASS = Q.LIMIT["a length"], Q.LIMIT["a mass"]
Length = Annotated[float, Field(ge=SMALLEST_LENGTH, le=_LENGTH), Unit("m")]
Offset = Annotated[float, Field(ge=-_LENGTH, le=_LENGTH), Unit("m")]
Mass = Annotated[float, Field(ge=SMALLEST, le=_MASS), Unit("kg")]
LinearDensity = Annotated[float, Field(ge=SMALLEST, le=_MASS), Unit("kg/m")]
Torque = Annotated[float, Field(ge=SMALLEST, le=MAX_TORQUE), Unit("N·m")]
Speed = Annotated[float, Field(ge=SMALLEST, le=MAX_RPM), Unit("rev/min")]
JointDeg = Annotated[float, Field(ge=-MAX_JOINT_DEG, le=MAX_JOINT_DEG), Unit("deg")]
TwistDeg = Annotated[float, Field(ge=-360.0, le=360.0), Unit("deg")]
TwistStep = Annotated[float, Field(ge=1.0, le=360.0), Unit("deg")]  # `modc design` enumerates every value
Gain = Annotated[float, Field(ge=0, le=MAX_GAIN), Unit("")]
PositiveGain = Annotated[float, Field(gt=0, le=MAX_GAIN), Unit("")]
Count = Annotated[int, Field(ge=1, le=MAX_COUNT), Unit("")]


class _Frozen(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False)


class Actuator(_Frozen):
    model: Text
    mass: Mass = Field(description="kg (paper Table 1)")
    rpm: Speed = Field(description="rated speed, rev/min (paper Table 1)")
    torque_nominal: Torque = Field(description="N·m (paper Table 1)")
    torque_peak: Torque = Field(description="N·m (paper Table 1)")
    epsilon: Count = Field(description="modules of this kind one module can carry (paper Table 1)")
    diameter: Length = Field(description="m, housing diameter")
    length: Length = Field(description="m, housing length along the joint axis")

    @property
    def velocity(self) -> float:
        """Rated speed in rad/s."""
        return self.rpm * 2.0 * math.pi / 60.0


class Part(_Frozen):
    mass: Mass = Field(description="kg")


class Casings(_Frozen):
    input_mass: Mass
    output_mass: Mass
    wall: Length = Field(description="m, casing wall thickness")
    output_thickness: Length = Field(description="m, output casing (flange) thickness")
    boss_radius: Length = Field(description="m, radius of the pivotal extension")


class TwistUnit(_Frozen):
    mass: Mass
    plate: Length = Field(description="m, base plate thickness")
    cheek_thickness: Length
    cheek_width: Length


class LinkModule(_Frozen):
    mass_per_length: LinearDensity = Field(description="kg/m of a printed link bar")
    width: Length = Field(description="m, along y of the joint frame")
    height: Length = Field(description="m, along z of the joint frame")


class Variant(_Frozen):
    description: Text
    actuator: Actuator
    casings: Casings
    twist_unit: TwistUnit
    link_module: LinkModule
    lower_deg: JointDeg = Field(description="joint position limit")
    upper_deg: JointDeg

    @model_validator(mode="after")
    def _limits(self):
        if not self.lower_deg < self.upper_deg:
            raise ValueError("lower_deg must be below upper_deg")
        return self


class UnitType(_Frozen):
    """One of the paper's four modular units (section 3.1, eqs. 7-10)."""

    port: Literal["Ip1", "Ip2"]
    link: bool
    x01: Offset
    z01: Offset
    z12: Offset
    x23: Offset = Field(0.0, description="default link length for units with a link module")

    @model_validator(mode="after")
    def _link_length(self):
        # a link module is a printed bar: a zero (or underflowed, 1e-400) length has no inertia
        if self.link and not self.x23 >= SMALLEST_LENGTH:
            raise ValueError(f"x23 of a unit with a link module must be at least {SMALLEST_LENGTH * 1000:g} mm")
        return self


class TwistSet(_Frozen):
    """Realisable twist values: min..max in steps of step (all degrees)."""

    min_deg: TwistDeg
    max_deg: TwistDeg
    step_deg: TwistStep
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
    min_dof: Count = 1
    max_dof: Count


class Control(_Frozen):
    p: PositiveGain = Field(description="proportional gain, actuator units (paper section 4.4)")
    i: Gain
    d: Gain


class Library(_Frozen):
    name: Label
    description: Text
    source: Text
    variants: dict[VariantName, Variant]
    units: dict[Annotated[int, Field(ge=1, le=99)], UnitType]  # unit type numbers: H1..H4
    twists: Twists
    link_length_min: Length
    link_length_max: Length
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


def _range_error(err, text: str, path: str) -> LibraryError | None:
    """A number beyond its field's upper bound: out-of-range, as for .mod quantities."""
    ctx = err.get("ctx") or {}
    if err.get("type") != "less_than_equal" or "le" not in ctx:
        return None
    try:  # YAML 1.1 reads 1e308 (no dot) as text, which pydantic takes for a number
        value = float(err.get("input"))
    except (TypeError, ValueError, OverflowError):
        return None
    unit = _unit(err["loc"])
    what = ".".join(str(p) for p in err["loc"])
    fields = {"what": what, "value": f"{value:g}{unit}", "limit": f"{ctx['le']:g}{unit}"}
    message = f"{what} = {fields['value']} is out of range (at most {fields['limit']})"
    return LibraryError(message, where(text, path, err["loc"]), text, "out-of-range", fields)


def _unit(loc: tuple) -> str:
    """' kg' for a location whose field is annotated with Unit('kg'), else ''."""
    cls: object = Library
    info = None
    for part in loc:
        fields = getattr(cls, "model_fields", None)
        if fields is not None and isinstance(part, str) and part in fields:
            info = fields[part]
            cls = info.annotation
        elif getattr(cls, "__origin__", None) is dict:
            cls = cls.__args__[1]  # type: ignore[attr-defined]
        else:
            return ""
    unit = next((m.symbol for m in getattr(info, "metadata", ()) if isinstance(m, Unit)), "")
    return f" {unit}" if unit else ""


@cache
def _load_path(path: str, mtime: float) -> Library:
    from pydantic import ValidationError

    text, data = read_library(path)
    try:
        return Library.model_validate(data)
    except ValidationError as e:
        first = e.errors()[0]
        ranged = _range_error(first, text, path)
        if ranged is not None:
            raise ranged from None
        loc = ".".join(str(p) for p in first["loc"] if p != "[key]")
        message = plain_words(first)
        raise LibraryError(f"{loc}: {message}" if loc else message, where(text, path, first["loc"]), text) from None


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
        raise LibraryError(f"library '{ref}' not found", code="library-not-found")
    try:
        return _load_path(str(path.resolve()), path.stat().st_mtime)
    except LibraryError as e:  # point at the file as the user named it, not at its resolved path
        if e.span is not None:
            e.span = dataclasses.replace(e.span, file=str(path))
        raise


def default() -> Library:
    return load("mark2")
