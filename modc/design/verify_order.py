"""Exact checks in ranking order of what the screens passed: a chain is checked once every chain
that could rank before it has been found (settle), until `top` kinematically distinct designs
pass (H/L variant swaps of one arm count once: they are alternatives of one entry)."""
from __future__ import annotations

import numpy as np

from ..model import ResolvedProblem
from . import space
from .evaluate import Candidate, verify
from .rank import Design, identity
from .search import ShapeResult

TRIES = 3  # twist settings verified per chain before giving up on it
SAME = 1e-6  # kg (or units): ranking values this close are level when bounding what is unsearched
VERIFY_FACTOR = 4  # at most this many exact checks per design asked for, per number of units


class Verifier:
    def __init__(self, problem: ResolvedProblem, top: int, out, mass):
        self.problem, self.top, self.out, self.mass = problem, top, out, mass
        self.pending: list[tuple] = []
        self.accepted: list[Design] = []
        self.keys: list[tuple] = []
        self.checks = 0
        # n -> the least mass of a shape of more than n units in the search (set by the search;
        # absent: none)
        self.floors: dict[int, float] = {}

    def add(self, n: int, splits, res: ShapeResult) -> None:
        from .rank import Screened, key

        if not res.found:
            return
        p = self.problem
        for variants in splits:
            if not all(space.allowed(p, v, k) for v, k in zip(variants, res.shape.kinds, strict=True)):
                continue
            found = tuple(f for f in res.found if self._holds(res, variants, f))
            if not found:
                continue
            mass = self.mass(p, res.shape, variants)
            chain = "-".join(f"{v}{k}" for v, k in zip(variants, res.shape.kinds, strict=True)) + res.shape.label()
            self.pending.append((key(p.rank, Screened(n, mass, None, chain)), n, mass, res.shape, found, variants))
            self.out.screened += 1

    def _holds(self, res: ShapeResult, variants, f) -> bool:
        """The static torque screen: gravity torques at the poses found for the targets (inside the
        limits, so no more than the worst case) within every actuator's peak."""
        from ..model import resolved
        from ..physical.statics import Statics
        from .evaluate import robot_for

        lib = self.problem.cell.library
        cand = Candidate(res.shape, variants, f.pivots, f.ports, f.solutions)
        robot = robot_for(self.at(f), cand, {}, self.problem.name)
        # the compiler's own static model (pinocchio's g(q) to rounding), batched over the poses
        tau = np.abs(Statics(resolved(robot, lib)).gravities([sols[0] for sols in f.solutions]))
        peak = np.array([lib.variants[v].actuator.torque_peak for v in variants])
        if np.all(tau <= peak):
            return True
        self.out.rejections.append(f"{'-'.join(u.name for u in cand.units())}: over peak torque at a target pose")
        return False

    def at(self, f) -> ResolvedProblem:
        """The problem a kept setting is checked in (base placement: its base pose's cell)."""
        return self.problem

    def _primary_keys(self) -> list[tuple]:
        best: dict[tuple, tuple] = {}
        for d, k in zip(self.accepted, self.keys, strict=True):
            i = identity(d)
            best[i] = min(best.get(i, k), k)
        return sorted(best.values())

    @property
    def bounded(self) -> bool:
        """Can a design rank before every unsearched shape (the first objective ranked is modules
        or mass, which the search's order bounds)? Then the search may stop early (done())."""
        return bool(self.problem.rank) and self.problem.rank[0] in ("modules", "mass")

    def frontier(self, n: int, below: float) -> tuple | None:
        """The least ranking key (the static objectives', chain text left out) any design not yet
        found could have: the shapes of n units from mass `below` kg on (inf: none left) and every
        shape of more units (self.floors[n]: the least mass among them; absent: none). Modules
        and mass bound it; any other objective (margin) is unbounded there, so no design is ahead
        of an unsearched shape on it. None: nothing is left unsearched."""
        inf = float("inf")
        lows = ([(n, below)] if below != inf else []) + \
            ([(n + 1, self.floors[n])] if self.floors.get(n, inf) != inf else [])
        keys = [tuple(float(m) if o == "modules" else mass if o == "mass" else -inf for o in self.problem.rank)
                for m, mass in lows]
        return min(keys) if keys else None

    def _ahead(self, k: tuple, bound: tuple | None) -> bool:
        """Does a design of key k rank before everything left unsearched (bound: frontier())?
        Objective by objective, values within SAME of each other are level (equal masses summed
        in another order differ in the last bits). Level on every objective ranked: ahead when
        margin is not ranked (nothing can tell them apart but the chain's text), else not (the
        unsearched shape's margin may be larger)."""
        if bound is None:
            return True
        for h, b in zip(k, bound, strict=False):
            if abs(h - b) > SAME:
                return h < b
        return "margin" not in self.problem.rank

    def done(self, n: int, next_mass: float, count: int | None = None) -> bool:
        """count (default top) distinct designs found that rank before every shape not yet
        searched (frontier(n, next_mass))."""
        bound = self.frontier(n, next_mass)
        return sum(self._ahead(k, bound) for k in self._primary_keys()) >= (count or self.top)

    def settle(self, n: int, below: float) -> None:
        """Check the pending chains that rank before every shape not yet searched (frontier(n,
        below)), best first."""
        bound = self.frontier(n, below)

        def due(e) -> bool:
            return self._ahead(e[0], bound)

        ready = sorted((e for e in self.pending if due(e)), key=lambda e: e[0])
        self.pending = [e for e in self.pending if not due(e)]
        for k, _n, _mass, shape, found, variants in ready:
            better = self._primary_keys()[: self.top]
            if len(better) >= self.top and k[:2] > better[-1][:2]:
                break  # ranks behind top designs already checked (equal keys still compete on margin)
            if self.checks >= VERIFY_FACTOR * self.top * 4:
                break
            for f in found[:TRIES]:
                cand = Candidate(shape, variants, f.pivots, f.ports, f.solutions)
                self.checks += 1
                v = verify(self.at(f), cand)
                if isinstance(v, str):
                    self.out.rejections.append(f"{'-'.join(u.name for u in cand.units())}: {v}")
                    continue
                self.accepted.append(Design(cand, v))
                self.keys.append(k)
                break

    def swaps(self, d: Design) -> Design:
        """d with every other H/L split of its arm that passes the exact check as an alternative."""
        from dataclasses import replace

        from .rank import order

        p = self.problem
        c = d.candidate
        have = {a.candidate.variants for a in d.alternatives} | {c.variants}
        found = list(d.alternatives)
        for variants in space.variant_splits(p, c.shape.n):
            allowed = all(space.allowed(p, v, k) for v, k in zip(variants, c.shape.kinds, strict=True))
            if variants in have or not allowed:
                continue
            cand = Candidate(c.shape, variants, c.pivots, c.ports, c.solutions)
            v = verify(p, cand)
            if not isinstance(v, str):
                found.append(Design(cand, v))
        return replace(d, alternatives=tuple(order(found, p.rank)))
