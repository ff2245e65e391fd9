"""The YAML form of a .mod file: its structure as pydantic models, and the JSON Schema.

Quantities are strings written exactly as in .mod ("45deg", "220 mm", "(0.3, 0, 0.25) m"),
so both forms share one meaning and one set of unit diagnostics.
"""
from __future__ import annotations

from typing import Annotated, Any

from pydantic import BaseModel, ConfigDict, Field

from ..names import IDENTIFIER, MAX_NAME
from ..objectives import REGISTRY

# Names are checked while lowering (invalid-name, one rule for both forms); the schema states the rule.
_NAME_SCHEMA: dict[str, Any] = {"pattern": f"^{IDENTIFIER}$", "maxLength": MAX_NAME}
Name = Annotated[str, Field(json_schema_extra=_NAME_SCHEMA)]
_KEYS: dict[str, Any] = {"propertyNames": _NAME_SCHEMA}

Quantity = Annotated[str | float, Field(description='a number with its unit, as in .mod: "45deg", "0.22 m", "500 g"')]
Vector = Annotated[str, Field(description='a parenthesised tuple with one unit, as in .mod: "(0.3, 0, 0.25) m"')]


class _Doc(BaseModel):
    model_config = ConfigDict(extra="forbid")


class UnitItem(_Doc):
    unit: str = Field(description="unit name, e.g. H4")
    pivot: Quantity | None = None
    port: Quantity | None = None
    link: Quantity | None = None


class PlacementDoc(_Doc):
    at: Vector | None = None
    rpy: Vector | None = None


class PayloadDoc(_Doc):
    mass: Quantity
    at: Vector | None = None


class BoxDoc(_Doc):
    box: Name = Field(description="obstacle name")
    size: Vector
    at: Vector
    rpy: Vector | None = None


class SphereDoc(_Doc):
    sphere: Name
    radius: Quantity
    at: Vector


class CylinderDoc(_Doc):
    cylinder: Name
    radius: Quantity
    length: Quantity
    at: Vector
    rpy: Vector | None = None


class TargetDoc(_Doc):
    at: Vector
    rpy: Vector | None = Field(
        None, description='tool0\'s orientation in base_link (URDF fixed axes), e.g. "(0, 90, 0) deg"'
    )
    within: str | None = Field(None, description='tolerances: "5 mm" or "5 mm, 2 deg"')
    pointing: Vector | None = Field(None, description='instead of rpy: tool0\'s x axis only, e.g. "(0, 0, -1)"')


TargetValue = Vector | TargetDoc


class RegionDoc(_Doc):
    """A grid of targets over a box (docs/language.md: `region`)."""

    size: Vector
    at: Vector
    grid: str | list[int] = Field(description='points per axis: "3 x 2 x 1" or [3, 2, 1]')
    rpy: Vector | None = None
    within: str | None = Field(None, description='tolerances: "5 mm" or "5 mm, 2 deg"')
    pointing: Vector | None = Field(None, description='instead of rpy: tool0\'s x axis only, e.g. "(0, 0, -1)"')
    turned: Vector | None = Field(None, description='the box\'s orientation (fixed-axis rpy), e.g. "(0, 0, 45) deg"')


class PathDoc(_Doc):
    """tool0 along the straight segment between two targets (or region points)."""

    model_config = ConfigDict(extra="forbid", populate_by_name=True)
    start: str = Field(alias="from", description='a target or region point, e.g. "tray[1,0,0]"')
    to: str
    straight: bool = Field(True, description="the only kind of path: a straight segment")


class BaseWithinDoc(_Doc):
    """The base's placements to try (design blocks)."""

    size: Vector
    at: Vector
    step: Quantity
    yaw: str | None = Field(None, description='"0 to 90 deg step 45 deg"')


class RobotDoc(_Doc):
    name: Name
    library: str | None = Field(None, description="built-in library name, or a path to a library YAML file")
    chain: list[str | UnitItem] = Field(
        description='units base first: "H1", "H4(pivot=-90deg)" or {unit: H4, pivot: -90deg}'
    )
    base: PlacementDoc | None = None
    tool: PlacementDoc | None = None
    payload: PayloadDoc | None = None
    poses: dict[str, Vector] = Field(
        default_factory=dict, description='name -> joint angles, e.g. home: "(0, 30, -45) deg"', json_schema_extra=_KEYS
    )
    limits: dict[str, Vector] = Field(default_factory=dict, description='joint name -> "(lower, upper) deg"',
                                      json_schema_extra=_KEYS)
    obstacles: list[BoxDoc | SphereDoc | CylinderDoc] = Field(default_factory=list)
    targets: dict[str, TargetValue] = Field(
        default_factory=dict,
        description="name -> position of tool0 in base_link (or {at, rpy, within})",
        json_schema_extra=_KEYS,
    )
    allow: list[str] = Field(default_factory=list, description="assembly-rule codes to silence, e.g. first-variant")
    regions: dict[str, RegionDoc] = Field(default_factory=dict, description="name -> {size, at, grid, rpy, within}",
                                          json_schema_extra=_KEYS)
    tasks: dict[str, list[str]] = Field(default_factory=dict, json_schema_extra=_KEYS,
                                        description='name -> targets to visit in order: [plant, tray, "tray[1,0,0]"]')
    paths: dict[str, PathDoc] = Field(default_factory=dict, json_schema_extra=_KEYS,
                                      description="name -> {from, to}: tool0 along a straight segment")


class DesignDoc(_Doc):
    """A design problem (`modc design`): the cell and its targets, search bounds, objectives."""

    name: str = Field(pattern=r"^[A-Za-z_][A-Za-z0-9_]*$")
    library: str | None = None
    base: PlacementDoc | None = None
    tool: PlacementDoc | None = None
    payload: PayloadDoc | None = None
    obstacles: list[BoxDoc | SphereDoc | CylinderDoc] = Field(default_factory=list)
    targets: dict[str, TargetValue] = Field(default_factory=dict)
    allow: list[str] = Field(default_factory=list)
    regions: dict[str, RegionDoc] = Field(default_factory=dict, json_schema_extra=_KEYS)
    tasks: dict[str, list[str]] = Field(default_factory=dict, json_schema_extra=_KEYS)
    paths: dict[str, PathDoc] = Field(default_factory=dict, json_schema_extra=_KEYS)
    base_within: BaseWithinDoc | None = Field(None, description="base positions (and yaws) to try")
    units: int | str | None = Field(None, description='number of units: 3 or "2 to 4"')
    modules: list[str] | None = Field(None, description="unit types a chain may use, e.g. [H1, H3, L3, L4]")
    links: str | None = Field(None, description='link lengths to try: "220 mm" or "150 mm to 300 mm step 50 mm"')
    rank: list[str] | None = Field(
        None, description="objectives in order: " + ", ".join(REGISTRY))
    compare_with: list[str | UnitItem] | None = Field(
        None, description='a reference arm shown beside the designs, units base first: ["H1", "L4(pivot=-90deg)"]')


class Document(_Doc):
    robots: list[RobotDoc] = Field(default_factory=list)
    designs: list[DesignDoc] = Field(default_factory=list)


def json_schema() -> dict:
    schema = Document.model_json_schema()
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = "modc robot file (YAML form)"
    return schema
