"""Robot names are unique in a file; pose, target and obstacle names are unique in a robot."""
from __future__ import annotations

from ..diagnostics import codes
from ..model import Design
from ..model.robot import Obstacle, Pose, Target
from .context import Context


def run(design: Design, ctx: Context) -> Design:
    robots: set[str] = set()
    for r in design.robots:
        if r.name in robots:
            ctx.report(codes.DUPLICATE_ROBOT.at(r.name_span, name=r.name))
        robots.add(r.name)
        names: set[str] = set()
        items: list[Pose | Target | Obstacle] = [*r.poses, *r.targets, *r.obstacles]
        for item in sorted(items, key=lambda x: (x.span.line, x.span.col)):
            if item.name in names:
                ctx.report(codes.DUPLICATE_NAME.at(item.span, name=item.name, block=f"robot '{r.name}'"))
            names.add(item.name)
    return design
