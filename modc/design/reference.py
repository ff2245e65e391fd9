"""The reference arm of a design block (`compare with chain …`): the chain evaluated on the cell
with the ranking's own code, so that it can stand beside the designs found. Per target, the
screen's IK and obstacle test (evaluate.screen_batch, the target alone: one it misses does not
hide the others); when every target is reached, the exact check every ranked design passed
(evaluate.verify). A reference that fails says what it fails; its mass and torque margin come
from the same compiler check (the torque analysis, over-peak reported rather than refused).
A reference that passes them on a cell with tasks is planned and timed like every design
(tasks.plan_design): its cycle time and energy stand beside theirs, or it fails the task."""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..model import ResolvedProblem, Robot, Transform
from .evaluate import Candidate, Spec, Verified, _sub_targets, screen_batch, verify
from .rank import Planned, target_share
from .space import Shape

RESTARTS = 8  # IK seed sets tried per target: a reference is one arm, it may have more starts than the search


@dataclass(frozen=True)
class Reference(Planned):
    chain: str
    modules: int
    mass: float | None  # kg, the arm without payload
    margin: float | None  # smallest share of peak torque left over the joints
    targets: dict[str, dict]  # name -> reached, position_error_m (closest found), error_share (of the tolerance)
    fails: tuple[str, ...]  # what keeps it from being a design; () when it passes every check
    verified: Verified | None = None
    candidate: Candidate | None = None
    plans: tuple = ()  # modc.plan.task.TaskPlan per task and path of the cell, once planned
    coverage: float = 1.0  # share of the region points reached (`rank coverage`)

    @property
    def feasible(self) -> bool:
        return not self.fails

    def worst_share(self) -> float | None:
        shares = [t["error_share"] for t in self.targets.values() if t["error_share"] is not None]
        return max(shares, default=None)

    def to_json(self, name: str | None = None) -> dict:
        """ranking.json's "reference" entry; name: the design block's, when its files were written
        (DIR/<name>_reference.mod, and .traj.json once planned)."""
        out = {"chain": self.chain, "modules": self.modules, "feasible": self.feasible,
               "mass_kg": None if self.mass is None else round(self.mass, 6),
               "torque_margin": None if self.margin is None else round(self.margin, 6),
               "worst_error_share": None if self.worst_share() is None else round(self.worst_share() or 0.0, 6),
               "targets": self.targets, "fails": list(self.fails)}
        if name is not None and self.mass is not None:
            out["file"] = file_name(name)
        if self.verified is not None:  # where its base_link stands in the cell (`base within`: the pose found)
            base = self.verified.robot.base
            out["base"] = {"xyz_m": [round(v, 9) + 0.0 for v in base.xyz],
                           "rpy_deg": [round(math.degrees(v), 6) + 0.0 for v in base.rpy]}
        if self.plans:
            out |= {"cycle_time_s": round(self.cycle_time, 6), "energy_j": round(self.energy, 6),
                    "peak_torque_share": round(max(p.peak_share for p in self.plans), 6),
                    "coverage": round(self.coverage, 6),
                    "tasks": [{"task": p.task, "kind": p.kind, "cycle_time_s": round(p.cycle_time, 6),
                               "energy_j": round(p.energy, 6), "peak_torque_share": round(p.peak_share, 6),
                               "segments": [s.to_json() for s in p.segments]} for p in self.plans],
                    **({"traj": traj_name(name), "traj_task": self.plans[0].task} if name is not None else {})}
        return out


def file_name(problem: str) -> str:
    return f"{problem}_reference.mod"


def traj_name(problem: str) -> str:
    return f"{problem}_reference.traj.json"


def chain_text(robot: Robot) -> str:
    from ..model.write import unit_text

    return " - ".join(unit_text(robot, i) for i in range(robot.dof))


def _static(problem: ResolvedProblem, ref: Robot) -> tuple[float | None, float | None, str | None]:
    """Mass and torque margin of the reference without poses: the compiler's check and torque analysis."""
    from ..compiler import check_text
    from ..model.write import robot_file_text
    from ..physical.assembly import library_mass

    text = robot_file_text(ref.model_copy(update={"name": problem.name, "poses": ()}))
    checked = check_text(text, f"{problem.name}.mod", analyses=frozenset({"torque"}), torque_severity="warning")
    if not checked.ok:
        d = next(d for d in checked.diagnostics if d.is_error)
        return None, None, f"{d.code}: {d.message}"
    robot = checked.design.resolved_robots()[0]
    payload = robot.payload.mass if robot.payload else 0.0
    margin = min(j.margin for j in robot.torque) if robot.torque else 1.0
    return library_mass(robot) - payload, float(margin), None


def evaluate(problem: ResolvedProblem, seed: int = 0, deadline: float | None = None,
             poses: list[Transform] | None = None) -> Reference | None:
    """The block's reference arm on its cell, or None when it names none. Every region point is
    a target of it, as of the designs (unless `rank coverage`). One that passes the static
    checks on a cell with tasks is planned and timed (deadline: time.time() to give up by).
    poses (`base within`: the grid's poses worth a search, nearest first): the reference stands
    at the first one where it passes the static checks, else it is told at the nearest."""
    from .placement import cell_at
    from .tasks import has_tasks

    if not poses:
        out = _at(problem, seed)
    else:
        first = None
        for pose in poses:
            out = _at(problem.model_copy(update={"cell": cell_at(problem.cell, pose), "base_grid": None}), seed)
            first = first or out
            if out is None or out.verified is not None:
                break
        else:
            out = first
    tasked = has_tasks(problem) or "coverage" in problem.rank
    if out is None or out.verified is None or out.candidate is None or not tasked:
        return out
    return _planned(out, seed, deadline, "coverage" in problem.rank)


def _at(problem: ResolvedProblem, seed: int) -> Reference | None:
    """The reference on the problem's cell, as it stands, before any planning."""
    from .tasks import with_points

    screened, names = with_points(problem)
    out = _evaluate(screened, seed)
    return _told(out, names) if out is not None and names else out


def _told(out: Reference, names: dict[str, str]) -> Reference:
    """The reference told in the cell's names (region points as `tray[1,0,0]`), its robot without
    the points as targets (its regions hold them), as tasks.restore tells the designs."""
    from .tasks import told

    fails = []
    for f in out.fails:
        for internal, shown in names.items():
            f = f.replace(f"'{internal}'", f"'{shown}'")
        fails.append(f)
    verified = None if out.verified is None else told(out.verified, names)
    return replace(out, targets={names.get(k, k): v for k, v in out.targets.items()}, fails=tuple(fails),
                   verified=verified)


def _planned(out: Reference, seed: int, deadline: float | None, coverage: bool) -> Reference:
    """The reference with its tasks planned and timed by the designs' own code, or failing the
    task it cannot serve."""
    from .rank import Design
    from .tasks import plan_design

    assert out.verified is not None and out.candidate is not None
    d = plan_design(Design(out.candidate, out.verified), seed, deadline, coverage)
    if isinstance(d, str):
        return replace(out, fails=(*out.fails, d))
    assert d is not None  # None only when stopped, and no stopping is given
    return replace(out, plans=d.plans, coverage=d.coverage, verified=d.verified)


def _screened(one: Spec, shape: Shape, pivots, ports, seed: int) -> tuple[tuple, float, bool]:
    """The design screen on one target, RESTARTS seeds at most: (its joint solutions, the closest
    tool0 came in m, whether it came within tolerance at all, in collision or not)."""
    closest, hit = np.inf, False
    for k in range(RESTARTS):
        s = screen_batch(one, shape, pivots, ports, seed + k)
        assert s is not None  # (never interrupted: no callback)
        closest, hit = min(closest, float(s.closest[0, 0])), hit or bool(s.hit[0, 0])
        if s.feasible[0]:
            return tuple(tuple(float(x) for x in q) for q in s.solutions[0][0]), closest, hit
    return (), closest, hit


def _evaluate(problem: ResolvedProblem, seed: int) -> Reference | None:
    ref = problem.reference
    lib = problem.cell.library
    if ref is None or lib is None or not ref.units or any(not u.variant for u in ref.units):
        return None
    units = ref.units
    shape = Shape(tuple(u.kind for u in units), tuple(u.link if lib.units[u.kind].link else None for u in units))
    pivots = np.array([[u.pivot for u in units]], float)
    ports = np.array([[u.port for u in units]], float)
    spec = Spec.of(problem)
    targets: dict[str, dict] = {}
    solutions, fails = [], []
    for t, target in enumerate(problem.cell.targets):
        sols, closest, hit = _screened(replace(spec, targets=_sub_targets(spec.targets, t)), shape, pivots, ports,
                                       seed)
        solutions.append(sols)
        tol = target.position_tolerance
        finite = bool(np.isfinite(closest))
        targets[target.name] = {"reached": bool(sols), "position_error_m": round(closest, 9) if finite else None,
                                "error_share": round(closest / tol, 6) if finite else None}
        if not sols:
            fails.append(f"target '{target.name}' is reached only in collision with the cell" if hit else
                         f"target '{target.name}' missed by {closest * 1000:.3g} mm "
                         f"(tolerance {tol * 1000:g} mm)" if finite else
                         f"target '{target.name}' not reached")
    text = chain_text(ref)
    verified = None
    if not fails:
        variants = tuple(u.variant for u in units)
        cand = Candidate(shape, variants, tuple(pivots[0]), tuple(ports[0]), tuple(solutions))
        v = verify(problem, cand)
        if isinstance(v, str):
            fails.append(v)
        else:
            verified = v
            for target in problem.cell.targets:
                got = v.targets[target.name]
                targets[target.name] = {"reached": True, **got, "error_share": round(target_share(got, target), 6)}
    if verified is not None:
        return Reference(text, len(units), verified.mass, verified.margin, targets, (), verified, cand)
    mass, margin, why = _static(problem, ref)
    return Reference(text, len(units), mass, margin, targets, tuple(fails + ([why] if why else [])))
