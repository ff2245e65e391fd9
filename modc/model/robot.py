"""The checked model: what a .mod (or YAML) file means, in SI units (m, kg, rad).

Backends read only this (and the library it points to), never the syntax.
"""
from __future__ import annotations

import math
from typing import ClassVar, Literal

from ..diagnostics import NOWHERE, Span
from ..objectives import DEFAULT
from .base import InvalidModel, Value, floats, grid3, hidden, optional, vec3  # noqa: F401 (InvalidModel re-exported)
from .library import Library

# Every user-given name in the model (robot, unit, pose, target, obstacle, joint reference) is one
# of these: lowering reports a bad one as invalid-name, so no backend can ever see another string.
Name = str
Vec3 = tuple[float, float, float]


class Transform(Value):
    """A placement: position (m) then fixed-axis roll-pitch-yaw (rad), as in URDF."""

    _convert = (("xyz", vec3), ("rpy", vec3))

    xyz: Vec3 = (0.0, 0.0, 0.0)
    rpy: Vec3 = (0.0, 0.0, 0.0)


class UnitSpec(Value):
    """One modular unit of the chain, e.g. H4(pivot=-90deg, port=45deg)."""

    _names = ("name",)
    _convert = (("kind", int), ("pivot", float), ("port", float), ("link", optional(float)))

    name: Name
    variant: str = ""  # filled once the library is known
    kind: int = 0
    pivot: float = 0.0  # rad, twist in the adaptive twist unit (rotation about y, eq. 4)
    port: float = 0.0  # rad, twist at the connection port after the link (rotation about x, eq. 6)
    link: float | None = None  # m, link-module length; None = the library's default
    span: Span = hidden(NOWHERE)
    param_spans: dict[str, Span] = hidden(default_factory=dict)


class DHRow(Value):
    """One row of a standard DH table: Rz(theta) Tz(d) Tx(a) Rx(alpha), SI units."""

    _convert = (("a", float), ("alpha", float), ("d", float), ("theta", float))

    a: float
    alpha: float
    d: float
    theta: float = 0.0
    span: Span = hidden(NOWHERE)


class Payload(Value):
    _convert = (("mass", float), ("com", vec3))

    mass: float  # kg
    com: Vec3 = (0.0, 0.0, 0.0)  # m, in the tool0 frame
    span: Span = hidden(NOWHERE)


class Pose(Value):
    _names = ("name",)
    _convert = (("q", floats),)

    name: Name
    q: tuple[float, ...]  # rad, joint_1 first
    span: Span = hidden(NOWHERE)


class JointLimit(Value):
    _names = ("joint",)
    _convert = (("lower", float), ("upper", float))

    joint: Name
    lower: float
    upper: float
    span: Span = hidden(NOWHERE)


class Obstacle(Value):
    _names = ("name",)
    _convert = (("size", floats),)
    SHAPES: ClassVar[tuple[str, ...]] = ("box", "sphere", "cylinder")

    name: Name
    shape: Literal["box", "sphere", "cylinder"]
    size: tuple[float, ...]  # box: (x, y, z); sphere: (r,); cylinder: (r, length along z)
    origin: Transform
    span: Span = hidden(NOWHERE)

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.shape not in self.SHAPES:
            raise InvalidModel(f"an obstacle is one of {', '.join(self.SHAPES)}")


POSITION_TOLERANCE = 0.005  # m: default distance of tool0 from a target that counts as on it
ORIENTATION_TOLERANCE = 0.034906585039886591  # rad (2°): default for a target with an orientation


class Target(Value):
    _names = ("name",)
    _convert = (("xyz", vec3), ("rpy", optional(vec3)), ("position_tolerance", float),
                ("orientation_tolerance", float))

    name: Name
    xyz: Vec3  # m, in base_link
    rpy: Vec3 | None = None  # rad, tool0's orientation in base_link (URDF fixed axes); None: position only
    position_tolerance: float = POSITION_TOLERANCE
    orientation_tolerance: float = ORIENTATION_TOLERANCE
    span: Span = hidden(NOWHERE)
    pointing: Vec3 | None = None  # unit vector in base_link: tool0's x axis (the approach) only; never with rpy

    @property
    def oriented(self) -> bool:
        """Whether the target asks for an orientation (a full rpy, or the approach direction)."""
        return self.rpy is not None or self.pointing is not None

    @property
    def tolerance(self) -> tuple[float, float]:
        """(m, rad): how near tool0 must come to count as on the target, the bounds plan.ik.solve
        accepts a run within; a position-only target has no bound on the orientation."""
        return (self.position_tolerance, self.orientation_tolerance if self.oriented else math.inf)


MAX_REGION_POINTS = 10_000  # per region: a tray of a few dozen cells is real; beyond this, a typo


class Region(Value):
    """`region NAME box size … at … [turned …] grid nx x ny x nz`: targets evenly spaced over a
    box, faces included; an axis with one point holds it at the box's centre. The box is
    axis-aligned in base_link unless `turned` (fixed-axis rpy, as an obstacle's): its axes, and so
    its points, turn with it; the points' tool orientation (rpy, pointing) does not."""

    _names = ("name",)
    _convert = (("size", vec3), ("center", vec3), ("grid", grid3), ("rpy", optional(vec3)),
                ("turned", optional(vec3)), ("position_tolerance", float), ("orientation_tolerance", float))

    name: Name
    size: Vec3  # m, full extents
    center: Vec3  # m, in base_link
    grid: tuple[int, int, int]
    rpy: Vec3 | None = None  # every point's tool0 orientation
    pointing: Vec3 | None = None  # or every point's approach direction only (Target.pointing)
    turned: Vec3 | None = None  # rad: the box's axes in base_link (None: base_link's own)
    position_tolerance: float = POSITION_TOLERANCE
    orientation_tolerance: float = ORIENTATION_TOLERANCE
    span: Span = hidden(NOWHERE)

    def indices(self) -> list[tuple[int, int, int]]:
        """Every point's (i, j, k), in order: k fastest, then j, then i."""
        nx, ny, nz = self.grid
        return [(i, j, k) for i in range(nx) for j in range(ny) for k in range(nz)]

    def point_name(self, index: tuple[int, int, int]) -> str:
        return f"{self.name}[{index[0]},{index[1]},{index[2]}]"

    def point(self, index: tuple[int, int, int]) -> Target:
        """The point as a target (its name, `tray[i,j,k]`, is not an identifier: built unvalidated)."""
        xyz = []
        for c, s, n, i in zip(self.center, self.size, self.grid, index, strict=True):
            xyz.append(c if n == 1 else c - s / 2 + s * i / (n - 1))
        if self.turned is not None:  # the same offsets from the centre, along the box's own axes
            from ..rotation import rpy_matrix

            offset = rpy_matrix(self.turned) @ [x - c for x, c in zip(xyz, self.center, strict=True)]
            xyz = [c + float(d) for c, d in zip(self.center, offset, strict=True)]
        return Target.model_construct(name=self.point_name(index), xyz=(xyz[0], xyz[1], xyz[2]), rpy=self.rpy,
                                      pointing=self.pointing, position_tolerance=self.position_tolerance,
                                      orientation_tolerance=self.orientation_tolerance, span=self.span)

    def points(self) -> list[Target]:
        return [self.point(ix) for ix in self.indices()]


class Task(Value):
    """`task NAME { visit … }`: the targets tool0 visits in order (region names expanded to their
    points), joined by collision-free joint-space motions."""

    _names = ("name",)
    _convert = (("visits", tuple),)

    name: Name
    visits: tuple[str, ...]  # target names and region point names (`tray[0,1,0]`)
    span: Span = hidden(NOWHERE)


class StraightPath(Value):
    """`path NAME from a to b straight`: tool0 along the segment a -> b, orientation interpolated."""

    _names = ("name",)

    name: Name
    start: str
    end: str
    span: Span = hidden(NOWHERE)


class BaseGrid(Value):
    """`base within box size … at … step … [yaw lo to hi step s]` (design blocks): the base
    positions (and yaws) to try, in the cell frame."""

    _convert = (("size", vec3), ("center", vec3), ("step", float), ("yaws", floats))

    size: Vec3
    center: Vec3
    step: float  # m
    yaws: tuple[float, ...] = (0.0,)  # rad
    span: Span = hidden(NOWHERE)

    def positions(self) -> list[Vec3]:
        axes = []
        for c, s in zip(self.center, self.size, strict=True):
            n = int(s / self.step + 1e-9) + 1 if s > 0 else 1
            axes.append([c] if n == 1 else [c - s / 2 + k * self.step for k in range(n)])
        return [(x, y, z) for x in axes[0] for y in axes[1] for z in axes[2]]

    def poses(self) -> list[Transform]:
        return [Transform(xyz=p, rpy=(0.0, 0.0, yaw)) for p in self.positions() for yaw in self.yaws]


def default_position(lower: float, upper: float) -> float:
    """MoveIt's default value of a revolute joint with these bounds (moveit_core,
    RevoluteJointModel::getVariableDefaultPositions): 0 inside the bounds, else their middle."""
    return 0.0 if lower <= 0.0 <= upper else (lower + upper) / 2.0


class Robot(Value):
    _names = ("name",)
    _convert = (*((f, tuple) for f in ("units", "poses", "limits", "obstacles", "targets", "regions", "tasks",
                                       "paths")), ("dh", optional(tuple)), ("allow", frozenset))

    name: Name
    library_ref: str = "mark2"
    library_dir: str | None = None  # where a relative library path is resolved
    library: Library | None = None  # resolved by the resolve_library pass
    units: tuple[UnitSpec, ...] = ()
    dh: tuple[DHRow, ...] | None = None  # a DH table to convert (the convert_dh pass fills units)
    dh_fit_links: bool = False
    base: Transform = Transform()  # base_link in the world (cell) frame
    tool: Transform = Transform()  # tool0 relative to the last unit's last frame
    payload: Payload | None = None
    poses: tuple[Pose, ...] = ()
    limits: tuple[JointLimit, ...] = ()
    obstacles: tuple[Obstacle, ...] = ()
    targets: tuple[Target, ...] = ()
    allow: frozenset[str] = frozenset()
    regions: tuple[Region, ...] = ()
    tasks: tuple[Task, ...] = ()
    paths: tuple[StraightPath, ...] = ()
    torque: tuple | None = hidden(None)  # set by check_torque
    span: Span = hidden(NOWHERE)
    name_span: Span = hidden(NOWHERE)
    library_span: Span = hidden(NOWHERE)  # the `library` statement, where library errors point

    @property
    def dof(self) -> int:
        return len(self.units)

    @property
    def sequence(self) -> str:
        return "-".join(u.name for u in self.units)

    @property
    def file_stem(self) -> str:
        """docs/conventions.md: the URDF for the Kinova bring-up is named mod<n>_<name>."""
        return f"mod{self.dof}_{self.name}"

    def task_target(self, name: str) -> Target | None:
        """A target, or a region's point (`tray[1,0,0]`), by name."""
        t = next((t for t in self.targets if t.name == name), None)
        if t is not None or "[" not in name:
            return t
        region, _, rest = name.partition("[")
        r = next((r for r in self.regions if r.name == region), None)
        try:
            index = tuple(int(v) for v in rest.rstrip("]").split(","))
        except ValueError:
            return None
        if r is None or len(index) != 3 or not all(0 <= i < n for i, n in zip(index, r.grid, strict=True)):
            return None
        return r.point((index[0], index[1], index[2]))

    def pose(self, name: str) -> Pose | None:
        return next((p for p in self.poses if p.name == name), None)


class ResolvedRobot(Robot):
    """A robot whose library is resolved: what every pass after resolve_library, every backend
    and every analysis reads. Made only by `resolved` (the resolve_library and check_problems
    passes), so `library` is never None and the type checker proves it where it is read."""

    library: Library

    def __post_init__(self) -> None:
        super().__post_init__()
        if not isinstance(self.library, Library):
            raise InvalidModel("a resolved robot has its module library")

    def hardware_range(self, i: int) -> tuple[float, float]:
        """Joint i's (1-based) range in the library, rad, before any `limit` narrows it."""
        return self.library.variants[self.units[i - 1].variant].joint_range

    def link_length(self, u: UnitSpec) -> float:
        t = self.library.units[u.kind]
        if not t.link:
            return 0.0
        return t.x23 if u.link is None else u.link

    def home(self) -> tuple[float, ...]:
        """The one home pose (rad) of every backend and analysis: the pose declared `home`, else
        MoveIt's default joint values (default_q). check_poses reports a declared home outside
        the limits (pose-out-of-limits), so a checked robot's home is always inside them."""
        p = self.pose("home")
        return tuple(p.q) if p is not None else self.default_q()

    def named_poses(self) -> list[tuple[str, tuple[float, ...]]]:
        """(name, q) of home (as home()) first, then every other declared pose in file order: the
        SRDF's group states, the MJCF keyframes, the smoke test's poses and the viewer's list."""
        return [("home", self.home())] + [(p.name, tuple(p.q)) for p in self.poses if p.name != "home"]

    def default_q(self) -> tuple[float, ...]:
        """MoveIt's default joint values (RobotState::setToDefaultValues, which the Setup
        Assistant's collision matrix also starts from): per joint, 0 when its range (narrowed by
        `limit`) contains 0, else the middle of the range."""
        return tuple(default_position(*self.joint_range(i)) for i in range(1, self.dof + 1))

    def joint_range(self, i: int) -> tuple[float, float]:
        """Position limits of joint i (1-based), rad: the library's range, narrowed by `limit`."""
        hw = self.hardware_range(i)
        lo, hi = hw
        for lim in self.limits:
            if lim.joint == f"joint_{i}" and lim.lower < lim.upper:
                lo, hi = max(lo, lim.lower), min(hi, lim.upper)
        # an inverted or disjoint limit is reported by check_poses; analyses keep the hardware range
        return (lo, hi) if lo < hi else hw


def resolved(robot: Robot, library: Library, **update: object) -> ResolvedRobot:
    """The robot with its library (and fields in update replaced), unchecked as model_copy."""
    new = object.__new__(ResolvedRobot)
    new.__dict__.update(robot.__dict__)
    for k, v in update.items():
        if k not in new.__dict__:
            raise TypeError(f"Robot has no field {k!r}")
        new.__dict__[k] = v
    new.__dict__["library"] = library
    return new


RANK_KEYS = DEFAULT  # ranked unless named (fewest modules, least mass, largest torque margin): modc.objectives


class Problem(Value):
    """A `design` block: the cell (a robot without units: library, base, tool, payload,
    obstacles, targets) and the bounds and objectives of the search for its chains."""

    _names = ("name",)
    _convert = (("min_units", int), ("max_units", int), ("modules", optional(tuple)), ("links", optional(floats)),
                ("rank", tuple))

    name: Name
    cell: Robot
    min_units: int = 1
    max_units: int = 3
    modules: tuple[str, ...] | None = None  # allowed unit names; None: every unit of the library
    links: tuple[float, ...] | None = None  # m, link-module lengths to try; None: the library's default
    rank: tuple[str, ...] = RANK_KEYS
    base_grid: BaseGrid | None = None  # `base within …`: base poses to try (cell frame); None: the base as written
    reference: Robot | None = None  # `compare with chain …`: the cell with that chain, evaluated beside the designs
    span: Span = hidden(NOWHERE)
    name_span: Span = hidden(NOWHERE)
    # where each bound was written ("units", "links", "module:H9"), for the library checks
    bound_spans: dict[str, Span] = hidden(default_factory=dict)


class ResolvedProblem(Problem):
    """A `design` block whose cell's library is resolved: what check_problems hands on and every
    design analysis reads (its cell is a ResolvedRobot, so the library is never None)."""

    cell: ResolvedRobot

    def __post_init__(self) -> None:
        super().__post_init__()
        if not isinstance(self.cell, ResolvedRobot):
            raise InvalidModel("a resolved design problem has its cell's module library")


def resolved_problem(problem: Problem, cell: ResolvedRobot) -> ResolvedProblem:
    """The problem with its resolved cell, unchecked as model_copy."""
    new = object.__new__(ResolvedProblem)
    new.__dict__.update(problem.__dict__)
    new.__dict__["cell"] = cell
    return new


class Design(Value):
    """Everything one input file defines."""

    _convert = (("robots", tuple), ("problems", tuple))

    path: str
    robots: tuple[Robot, ...] = ()
    problems: tuple[Problem, ...] = ()  # `design` blocks

    def resolved_robots(self) -> tuple[ResolvedRobot, ...]:
        """The robots of a design whose checks passed (a build's, an analysis's): every one
        resolved. InvalidModel for a robot whose library was never resolved."""
        for r in self.robots:
            if not isinstance(r, ResolvedRobot):
                raise InvalidModel(f"robot {r.name}: its library is not resolved (check the design first)")
        return self.robots  # type: ignore[return-value]  # each one checked just above

    def resolved_problems(self) -> tuple[ResolvedProblem, ...]:
        """The design blocks of a design whose checks passed: every cell resolved. InvalidModel
        for a block whose library was never resolved."""
        for p in self.problems:
            if not isinstance(p, ResolvedProblem):
                raise InvalidModel(f"design {p.name}: its library is not resolved (check the design first)")
        return self.problems  # type: ignore[return-value]  # each one checked just above
