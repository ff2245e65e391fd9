"""Frozen AST nodes, each with the source span it came from.

The .mod parser and the YAML reader both produce these; lowering turns them into the model.
Numbers stay as written (value + unit word) here: units are checked while lowering.
"""
from __future__ import annotations

from dataclasses import dataclass

from ..diagnostics import Span


@dataclass(frozen=True, slots=True)
class Quantity:
    value: float
    unit: str | None
    span: Span


@dataclass(frozen=True, slots=True)
class Vector:
    values: tuple[float, ...]
    unit: str | None
    span: Span


@dataclass(frozen=True, slots=True)
class Name:
    text: str
    span: Span


@dataclass(frozen=True, slots=True)
class Param:
    name: Name
    value: Quantity
    span: Span


@dataclass(frozen=True, slots=True)
class Unit:
    name: Name  # e.g. H4
    params: tuple[Param, ...]
    span: Span


@dataclass(frozen=True, slots=True)
class Chain:
    units: tuple[Unit, ...]
    span: Span


@dataclass(frozen=True, slots=True)
class DHRow:
    params: tuple[Param, ...]
    span: Span


@dataclass(frozen=True, slots=True)
class DH:
    """A standard DH table, to be converted into a chain (paper section 4.2)."""

    rows: tuple[DHRow, ...]
    fit_links: bool
    span: Span


@dataclass(frozen=True, slots=True)
class Library:
    ref: str  # built-in name or path (relative to the source file)
    is_path: bool
    span: Span


@dataclass(frozen=True, slots=True)
class Placement:
    """`base …` or `tool …`: a pose given as position and roll-pitch-yaw."""

    keyword: str
    at: Vector | None
    rpy: Vector | None
    span: Span


@dataclass(frozen=True, slots=True)
class Payload:
    mass: Quantity
    at: Vector | None
    span: Span


@dataclass(frozen=True, slots=True)
class Pose:
    name: Name
    values: Vector
    span: Span


@dataclass(frozen=True, slots=True)
class Limit:
    joint: Name
    values: Vector
    span: Span


@dataclass(frozen=True, slots=True)
class Box:
    name: Name
    size: Vector
    at: Vector
    rpy: Vector | None
    span: Span


@dataclass(frozen=True, slots=True)
class Sphere:
    name: Name
    radius: Quantity
    at: Vector
    span: Span


@dataclass(frozen=True, slots=True)
class Cylinder:
    name: Name
    radius: Quantity
    length: Quantity
    at: Vector
    rpy: Vector | None
    span: Span


@dataclass(frozen=True, slots=True)
class Within:
    """`within 5 mm, 2 deg`: a target's position (and orientation) tolerance."""

    position: Quantity
    orientation: Quantity | None
    span: Span


@dataclass(frozen=True, slots=True)
class Target:
    name: Name
    at: Vector
    span: Span
    rpy: Vector | None = None  # tool0's orientation in base_link (URDF fixed axes)
    within: Within | None = None


@dataclass(frozen=True, slots=True)
class Allow:
    codes: tuple[Name, ...]
    span: Span


@dataclass(frozen=True, slots=True)
class Units:
    """`units 1 to 3` (design blocks): bounds on the number of units."""

    low: Quantity
    high: Quantity | None
    span: Span


@dataclass(frozen=True, slots=True)
class Modules:
    """`modules H1, H3, L4` (design blocks): the unit types a chain may use."""

    names: tuple[Name, ...]
    span: Span


@dataclass(frozen=True, slots=True)
class Links:
    """`links 150 mm to 300 mm step 50 mm` (design blocks): link-module lengths to try."""

    low: Quantity
    high: Quantity | None
    step: Quantity | None
    span: Span


@dataclass(frozen=True, slots=True)
class Rank:
    """`rank modules, mass, margin` (design blocks): the order of objectives."""

    keys: tuple[Name, ...]
    span: Span


Statement = Chain | DH | Library | Placement | Payload | Pose | Limit | Box | Sphere | Cylinder | Target | Allow


@dataclass(frozen=True, slots=True)
class Robot:
    name: Name
    body: tuple[Statement, ...]
    span: Span


DesignStatement = (
    Library | Placement | Payload | Box | Sphere | Cylinder | Target | Allow | Units | Modules | Links | Rank
)


@dataclass(frozen=True, slots=True)
class DesignBlock:
    """`design NAME { … }`: a cell and its targets, for `modc design` to find chains for."""

    name: Name
    body: tuple[DesignStatement, ...]
    span: Span


@dataclass(frozen=True, slots=True)
class File:
    path: str
    robots: tuple[Robot, ...]
    designs: tuple[DesignBlock, ...] = ()
