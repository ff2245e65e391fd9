"""DH table -> module chain (paper section 4.2), with the policy for what its rules leave open.

The paper's rules, for row i = (a, alpha, d, theta) of a standard DH table:
  1. a != 0            -> unit i carries a link module (type 3 or 4);
  2. a == 0, alpha != 0 -> the twist is set with the pivot of unit i+1 (intersecting axes);
  3. a != 0, alpha != 0 -> the twist is set at unit i's connection port (skew axes);
  4. d != 0            -> a unit without a link module (type 1 or 2), unless rule 1 applies.

Policy for the rest (documented in docs/language.md; reproduces every published sequence the rules
decide — Example B, and Table 3's planar, spatial and skew rows):
  * Ip1 or Ip2: unit 1 sits on the base through Ip1; later units connect through Ip2, as in the
    paper's results — except after a row with a = 0 and alpha = 0, where Ip2's 29.7 mm offset
    would add an a the table does not ask for, so Ip1 keeps the axes collinear.
  * Link length: with fit_links, unit i's link is printed a_i - x01(unit i+1) long so that the
    common normal is exactly a_i; otherwise the library's standard link is used.
  * Twists: rounded to the library's realisable set (a twist-rounded warning names both).
    The last row's twist, having no next unit, goes into the tool orientation.
  * H or L: the rules allow H^k L^(n-k) with k <= eps(H), n-k <= eps(L); among those, the k
    whose worst static gravity torque leaves the largest smallest margin to tau_nom (ties: the
    lighter arm). That is the torque the modules must carry, not just the position they reach.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from ..diagnostics import Diagnostic, codes
from ..formatting import angle
from ..model import Robot, Transform, UnitSpec, resolved
from ..model.library import Library

TOL_A = 1e-6  # m: below this an a is zero
TOL_ALPHA = 1e-9  # rad


@dataclass
class Conversion:
    units: tuple[UnitSpec, ...]
    tool: Transform
    diagnostics: list[Diagnostic] = field(default_factory=list)


def structure(robot: Robot, lib: Library) -> Conversion:
    """Unit types, twists and link lengths for the table; every unit still of variant H."""
    rows = robot.dh or ()
    n = len(rows)
    link = [abs(r.a) > TOL_A for r in rows]
    ip1 = [True] + [not link[i] and abs(rows[i].alpha) < TOL_ALPHA for i in range(n - 1)]
    kind_of = {(True, False): 1, (False, False): 2, (True, True): 3, (False, True): 4}
    kinds = [kind_of[(ip1[i], link[i])] for i in range(n)]
    pivots, ports = [0.0] * n, [0.0] * n
    tool_pitch = 0.0
    diags: list[Diagnostic] = []

    def rounded(i: int, alpha: float, where: str, ts) -> float:
        real = math.radians(ts.nearest(math.degrees(alpha)))
        wrapped = math.remainder(alpha - real, 2 * math.pi)
        if abs(wrapped) > 1e-9:
            diags.append(codes.TWIST_ROUNDED.at(rows[i].span, row=i + 1, requested=f"{alpha:.6g} rad ({angle(alpha)})",
                                                realised=angle(real), where=where, step=f"{ts.step_deg:g}deg"))
        return real

    for i, r in enumerate(rows):
        if abs(r.alpha) < TOL_ALPHA:
            continue
        if link[i]:
            ports[i] = rounded(i, r.alpha, f"port of unit {i + 1}", lib.twists.port)
        elif i + 1 < n:
            pivots[i + 1] = rounded(i, r.alpha, f"pivot of unit {i + 2}", lib.twists.pivot)
        else:
            tool_pitch = r.alpha  # the tool mount is not a module: any angle
    units = []
    for i, r in enumerate(rows):
        length = None
        if link[i] and robot.dh_fit_links:
            x01_next = lib.units[kinds[i + 1]].x01 if i + 1 < n else 0.0
            length = abs(r.a) - x01_next
        spans = {"link": r.span} if length is not None else {}
        spans.update({k: r.span for k, v in (("pivot", pivots[i]), ("port", ports[i])) if v})
        units.append(
            UnitSpec(
                name=f"{lib.rules.first_variant}{kinds[i]}",
                variant=lib.rules.first_variant,
                kind=kinds[i],
                pivot=pivots[i],
                port=ports[i],
                link=length,
                span=r.span,
                param_spans=spans,
            )
        )
    return Conversion(tuple(units), Transform(rpy=(0.0, tool_pitch, 0.0)), diags)


def with_variants(units: tuple[UnitSpec, ...], variants: list[str]) -> tuple[UnitSpec, ...]:
    return tuple(
        u.model_copy(update={"variant": v, "name": f"{v}{u.kind}"}) for u, v in zip(units, variants, strict=True)
    )


def choose_variants(robot: Robot, lib: Library, units: tuple[UnitSpec, ...], tool: Transform) -> list[str]:
    """H^k L^(n-k): the rule-abiding k with the best worst-case torque margin."""
    from ..physical.statics import Statics

    n = len(units)
    heavy, light = lib.rules.first_variant, lib.rules.last_variant
    eps_h, eps_l = lib.variants[heavy].actuator.epsilon, lib.variants[light].actuator.epsilon
    feasible = [k for k in range(1, n) if k <= eps_h and n - k <= eps_l]
    if not feasible:  # the chain cannot obey the rules; the checks will say so
        k = max(1, min(eps_h, n - 1 if n > 1 else 1))
        return [heavy] * k + [light] * (n - k)
    best: tuple[float, list[str]] | None = None
    for k in feasible:
        variants = [heavy] * k + [light] * (n - k)
        trial = resolved(robot, lib, units=with_variants(units, variants), tool=tool)
        worst = Statics(trial).worst(samples=64)
        nominal = [lib.variants[v].actuator.torque_nominal for v in variants]
        margin = min((t_nom - t) / t_nom for t_nom, t in zip(nominal, worst, strict=True))
        if best is None or margin > best[0] + 1e-9:
            best = (margin, variants)
    assert best is not None  # feasible is not empty
    return best[1]


def convert(robot: Robot, lib: Library) -> Conversion:
    conv = structure(robot, lib)
    if conv.units:
        variants = choose_variants(robot, lib, conv.units, conv.tool)
        conv.units = with_variants(conv.units, variants)
    return conv
