"""`modc view DIR/ranking.json`: the designs of a `modc design` run (docs/conventions.md), best
first. Each design's robot file, and its task's trajectory (DIR/<name>_<rank>.traj.json) when the
design block has tasks, are the files ranking.json names, beside it: a name that leads out of DIR
(an absolute path, `..`, a symbolic link pointing elsewhere) refuses the whole ranking, so a
ranking.json handed over from elsewhere cannot make the page read other files.

The block's reference arm (`compare with chain …`, ranking.json's "reference"), when its file was
written, comes after the designs. A design with a trajectory plays it (the segment on view named from the trajectory's
"segments"); a design without one starts at its first target's pose (ranking.json's "q").

    page = RankingPage(Ranking("out/ranking.json"))
    page.choose(1)          # the second design
    page.seek(1.5); page.segment()
"""
from __future__ import annotations

import bisect
import math
import os
from dataclasses import dataclass
from pathlib import Path

from .. import names, trajectory
from .page import Page, Source, ViewError


def _number(x: object) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


@dataclass(frozen=True)
class Segment:
    """One piece of a task's trajectory, as `modc plan --task` names it."""

    kind: str  # approach | motion | straight
    start: str
    end: str
    t0: float  # s, in the trajectory
    duration: float  # s

    def label(self) -> str:
        return f"{self.kind} {self.start} → {self.end} ({self.duration:.3f} s)"


def segments_of(path: Path) -> list[Segment]:
    """The "segments" key of a task trajectory (modc.plan.task.TaskPlan.dumps); [] when absent
    or not as written there (the motion still plays, unnamed)."""
    from ..files import InputProblem, read_json

    try:
        doc = read_json(path)
    except (OSError, InputProblem):
        return []
    raw = doc.get("segments") if isinstance(doc, dict) else None
    out: list[Segment] = []
    for s in raw if isinstance(raw, list) else []:
        if not (isinstance(s, dict) and all(isinstance(s.get(k), str) for k in ("kind", "from", "to"))
                and _number(s.get("t_start_s")) and _number(s.get("duration_s"))):
            return []
        out.append(Segment(s["kind"], s["from"], s["to"], float(s["t_start_s"]), float(s["duration_s"])))
    return out


class Ranking:
    """The designs of a ranking.json, sorted by rank; every file they name checked to lie in its folder."""

    def __init__(self, path: str | os.PathLike):
        self.path = Path(path)
        from ..files import InputProblem, read_json

        try:  # under the limits of every input: a regular file, bounded, UTF-8, not nested deeply
            doc = read_json(self.path)
        except OSError as e:
            raise ViewError(f"cannot read {self.path}: {e.strerror or e}") from None
        except InputProblem as e:
            raise ViewError(f"{self.path}: {e}") from None
        designs = doc.get("designs") if isinstance(doc, dict) else None
        if not isinstance(designs, list) or not designs:
            raise ViewError(f'{self.path}: expected {{"designs": [{{"rank": …, "file": …}}, …]}}, at least one design')
        for k, d in enumerate(designs):
            if not (isinstance(d, dict) and isinstance(d.get("file"), str) and isinstance(d.get("rank"), int)):
                raise ViewError(f'{self.path}: designs[{k}]: expected an object with an integer "rank" and a "file"')
            if "traj" in d and not isinstance(d["traj"], str):
                raise ViewError(f'{self.path}: designs[{k}].traj: expected the name of a trajectory file')
        order = sorted(range(len(designs)), key=lambda k: designs[k]["rank"])
        self.designs = [designs[k] for k in order]
        where = [f"designs[{k}]" for k in order]
        # the design blocks' reference arms (`compare with chain …`) that were written, after the designs
        refs = doc.get("reference")
        for name, r in sorted(refs.items()) if isinstance(refs, dict) else []:
            if isinstance(r, dict) and isinstance(r.get("file"), str) and isinstance(r.get("traj", ""), str):
                self.designs.append({**r, "rank": None})
                where.append(f"reference.{names.shown(name, 60)}")
        # checked here, for every design: the page opens none of them if one leads out
        self._files = [self._inside(d["file"], f"{w}.file") for w, d in zip(where, self.designs, strict=True)]
        self._trajs = [self._inside(d["traj"], f"{w}.traj") if "traj" in d else None
                       for w, d in zip(where, self.designs, strict=True)]

    def _inside(self, name: str, where: str) -> Path:
        folder = self.path.parent.resolve()
        shown = names.shown(name, 60)
        if not name or "\x00" in name or Path(name).is_absolute():
            raise ViewError(f"{self.path}: {where}: '{shown}' is not a file name beside ranking.json")
        try:
            resolved = (folder / name).resolve()
        except (OSError, RuntimeError, ValueError):  # a symlink loop, an unreadable path
            raise ViewError(f"{self.path}: {where}: '{shown}' cannot be resolved") from None
        if not resolved.is_relative_to(folder):
            raise ViewError(f"{self.path}: {where}: '{shown}' leads out of {self.path.parent} (the folder of "
                            "ranking.json); refused: a ranking names only the files `modc design` wrote beside it")
        return self.path.parent / name

    def file(self, k: int) -> Path:
        return self._files[k]

    def traj(self, k: int) -> Path | None:
        return self._trajs[k]

    def trajectory(self, k: int) -> trajectory.Trajectory | None:
        from .page import read_trajectory

        path = self._trajs[k]
        return None if path is None else read_trajectory(str(path))

    def cycle_time(self, k: int) -> float | None:
        t = self.designs[k].get("cycle_time_s")
        return float(t) if _number(t) else None

    def caption(self, k: int) -> str:
        d = self.designs[k]
        rank = "the reference arm" if d["rank"] is None else f"rank {d['rank']}"
        parts = [f"design {k + 1} of {len(self.designs)}: {rank}"]
        if isinstance(d.get("chain"), str):
            parts.append(d["chain"])
        mass = d.get("mass_kg")
        if _number(mass):
            parts.append(f"{mass:.3g} kg")
        cycle = self.cycle_time(k)
        if cycle is not None:
            task = d.get("traj_task")
            parts.append(f"cycle time {cycle:.3f} s" + (f" ('{task}')" if isinstance(task, str) else ""))
        return ", ".join(parts) + f" ({d['file']})"

    def choice(self, k: int) -> str:
        """The design's line in the page's list: rank, chain, cycle time (unique: the rank leads)."""
        d = self.designs[k]
        chain = names.shown(d["chain"], 60) if isinstance(d.get("chain"), str) else names.shown(d["file"], 60)
        cycle = self.cycle_time(k)
        rank = "reference" if d["rank"] is None else f"rank {d['rank']}"
        return f"{k + 1}. {rank}: {chain}" + (f", {cycle:.3f} s" if cycle is not None else "")

    def target_poses(self, k: int, dof: int) -> list[tuple[str, tuple[float, ...]]]:
        """(target, q) of the design's targets as ranking.json gives them; entries not a list of
        dof finite numbers are left out."""
        targets = self.designs[k].get("targets")
        out = []
        for name, t in (targets.items() if isinstance(targets, dict) else []):
            q = t.get("q") if isinstance(t, dict) else None
            if isinstance(q, list) and len(q) == dof and all(_number(x) for x in q):
                out.append((name, tuple(float(x) for x in q)))
        return out


class RankingPage(Page):
    """A Page paging through a ranking: each design's file checked when first shown, with its
    task's trajectory to play, else at its first target's pose."""

    def __init__(self, ranking: Ranking, library: str | None = None):
        self.ranking = ranking
        self._segments: dict[int, list[Segment]] = {}
        sources = [Source(ranking.file(k), library=library, traj=ranking.trajectory(k))
                   for k in range(len(ranking.designs))]
        super().__init__(sources, [ranking.caption(k) for k in range(len(ranking.designs))])

    def _follow(self) -> None:
        first = self._shown == -1
        super()._follow()
        arm = self.arm
        if not first or arm is None:
            return
        if self.source.trajectory is not None:
            self.seek(0.0)
        else:
            poses = self.ranking.target_poses(self.index, arm.dof)
            if poses:
                self.q = arm.clamp(poses[0][1])

    def choose(self, k: int) -> None:
        """Show design k (0: the best)."""
        if not 0 <= k < len(self.sources):
            raise IndexError(k)
        self.index = k
        self._enter()

    def segments(self) -> list[Segment]:
        if self.index not in self._segments:
            path = self.ranking.traj(self.index)
            self._segments[self.index] = segments_of(path) if path is not None else []
        return self._segments[self.index]

    def segment(self) -> Segment | None:
        """The segment playing at the page's time."""
        segs = self.segments()
        if not segs or self.source.trajectory is None:
            return None
        k = bisect.bisect_right([s.t0 for s in segs], self.t) - 1
        return segs[max(k, 0)]
