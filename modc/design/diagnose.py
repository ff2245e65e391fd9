"""Why no design: per target, whether any arm in the bounds reaches it alone, and if not, what
rules it out - reach (a sound bound or no IK run gets there), the cell's obstacles (reached only
in collision, or the target lies so deep in an obstacle that no arm fits), the joint limits
(reached with the joints free, never within their limits) or, when every target is reachable
alone, torque or the combination. Distances are always finite."""
from __future__ import annotations

import dataclasses
import math
import time
from typing import Any

import numpy as np

from ..formatting import counted
from ..model import ResolvedProblem
from ..model.robot import StraightPath, Task
from . import space
from .evaluate import Spec, _sub_targets
from .screen import reach_bound
from .search import STOP, parts_of, search_part

PROBE_SECONDS = 10.0  # per target not yet tried alone


def _length(x: float) -> str:
    return f"{x:.3g} m" if x >= 0.1 else f"{x * 1000:.3g} mm"


def _shapes_for(problem: ResolvedProblem, t: int, hi: int) -> list[space.Shape]:
    """Shapes of the bounds that could reach target t alone (by the reach bound), smallest first."""
    lib = problem.cell.library
    target = problem.cell.targets[t]
    out = []
    for n in range(max(problem.min_units, lib.rules.min_dof), hi + 1):
        if not space.variant_splits(problem, n):
            continue
        for s in space.shapes(problem, n):
            lengths = [x or lib.units[k].x23 for k, x in zip(s.kinds, s.links, strict=True)]
            r = reach_bound([lib.units[k] for k in s.kinds], lengths, problem.cell.tool.xyz)
            if float(np.linalg.norm(target.xyz)) - target.position_tolerance <= r:
                out.append(s)
    return out


def _probe(problem: ResolvedProblem, spec: Spec, t: int, seed: int, until: float, free: bool) -> dict:
    """Search for target t alone (joints free of their limits with `free`) until it is reached clear
    of the cell or time runs out."""
    lib = problem.cell.library
    one = dataclasses.replace(spec, targets=_sub_targets(spec.targets, t))
    if free:
        one = dataclasses.replace(one, lower=-math.pi, upper=math.pi)
    res: dict[str, Any] = {"hit": False, "clear": False, "closest": math.inf, "screened": 0, "finished": True}
    for s in _shapes_for(problem, t, min(problem.max_units, lib.rules.max_dof)):
        for _, ranges, full in parts_of(one, s):
            if time.time() > until:
                res["finished"] = False
                return res
            p = search_part(one, s, ranges, seed, until, full)
            res["hit"] |= p.hit[0]
            res["clear"] |= p.clear[0]
            res["closest"] = min(res["closest"], p.closest[0])
            res["screened"] += p.screened
            if res["clear"]:
                return res
    return res


def _alone(problem: ResolvedProblem, spec: Spec, i: int, seed: int, deadline: float | None, closest: float,
           entry: dict) -> dict | None:
    """Target i searched alone (PROBE_SECONDS at most): the probe's result, or None once entry
    says it is reached alone, or reached only with the joints beyond their limits."""
    until = time.time() + PROBE_SECONDS if deadline is None else min(deadline, time.time() + PROBE_SECONDS)
    p = _probe(problem, spec, i, seed, until, free=False)
    if p["clear"]:
        entry["reached_alone"] = True
        return None
    c = min(closest, p["closest"])
    if not p["hit"] and p["screened"]:
        loose = _probe(problem, spec, i, seed, until + PROBE_SECONDS / 2, free=True)
        if loose["hit"]:
            entry.update(ruled_out_by="joint limits", closest_m=_finite(c),
                         detail="reached only with the joints beyond their limits"
                         + (f" (within the limits no design gets closer than {_length(c)})"
                            if math.isfinite(c) else ""))
            return None
    return p


def diagnose(problem: ResolvedProblem, spec: Spec, names, blocked, hit, clear, closest, seed: int,
             deadline: float | None, stopped: bool) -> dict[str, dict]:
    out: dict[str, dict] = {}
    for i, name in enumerate(names):
        entry: dict[str, Any] = {"reached_alone": bool(clear[name]), "ruled_out_by": None, "closest_m": None,
                                 "detail": ""}
        out[name] = entry
        if blocked[i] >= 0:
            wall = problem.cell.obstacles[int(blocked[i])].name
            entry.update(ruled_out_by="obstacles", closest_m=None,
                         detail=f"obstacle '{wall}' rules it out for every arm: tool0 there is inside it, or "
                                "it stands between the base and the target across the arm's whole reach")
            continue
        if clear[name]:
            continue
        h, c = hit[name], closest[name]
        if not h and math.isfinite(c) and c > problem.cell.targets[i].position_tolerance:
            # closest is at most every shape's sound reach bound (run._tiers bounds every shape
            # before any IK; an IK distance is never below its shape's bound): beyond the tolerance
            # for every shape is a proof, whether or not the search ran to its end
            entry.update(ruled_out_by="reach", closest_m=_finite(c), detail=f"no design gets closer than {_length(c)}")
            continue
        if stopped and not h:
            entry.update(detail="not reached by the settings screened before the search stopped")
            continue
        if not h and (STOP.is_set() or (deadline is not None and time.time() >= deadline)):
            entry.update(detail="not reached by the settings screened; the time ran out before it was "
                                "searched alone")
            continue
        if not h:
            p = _alone(problem, spec, i, seed, deadline, c, entry)
            if p is None:  # said: reached alone, or only beyond the joint limits
                continue
            h, c = p["hit"], min(c, p["closest"])
        if h:
            entry.update(ruled_out_by="obstacles", detail="reached only in collision with the cell")
            continue
        if math.isfinite(c) and c > 0:
            detail = f"no design gets closer than {_length(c)}"
        elif screened_any(p if not hit[name] else None):
            detail = "no IK run within the joint limits gets within its tolerance"
        else:
            detail = "out of reach of every twist setting (a sound reach bound)"
        entry.update(ruled_out_by="reach", closest_m=_finite(c) if math.isfinite(c) and c > 0 else None,
                     detail=detail)
    return out


NAMED = 5  # targets named per reason; the rest counted (a 100 x 100 region is 10,000 points)


def _grouped(bad: list[tuple[str, dict]]) -> str:
    """Per reason, in the order first met, the targets it rules out: "target 'a': …" or
    "targets 'a', 'b' and 3 more: …"."""
    why: dict[str, list[str]] = {}
    for n, t in bad:
        said = t["detail"] + (f" ({t['ruled_out_by']})" if t["ruled_out_by"] and t["ruled_out_by"] not in t["detail"]
                              else "")
        why.setdefault(said, []).append(n)
    parts = []
    for said, names in why.items():
        shown = ", ".join(f"'{n}'" for n in names[:NAMED])
        more = f" and {len(names) - NAMED:,} more" if len(names) > NAMED else ""
        parts.append(f"{'targets' if len(names) > 1 else 'target'} {shown}{more}: {said}")
    return "; ".join(parts)


def screened_any(probe: dict | None) -> bool:
    return probe is None or bool(probe["screened"])


def _finite(x: float) -> float | None:
    return round(float(x), 9) if math.isfinite(x) else None


def blamed_task(o) -> Task | StraightPath | None:
    """The task or path to point a no-design diagnostic at: when every chain that passed the
    static checks failed planning, the one most of them failed on (the first written on a tie)."""
    if o.designs or o.stopped or not o.failed_on or sum(o.failed_on.values()) != len(o.rejections):
        return None
    cell = o.problem.cell
    written = [t for t in (*cell.tasks, *cell.paths) if t.name in o.failed_on]
    return max(written, key=lambda t: o.failed_on[t.name], default=None)


def blamed_statement(o):
    """The statement a no-design diagnostic points at: the task or path every candidate failed
    planning on, else the one region whose points alone no design reaches; None: the design block."""
    task = blamed_task(o)
    if task is not None:
        return task
    missed = {n.partition("[")[0] for n, t in o.targets.items() if not t["reached_alone"]}
    if len(missed) != 1 or not all("[" in n for n, t in o.targets.items() if not t["reached_alone"]):
        return None
    return next((r for r in o.problem.cell.regions if r.name in missed), None)


def why_none(o) -> str:
    if o.stopped and o.not_planned:
        return (f"the search stopped ({o.stopped}) before planning and timing the "
                f"{counted(len(o.not_planned), 'design')} reaching every target it found (first: "
                f"{o.not_planned[0]}); give it more time (--time-budget)")
    head = f"the search stopped ({o.stopped}) before finding one; " if o.stopped else ""
    if o.regions_beyond:
        told = "; ".join(f"every point of region '{k}' lies beyond the reach of the longest arm in the bounds "
                         f"(by {_length(d)} at least)" for k, d in o.regions_beyond.items())
        return head + told + ", and `rank coverage` needs a design to serve some point of the cell's regions"
    if o.bases_searched == 0 and o.bases_touching:
        return head + (f"of the {o.bases_total} base poses, {o.bases_touching} put base_link into the cell and "
                       f"{o.bases_pruned} leave some target beyond the reach of the longest arm in the bounds")
    if o.bases_searched == 0:
        far = max(o.closest.values(), default=0.0)
        return head + (f"from every one of the {o.bases_pruned} base poses some target lies beyond the reach of "
                       f"the longest arm in the bounds (by {_length(far)} at least)")
    bad = [(n, t) for n, t in o.targets.items() if not t["reached_alone"]]
    if bad:
        return head + _grouped(bad)
    torque = [r for r in o.rejections if "torque" in r]
    if torque:
        return head + (f"every target can be reached alone, but torque rules out {counted(len(torque), 'chain')} "
                       f"(first: {torque[0]})")
    blamed = blamed_task(o)
    if blamed is not None:
        kind = "path" if isinstance(blamed, StraightPath) else "task"
        return head + (f"every target can be reached alone; {counted(len(o.rejections), 'chain')} reach every "
                       f"target, but none can be planned on {kind} '{blamed.name}' (first: {o.rejections[0]})")
    if o.rejections:
        return head + (f"every target can be reached alone; {counted(len(o.rejections), 'chain')} reach every "
                       f"target, but none passes the checks (first: {o.rejections[0]})")
    # stopped: only the chains searched are known not to (the others were not tried)
    which = "no chain searched before it stopped" if o.stopped else "no chain"
    more = "; give it more time (--time-budget)" if o.stopped else ""
    if not o.problem.cell.obstacles:
        return head + (f"every target can be reached alone, but {which} reaches all of them with one arm "
                       f"(within its joint limits, clear of itself){more}")
    return head + f"every target can be reached alone, but {which} reaches all of them without touching the cell{more}"
