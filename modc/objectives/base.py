"""What an objective of `modc design` is (`rank modules, mass, …`): its name, how it orders
designs, and how report.html, `ranking.json` and the why sentences show it. The value is read
from a design as modc.design.rank.Design has it (modules, mass, margin, plans, coverage), so an
objective module imports nothing of the search."""
from __future__ import annotations

from collections.abc import Callable
from typing import Any

from ..records import Record


class Objective(Record, kw_only=False):
    name: str  # as `rank` names it: an identifier
    summary: str  # one line for editors (completion, hover) and the YAML schema
    words: str  # how a sentence or a column heading names it
    value: Callable[[Any], float | None]  # of a design, in SI units; None: not known yet (ranks level)
    unit: str = ""  # of the value as shown, with its leading space (" kg")
    scale: float = 1.0  # shown = value * scale (a share shown in %: 100)
    digits: int = 0  # decimals shown in a table
    larger_first: bool = False  # a larger value ranks first (margin, coverage)
    task: bool = False  # known only once a design's tasks are planned and timed
    needs_task: bool = False  # measured on the cell's tasks and paths: `rank` it only in a cell with one
    default: bool = False  # ranked, in registry order, after the objectives `rank` names
    planned_column: bool = False  # report.html shows it for planned designs even when not ranked

    def key(self, design: Any) -> float:
        """The sort key: smaller ranks first; rounded to 1e-9 so that noise does not decide."""
        v = self.value(design)
        if v is None:
            return 0.0
        r = round(float(v), 9)
        return -r if self.larger_first else r

    def shown(self, design: Any) -> float:
        v = self.value(design)
        return float("nan") if v is None else float(v) * self.scale
