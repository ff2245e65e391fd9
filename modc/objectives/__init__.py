"""The registry of `modc design`'s ranking objectives: one module per objective, in the default
order. A new objective is its module here and its line below; the `rank` statement's check,
editors' completion, the YAML schema, the ranking's order, report.html's columns and why
sentences, and ranking.json's "objectives" read the registry."""
from __future__ import annotations

from . import coverage, cycle_time, energy, margin, mass, modules
from .base import Objective

REGISTRY: dict[str, Objective] = {m.OBJECTIVE.name: m.OBJECTIVE
                                  for m in (modules, mass, margin, cycle_time, energy, coverage)}
DEFAULT: tuple[str, ...] = tuple(n for n, o in REGISTRY.items() if o.default)  # ranked unless named first
TASK: frozenset[str] = frozenset(n for n, o in REGISTRY.items() if o.task)

__all__ = ["DEFAULT", "REGISTRY", "TASK", "Objective"]
