"""The module library: a validated data file (docs/conventions.md), never code.

All lengths in metres, masses in kilograms, torques in N·m; fields ending in _deg are degrees.
"""
from __future__ import annotations

import math
from collections.abc import Callable
from functools import cache
from pathlib import Path
from typing import Annotated, Any, Literal

from .. import names, records
from ..records import Record
from . import quantities as Q
from .library_file import LIBRARY_KEYS, MAX_LIBRARY_BYTES, LibraryError, read_library, where  # noqa: F401 (re-exported)

BUILTIN = {"mark2": "mark2.yaml", "mark2-strict": "mark2-strict.yaml"}

# The library's types are frozen records (modc.records): a command whose library is in modc's cache
# (modc.model.library_check) builds them from stored values without importing pydantic. Their
# annotations are the schema: pydantic reads them, with the Rule and Bounds below, only when a
# library file is validated.


class Rule:
    """A string field's rule (one of modc.names'): the problem with a text, or None."""

    def __init__(self, problem: Callable[[str], str | None]):
        self.problem = problem

    def __get_pydantic_core_schema__(self, source: Any, handler: Any) -> Any:
        def check(text: str) -> str:
            why = self.problem(text)
            if why:
                raise ValueError(why)
            return text
        return {"type": "function-after", "function": {"type": "no-info", "function": check},
                "schema": handler(source)}


# A library file is input like a .mod file: every string in it reaches outputs (XML, xacro, YAML
# comments, mesh file names), so each obeys one of modc.names' rules.
VariantName = Annotated[str, Rule(names.variant_problem)]
Label = Annotated[str, Rule(names.label_problem)]
Text = Annotated[str, Rule(names.text_problem)]


class Bounds:
    """The range of a library number, and its unit (for out-of-range messages)."""

    def __init__(self, lo: float, hi: float, symbol: str = "", open_lo: bool = False):
        self.lo, self.hi, self.symbol, self.open_lo = lo, hi, symbol, open_lo  # open_lo: lo itself is outside

    def __get_pydantic_core_schema__(self, source: Any, handler: Any) -> Any:
        return {**handler(source), ("gt" if self.open_lo else "ge"): self.lo, "le": self.hi}


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
Length = Annotated[float, Bounds(SMALLEST_LENGTH, _LENGTH, "m")]
Offset = Annotated[float, Bounds(-_LENGTH, _LENGTH, "m")]
Mass = Annotated[float, Bounds(SMALLEST, _MASS, "kg")]
LinearDensity = Annotated[float, Bounds(SMALLEST, _MASS, "kg/m")]
Torque = Annotated[float, Bounds(SMALLEST, MAX_TORQUE, "N·m")]
Speed = Annotated[float, Bounds(SMALLEST, MAX_RPM, "rev/min")]
JointDeg = Annotated[float, Bounds(-MAX_JOINT_DEG, MAX_JOINT_DEG, "deg")]
TwistDeg = Annotated[float, Bounds(-360.0, 360.0, "deg")]
TwistStep = Annotated[float, Bounds(1.0, 360.0, "deg")]  # `modc design` enumerates every value
Gain = Annotated[float, Bounds(0, MAX_GAIN)]
PositiveGain = Annotated[float, Bounds(0, MAX_GAIN, open_lo=True)]
Count = Annotated[int, Bounds(1, MAX_COUNT)]
UnitNumber = Annotated[int, Bounds(1, 99)]  # unit type numbers: H1..H4



class Actuator(Record):
    model: Text
    mass: Mass  # kg (paper Table 1)
    rpm: Speed  # rated speed, rev/min (paper Table 1)
    torque_nominal: Torque  # N·m (paper Table 1)
    torque_peak: Torque  # N·m (paper Table 1)
    epsilon: Count  # modules of this kind one module can carry (paper Table 1)
    diameter: Length  # m, housing diameter
    length: Length  # m, housing length along the joint axis

    @property
    def velocity(self) -> float:
        """Rated speed in rad/s."""
        return self.rpm * 2.0 * math.pi / 60.0


class Part(Record):
    mass: Mass  # kg


class Casings(Record):
    input_mass: Mass
    output_mass: Mass
    wall: Length  # m, casing wall thickness
    output_thickness: Length  # m, output casing (flange) thickness
    boss_radius: Length  # m, radius of the pivotal extension


class TwistUnit(Record):
    mass: Mass
    plate: Length  # m, base plate thickness
    cheek_thickness: Length
    cheek_width: Length


class LinkModule(Record):
    mass_per_length: LinearDensity  # kg/m of a printed link bar
    width: Length  # m, along y of the joint frame
    height: Length  # m, along z of the joint frame


class Variant(Record):
    description: Text
    actuator: Actuator
    casings: Casings
    twist_unit: TwistUnit
    link_module: LinkModule
    lower_deg: JointDeg  # joint position limit
    upper_deg: JointDeg

    def __post_init__(self) -> None:
        if not self.lower_deg < self.upper_deg:
            raise ValueError("lower_deg must be below upper_deg")

    @property
    def joint_range(self) -> tuple[float, float]:
        """The joint's hardware position limits in radians (the file gives degrees): the one
        conversion every check, backend and analysis reads (ResolvedRobot.joint_range narrows it)."""
        import math

        return (math.radians(self.lower_deg), math.radians(self.upper_deg))


class UnitType(Record):
    """One of the paper's four modular units (section 3.1, eqs. 7-10)."""

    port: Literal["Ip1", "Ip2"]
    link: bool
    x01: Offset
    z01: Offset
    z12: Offset
    x23: Offset = 0.0  # default link length for units with a link module

    def __post_init__(self) -> None:
        # a link module is a printed bar: a zero (or underflowed, 1e-400) length has no inertia
        if self.link and not self.x23 >= SMALLEST_LENGTH:
            raise ValueError(f"x23 of a unit with a link module must be at least {SMALLEST_LENGTH * 1000:g} mm")


class TwistSet(Record):
    """Realisable twist values: min..max in steps of step (all degrees)."""

    min_deg: TwistDeg
    max_deg: TwistDeg
    step_deg: TwistStep
    wraps: bool = False  # angles are taken modulo 360 (ports)

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


class Twists(Record):
    pivot: TwistSet
    port: TwistSet


class Rules(Record):
    """Assembly rules (paper section 3, rules 1-4)."""

    first_variant: VariantName
    last_variant: VariantName
    may_follow: dict[VariantName, list[VariantName]]
    min_dof: Count = 1
    max_dof: Count


class Control(Record):
    p: PositiveGain  # proportional gain, actuator units (paper section 4.4)
    i: Gain
    d: Gain


class Library(Record):
    name: Label
    description: Text
    source: Text
    variants: dict[VariantName, Variant]
    units: dict[UnitNumber, UnitType]
    twists: Twists
    link_length_min: Length
    link_length_max: Length
    rules: Rules
    control: Control

    def __post_init__(self) -> None:
        for v in (self.rules.first_variant, self.rules.last_variant, *self.rules.may_follow):
            if v not in self.variants:
                raise ValueError(f"rules name variant '{v}' that is not defined")
        for succ in self.rules.may_follow.values():
            for v in succ:
                if v not in self.variants:
                    raise ValueError(f"rules name variant '{v}' that is not defined")
        if not self.units:
            raise ValueError("no unit types defined")

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


@cache
def _load_path(path: str, mtime: float) -> Library:
    from .library_check import load_file

    return load_file(path)


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
            e.span = records.replace(e.span, file=str(path))
        raise


def default() -> Library:
    return load("mark2")
