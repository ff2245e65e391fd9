"""Collision queries on a PyBullet scene (scene.Scene inherits them): which link pairs are
checked, which touch, which reach into an obstacle; and the pairs an SRDF disables.

Collision geometry. PyBullet turns every <collision> mesh of a moving link into its convex hull
(one hull per mesh, so a link is a compound of hulls). Hulls contain the meshes, so a pair found
apart is apart; a pair found in contact may only touch the hull of a concave part (the input
casings and twist units are concave). Contacts are reported only beyond CONTACT_TOL of
penetration: surfaces that merely touch (float32 geometry) are not collisions.

Which pairs are checked is physical/collisions.py's rule, the one `modc plan` and the SRDF use:
links with geometry, not adjacent (parent and child of a joint, after collapsing links without
collision geometry such as tool0 and payload: MoveIt's rule), and not a pair the collision matrix
skips (CollisionMatrix.unchecked: Adjacent, Default, Always; "Never" pairs stay checked).
"""
from __future__ import annotations

import itertools
import xml.etree.ElementTree as ET
from collections.abc import Iterable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

CONTACT_TOL = 1e-3  # m of hull penetration below which two bodies only touch


@dataclass(frozen=True)
class Contact:
    a: str  # link name
    b: str  # link or obstacle name
    distance: float  # m, negative = penetration depth

    @property
    def depth(self) -> float:
        return -self.distance


class CollisionQueries:
    """Mixed into scene.Scene, whose fields these are."""

    client: Any
    body: int
    links: dict[str, int]
    parents: dict[str, str]
    geometry_links: list[str]
    obstacles: dict[str, int]

    def adjacent_pairs(self) -> set[frozenset[str]]:
        """Parent-child pairs, after collapsing links without collision geometry (tool0,
        payload): their neighbours become adjacent to each other (the SRDF's rule, one home)."""
        from ..physical.collisions import adjacent_pairs

        has = set(self.geometry_links)
        edges = [(parent, child) for child, parent in self.parents.items()]
        return adjacent_pairs(tuple(self.links), edges, lambda name: name in has)

    def self_collision_pairs(self, allowed: Iterable[Iterable[str]] = ()) -> list[tuple[str, str]]:
        """Link pairs to check: links with geometry, not adjacent, not in `allowed`."""
        skip = self.adjacent_pairs() | {frozenset(p) for p in allowed}
        return [(a, b) for a, b in itertools.combinations(self.geometry_links, 2) if frozenset((a, b)) not in skip]

    def self_collisions(self, allowed: Iterable[Iterable[str]] = (), tol: float = CONTACT_TOL) -> list[Contact]:
        """Pairs of links (not adjacent, not allowed) whose hulls interpenetrate by more than tol,
        deepest first."""
        self.client.performCollisionDetection()
        out = []
        for a, b in self.self_collision_pairs(allowed):
            pts = self.client.getClosestPoints(self.body, self.body, 0.0, self.links[a], self.links[b])
            if pts:
                d = min(pt[8] for pt in pts)
                if d < -tol:
                    out.append(Contact(a, b, float(d)))
        return sorted(out, key=lambda c: (c.distance, c.a, c.b))

    def environment_collisions(self, tol: float = CONTACT_TOL) -> list[Contact]:
        """(link, obstacle) pairs whose shapes interpenetrate by more than tol, deepest first."""
        out = []
        for oname, ob in self.obstacles.items():
            for lname in self.geometry_links:
                pts = self.client.getClosestPoints(self.body, ob, 0.0, self.links[lname], -1)
                if pts:
                    d = min(pt[8] for pt in pts)
                    if d < -tol:
                        out.append(Contact(lname, oname, float(d)))
        return sorted(out, key=lambda c: (c.distance, c.a, c.b))

    def environment_physics(self, enabled: bool) -> None:
        """Whether obstacles push the arm in the dynamics (off by default: they are checked
        geometrically, so a pose inside a shelf is reported instead of exploding)."""
        for ob in self.obstacles.values():
            for i in self.links.values():
                self.client.setCollisionFilterPair(self.body, ob, i, -1, int(enabled))


def srdf_disabled_pairs(srdf: str | Path, include_never: bool = False) -> set[frozenset[str]]:
    """<disable_collisions> pairs of a MoveIt SRDF. Pairs disabled as "Never" (never seen in
    contact while sampling: skipped by MoveIt for speed, not because contact is fine) are left
    out unless include_never: a held pose that brings them into contact is a real collision."""
    out = set()
    for e in ET.parse(srdf).getroot().iter("disable_collisions"):
        if e.get("reason") == "Never" and not include_never:
            continue
        link1, link2 = e.get("link1"), e.get("link2")
        if link1 is None or link2 is None:  # names no pair of links: disables nothing
            continue
        out.add(frozenset((link1, link2)))
    return out


__all__ = ["CONTACT_TOL", "CollisionQueries", "Contact", "srdf_disabled_pairs"]
