"""Hypothesis strategies for valid .mod robots (docs/conventions.md, docs/language.md), shared by property tests.

    from strategies import valid_chains, valid_chains_with_dof, robot_specs

`valid_chains()` draws the text of one `robot NAME { ... }` block that modc must accept with the
default library (mark2): 2..6 units, first H, last L, no L -> H, at most 3 H and 3 L (so every
valid chain is H...H L...L); pivots are multiples of 15 deg in [-90, 90] on any unit; ports
(multiples of 15 deg in (-180, 180]) and link lengths (50..500 mm) only on units 3/4; an optional
tool offset and payload. Quantities are written in varied but equivalent units (deg/rad, m/cm/mm,
kg/g) and spacing, so the same strategy also exercises the lexer and unit conversion.

`robot_specs()` draws the structured `RobotSpec` behind the text, for tests that want the
expected values (DoF, sequence, SI parameters) without reading modc's model.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from hypothesis import strategies as st

MAX_PER_VARIANT = 3  # epsilon of both H and L in mark2
PIVOTS_DEG = tuple(range(-90, 91, 15))
PORTS_DEG = tuple(range(-165, 181, 15))  # (-180, 180]
LINK_MM = (50, 500)  # mark2 link_length_min/max


@dataclass(frozen=True)
class UnitChoice:
    """One unit as written. None = parameter left out (the library default applies)."""

    variant: str  # "H" | "L"
    kind: int  # 1..4
    pivot_deg: int | None = None
    port_deg: int | None = None
    link_mm: int | None = None

    @property
    def name(self) -> str:
        return f"{self.variant}{self.kind}"

    @property
    def has_link(self) -> bool:
        return self.kind in (3, 4)


@dataclass(frozen=True)
class RobotSpec:
    """A valid robot and how to spell it."""

    name: str
    units: tuple[UnitChoice, ...]
    tool_xyz_mm: tuple[int, int, int] | None = None
    tool_rpy_deg: tuple[int, int, int] | None = None
    payload_g: int | None = None
    payload_com_mm: tuple[int, int, int] | None = None
    # spelling choices (same meaning, different text)
    angle_unit: str = "deg"  # "deg" | "rad"
    length_unit: str = "mm"  # "mm" | "cm" | "m"
    mass_unit: str = "kg"  # "kg" | "g"
    dash: str = " - "

    @property
    def dof(self) -> int:
        return len(self.units)

    @property
    def sequence(self) -> str:
        return "-".join(u.name for u in self.units)

    @property
    def file_stem(self) -> str:
        return f"mod{self.dof}_{self.name}"

    # --- spelling -------------------------------------------------------------------------
    def _angle(self, deg: float) -> str:
        if self.angle_unit == "rad":
            return f"{math.radians(deg)!r}rad"
        return f"{deg}deg"

    def _length(self, mm: float) -> str:
        scale = {"mm": 1, "cm": 10, "m": 1000}[self.length_unit]
        return f"{mm / scale!r}{self.length_unit}" if scale != 1 else f"{mm}mm"

    def _vector(self, values, unit: str) -> str:
        return "(" + ", ".join(values) + f") {unit}"

    def _unit_text(self, u: UnitChoice) -> str:
        params = []
        if u.pivot_deg is not None:
            params.append(f"pivot={self._angle(u.pivot_deg)}")
        if u.port_deg is not None:
            params.append(f"port={self._angle(u.port_deg)}")
        if u.link_mm is not None:
            params.append(f"link={self._length(u.link_mm)}")
        return u.name + (f"({', '.join(params)})" if params else "")

    @property
    def text(self) -> str:
        lines = [f"robot {self.name} {{", "    chain " + self.dash.join(self._unit_text(u) for u in self.units)]
        if self.tool_xyz_mm is not None or self.tool_rpy_deg is not None:
            tool = "    tool"
            if self.tool_xyz_mm is not None:
                tool += f" at ({', '.join(str(v / 1000) for v in self.tool_xyz_mm)}) m"
            if self.tool_rpy_deg is not None:
                if self.angle_unit == "rad":
                    tool += " rpy " + self._vector([repr(math.radians(v)) for v in self.tool_rpy_deg], "rad")
                else:
                    tool += " rpy " + self._vector([str(v) for v in self.tool_rpy_deg], "deg")
            lines.append(tool)
        if self.payload_g is not None:
            mass = f"{self.payload_g}g" if self.mass_unit == "g" else f"{self.payload_g / 1000!r}kg"
            line = f"    payload {mass}"
            if self.payload_com_mm is not None:
                line += f" at ({', '.join(str(v / 1000) for v in self.payload_com_mm)}) m"
            lines.append(line)
        lines.append("}")
        return "\n".join(lines) + "\n"

    # --- meaning in SI, for tests -------------------------------------------------------------
    @property
    def tool_xyz(self) -> tuple[float, float, float]:
        return tuple(v / 1000 for v in self.tool_xyz_mm) if self.tool_xyz_mm else (0.0, 0.0, 0.0)

    @property
    def tool_rpy(self) -> tuple[float, float, float]:
        return tuple(math.radians(v) for v in self.tool_rpy_deg) if self.tool_rpy_deg else (0.0, 0.0, 0.0)

    @property
    def payload_kg(self) -> float:
        return 0.0 if self.payload_g is None else self.payload_g / 1000


names = st.from_regex(r"[A-Za-z_][A-Za-z0-9_]{0,15}", fullmatch=True)


@st.composite
def units(draw, variant: str) -> UnitChoice:
    kind = draw(st.integers(1, 4))
    pivot = draw(st.none() | st.sampled_from(PIVOTS_DEG))
    port = link = None
    if kind in (3, 4):
        port = draw(st.none() | st.sampled_from(PORTS_DEG))
        link = draw(st.none() | st.integers(*LINK_MM))
    return UnitChoice(variant, kind, pivot, port, link)


@st.composite
def robot_specs(draw, min_units: int = 2, max_units: int = 6) -> RobotSpec:
    """A valid robot: H^h L^l with 1 <= h, l <= 3 and min_units <= h + l <= max_units."""
    n = draw(st.integers(max(2, min_units), min(2 * MAX_PER_VARIANT, max_units)))
    h = draw(st.integers(max(1, n - MAX_PER_VARIANT), min(MAX_PER_VARIANT, n - 1)))
    chain = tuple(draw(units("H")) for _ in range(h)) + tuple(draw(units("L")) for _ in range(n - h))
    mm = st.integers(-200, 200)
    tool_xyz = draw(st.none() | st.tuples(mm, mm, mm))
    tool_rpy = draw(st.none() | st.tuples(*[st.integers(-180, 180)] * 3))
    payload = draw(st.none() | st.integers(1, 2000))
    com = draw(st.none() | st.tuples(mm, mm, mm)) if payload is not None else None
    return RobotSpec(
        name=draw(names), units=chain, tool_xyz_mm=tool_xyz, tool_rpy_deg=tool_rpy,
        payload_g=payload, payload_com_mm=com,
        angle_unit=draw(st.sampled_from(("deg", "rad"))),
        length_unit=draw(st.sampled_from(("mm", "cm", "m"))),
        mass_unit=draw(st.sampled_from(("kg", "g"))),
        dash=draw(st.sampled_from((" - ", "-", "  -\n      "))),
    )


def valid_chains(min_units: int = 2, max_units: int = 6) -> st.SearchStrategy[str]:
    """The .mod text of one valid robot (see module docstring)."""
    return robot_specs(min_units, max_units).map(lambda s: s.text)


def valid_chains_with_dof(min_units: int = 2, max_units: int = 6) -> st.SearchStrategy[tuple[str, int]]:
    """(text, expected DoF) of one valid robot."""
    return robot_specs(min_units, max_units).map(lambda s: (s.text, s.dof))
