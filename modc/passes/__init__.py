"""Semantic passes: one module per pass, run in this order over the whole design."""
from __future__ import annotations

from ..model import Design
from . import (
    check_assembly,
    check_environment,
    check_modules,
    check_names,
    check_poses,
    check_problems,
    check_reach,
    check_torque,
    check_twists,
    convert_dh,
    resolve_library,
)
from .context import Context

PASSES = (
    resolve_library,
    convert_dh,
    check_names,
    check_modules,
    check_assembly,
    check_twists,
    check_poses,
    check_environment,
    check_reach,
    check_torque,
    check_problems,
)


def run_all(design: Design, ctx: Context) -> Design:
    for p in PASSES:
        design = p.run(design, ctx)
    return design


__all__ = ["PASSES", "Context", "run_all"]
