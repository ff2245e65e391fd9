"""Frozen AST nodes, each with the source span it came from.

The .mod parser and the YAML reader both produce these; lowering turns them into the model.
Numbers stay as written (value + unit word) here: units are checked while lowering.
"""
from __future__ import annotations

from ..diagnostics import Span
from ..records import Record


class Quantity(Record, kw_only=False):
    value: float
    unit: str | None
    span: Span


class Vector(Record, kw_only=False):
    values: tuple[float, ...]
    unit: str | None
    span: Span


class Name(Record, kw_only=False):
    text: str
    span: Span


class Param(Record, kw_only=False):
    name: Name
    value: Quantity
    span: Span


class Unit(Record, kw_only=False):
    name: Name  # e.g. H4
    params: tuple[Param, ...]
    span: Span


class Chain(Record, kw_only=False):
    units: tuple[Unit, ...]
    span: Span


class DHRow(Record, kw_only=False):
    params: tuple[Param, ...]
    span: Span


class DH(Record, kw_only=False):
    """A standard DH table, to be converted into a chain (paper section 4.2)."""

    rows: tuple[DHRow, ...]
    fit_links: bool
    span: Span


class Library(Record, kw_only=False):
    ref: str  # built-in name or path (relative to the source file)
    is_path: bool
    span: Span


class Placement(Record, kw_only=False):
    """`base …` or `tool …`: a pose given as position and roll-pitch-yaw."""

    keyword: str
    at: Vector | None
    rpy: Vector | None
    span: Span


class Payload(Record, kw_only=False):
    mass: Quantity
    at: Vector | None
    span: Span


class Pose(Record, kw_only=False):
    name: Name
    values: Vector
    span: Span


class Limit(Record, kw_only=False):
    joint: Name
    values: Vector
    span: Span


class Box(Record, kw_only=False):
    name: Name
    size: Vector
    at: Vector
    rpy: Vector | None
    span: Span


class Sphere(Record, kw_only=False):
    name: Name
    radius: Quantity
    at: Vector
    span: Span


class Cylinder(Record, kw_only=False):
    name: Name
    radius: Quantity
    length: Quantity
    at: Vector
    rpy: Vector | None
    span: Span


class Within(Record, kw_only=False):
    """`within 5 mm, 2 deg`: a target's position (and orientation) tolerance."""

    position: Quantity
    orientation: Quantity | None
    span: Span


class Target(Record, kw_only=False):
    name: Name
    at: Vector
    span: Span
    rpy: Vector | None = None  # tool0's orientation in base_link (URDF fixed axes)
    within: Within | None = None
    pointing: Vector | None = None  # tool0's x axis (the approach) only, a direction in base_link


class Allow(Record, kw_only=False):
    codes: tuple[Name, ...]
    span: Span


class Units(Record, kw_only=False):
    """`units 1 to 3` (design blocks): bounds on the number of units."""

    low: Quantity
    high: Quantity | None
    span: Span


class Modules(Record, kw_only=False):
    """`modules H1, H3, L4` (design blocks): the unit types a chain may use."""

    names: tuple[Name, ...]
    span: Span


class Links(Record, kw_only=False):
    """`links 150 mm to 300 mm step 50 mm` (design blocks): link-module lengths to try."""

    low: Quantity
    high: Quantity | None
    step: Quantity | None
    span: Span


class Rank(Record, kw_only=False):
    """`rank modules, mass, margin` (design blocks): the order of objectives."""

    keys: tuple[Name, ...]
    span: Span


class Compare(Record, kw_only=False):
    """`compare with chain H1 - L4(…) - L3` (design blocks): a reference arm, evaluated on the cell
    with the ranking's own checks and shown beside the designs found."""

    chain: Chain
    span: Span


class PointRef(Record, kw_only=False):
    """A target or region named in a task or path: `plant`, `tray`, `tray[1,0,0]` (index 0-based)."""

    name: Name
    index: tuple[Quantity, Quantity, Quantity] | None
    span: Span

    @property
    def text(self) -> str:
        if self.index is None:
            return self.name.text
        return self.name.text + "[" + ",".join(f"{q.value:g}" for q in self.index) + "]"


class Region(Record, kw_only=False):
    """`region tray box size (…) m at (…) m [turned (…) deg] grid 3 x 2 x 1 [rpy …] [within …]`: a grid of targets."""

    name: Name
    size: Vector
    at: Vector
    grid: tuple[Quantity, Quantity, Quantity]
    span: Span
    rpy: Vector | None = None
    within: Within | None = None
    pointing: Vector | None = None  # as a target's
    turned: Vector | None = None  # the box's own orientation (fixed-axis rpy), as an obstacle's


class Task(Record, kw_only=False):
    """`task serve { visit plant, tray, plant }`: joint-space motions through the targets in order."""

    name: Name
    visits: tuple[PointRef, ...]
    span: Span


class StraightPath(Record, kw_only=False):
    """`path seam from a to b straight`: tool0 along the segment a -> b."""

    name: Name
    start: PointRef
    end: PointRef
    span: Span


class Range(Record, kw_only=False):
    """`yaw 0 to 90 deg step 45 deg`: an evenly stepped range (the low end may share the high's unit)."""

    low: Quantity
    high: Quantity
    step: Quantity
    span: Span


class BaseWithin(Record, kw_only=False):
    """`base within box size (…) m at (…) m step 50 mm [yaw …]` (design blocks): the base's grid."""

    size: Vector
    at: Vector
    step: Quantity
    span: Span
    yaw: Range | None = None


TaskStatement = Region | Task | StraightPath | BaseWithin

Statement = (
    Chain | DH | Library | Placement | Payload | Pose | Limit | Box | Sphere | Cylinder | Target | Allow | TaskStatement
)


class Robot(Record, kw_only=False):
    name: Name
    body: tuple[Statement, ...]
    span: Span


DesignStatement = (
    Library | Placement | Payload | Box | Sphere | Cylinder | Target | Allow | Units | Modules | Links | Rank
    | Compare | TaskStatement
)


class DesignBlock(Record, kw_only=False):
    """`design NAME { … }`: a cell and its targets, for `modc design` to find chains for."""

    name: Name
    body: tuple[DesignStatement, ...]
    span: Span


class File(Record, kw_only=False):
    path: str
    robots: tuple[Robot, ...]
    designs: tuple[DesignBlock, ...] = ()
