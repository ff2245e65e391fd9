"""The worst-case static torque analysis behind modc's cache (what the torque pass runs): keyed by
the checked robot itself, so a robot whose result is cached needs no numpy, no pinocchio and no
physical description; modc.dynamics.worst computes a missing one on the numpy statics.
"""
from __future__ import annotations

import json
import math

from .. import cache
from ..model import ResolvedRobot
from ..records import Record, as_plain

SAMPLES, REFINE, SEED = 512, 4, 0  # worst_case()'s search: samples of the joint box, refined, seed
ALGORITHM = "2"  # bump when worst_case() could give another result for the same input


class JointWorst(Record, kw_only=False):
    name: str
    variant: str
    tau: float  # max |g_i(q)|, N·m
    q: tuple[float, ...]  # the pose where it happens, rad
    tau_nom: float
    tau_max: float

    @property
    def margin(self) -> float:
        """Share of the peak torque left in the worst pose (negative: overloaded)."""
        return (self.tau_max - self.tau) / self.tau_max

    def to_json(self) -> dict:
        """The torque report's per-joint record (docs/conventions.md), rounded so that reports are stable."""
        return {"name": self.name, "unit": self.variant, "tau_gravity_max": round(self.tau, 6), "tau_nom": self.tau_nom,
                "tau_max": self.tau_max, "margin": round(self.margin, 6),
                "pose": [round(math.degrees(x), 1) + 0.0 for x in self.q], "status": self.level}

    @property
    def level(self) -> str:
        return "over-peak" if self.tau > self.tau_max else "over-nominal" if self.tau > self.tau_nom else "ok"


def analyse(robot: ResolvedRobot, payload_mass: float | None = None) -> list[JointWorst]:
    """The worst case for a checked robot; payload_mass (kg) replaces the file's payload mass,
    keeping its centre of mass (tool0's origin if the file has none). Cached by content."""
    payload = None
    if payload_mass is not None:
        com = robot.payload.com if robot.payload is not None else (0.0, 0.0, 0.0)
        payload = (payload_mass, com)
    key = _key(robot, payload)
    hit = cache.get("torque", key)
    if hit is not None:
        try:
            return [JointWorst(j[0], j[1], j[2], tuple(j[3]), j[4], j[5]) for j in json.loads(hit)]
        except (ValueError, TypeError, IndexError, KeyError):  # not an entry of this format: computed again
            pass
    from ..physical.assembly import describe
    from ..physical.statics import Statics
    from .model import with_payload
    from .worst import worst_case

    # the numpy statics: pinocchio's g(q) to rounding (the tests compare), without importing it (~0.06 s)
    result = worst_case(Statics(robot, describe(with_payload(robot, payload))))
    cache.put("torque", key, json.dumps([[j.name, j.variant, j.tau, list(j.q), j.tau_nom, j.tau_max]
                                         for j in result]).encode())
    return result


def _key(robot: ResolvedRobot, payload: tuple | None) -> str:
    """Everything worst_case() reads, as written in the checked robot (its library included;
    source positions left out): the arm's description, gravity and the actuators are functions of
    it. A superset of what matters (a renamed pose misses the cache): never a wrong hit."""
    plain = as_plain(robot, hidden=False)  # hidden: source spans and the torque result itself
    return cache.key(ALGORITHM, repr(plain), repr(payload), repr((SAMPLES, REFINE, SEED))) + ".json"
