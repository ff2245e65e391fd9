"""The reference arm of a design block (`compare with chain …`): the chain evaluated on the cell
with the ranking's own code, so that it can stand beside the designs found. Per target, the
screen's IK and obstacle test (evaluate.screen_batch, the target alone: one it misses does not
hide the others); when every target is reached, the exact check every ranked design passed
(evaluate.verify). A reference that fails says what it fails; its mass and torque margin come
from the same compiler check (the torque analysis, over-peak reported rather than refused)."""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..model import ResolvedProblem, Robot
from .evaluate import Candidate, Spec, Verified, _sub_targets, screen_batch, verify
from .rank import target_share
from .space import Shape

RESTARTS = 8  # IK seed sets tried per target: a reference is one arm, it may have more starts than the search


@dataclass(frozen=True)
class Reference:
    chain: str
    modules: int
    mass: float | None  # kg, the arm without payload
    margin: float | None  # smallest share of peak torque left over the joints
    targets: dict[str, dict]  # name -> reached, position_error_m (closest found), error_share (of the tolerance)
    fails: tuple[str, ...]  # what keeps it from being a design; () when it passes every check
    verified: Verified | None = None

    @property
    def feasible(self) -> bool:
        return not self.fails

    def worst_share(self) -> float | None:
        shares = [t["error_share"] for t in self.targets.values() if t["error_share"] is not None]
        return max(shares, default=None)

    def to_json(self) -> dict:
        return {"chain": self.chain, "modules": self.modules, "feasible": self.feasible,
                "mass_kg": None if self.mass is None else round(self.mass, 6),
                "torque_margin": None if self.margin is None else round(self.margin, 6),
                "worst_error_share": None if self.worst_share() is None else round(self.worst_share() or 0.0, 6),
                "targets": self.targets, "fails": list(self.fails)}


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


def evaluate(problem: ResolvedProblem, seed: int = 0) -> Reference | None:
    """The block's reference arm on its cell, or None when it names none. Every region point is
    a target of it, as of the designs (unless `rank coverage`)."""
    from .tasks import with_points

    problem, names = with_points(problem)
    out = _evaluate(problem, seed)
    if out is None or not names:
        return out
    fails = []
    for f in out.fails:
        for internal, shown in names.items():
            f = f.replace(f"'{internal}'", f"'{shown}'")
        fails.append(f)
    return replace(out, targets={names.get(k, k): v for k, v in out.targets.items()}, fails=tuple(fails))


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
        one = replace(spec, targets=_sub_targets(spec.targets, t))
        closest, hit, sols = np.inf, False, []
        for k in range(RESTARTS):
            s = screen_batch(one, shape, pivots, ports, seed + k)
            closest, hit = min(closest, float(s.closest[0, 0])), hit or bool(s.hit[0, 0])
            if s.feasible[0]:
                sols = [tuple(float(x) for x in q) for q in s.solutions[0][0]]
                break
        solutions.append(tuple(sols))
        tol = target.position_tolerance
        targets[target.name] = {"reached": bool(sols), "position_error_m": round(closest, 9) if np.isfinite(closest)
                                else None, "error_share": round(closest / tol, 6) if np.isfinite(closest) else None}
        if not sols:
            fails.append(f"target '{target.name}' is reached only in collision with the cell" if hit else
                         f"target '{target.name}' missed by {closest * 1000:.3g} mm "
                         f"(tolerance {tol * 1000:g} mm)" if np.isfinite(closest) else
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
        return Reference(text, len(units), verified.mass, verified.margin, targets, (), verified)
    mass, margin, why = _static(problem, ref)
    return Reference(text, len(units), mass, margin, targets, tuple(fails + ([why] if why else [])))
