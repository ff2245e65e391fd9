"""What the live page shows, apart from any browser library: the design on view (one file, or
one design of a ranking.json), the joint values, named poses, trajectory playback, and the
re-check of the file whenever it changes on disk (an error keeps the last good arm).

    page = Page([Source("arm.mod")])
    page.poll()              # True when the file changed and was checked again
    page.set_joint(0, 0.3)   # rad, clamped to the joint's range
    page.arm.tool0(page.q), page.arm.torques(page.q)
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .. import trajectory
from ..compiler import COMPILE_ANALYSES, InputError, check_file
from ..diagnostics import Diagnostic, codes
from ..diagnostics.render import render_text
from ..model.select import RobotChoiceError, choose_robot
from .arm import Arm

if TYPE_CHECKING:
    from .ranking import Ranking


class ViewError(ValueError):
    """A command-line problem (exit 2): an unreadable trajectory or ranking.json."""


def _stamp(path: Path) -> tuple[int, int] | None:
    try:
        st = os.stat(path)
    except OSError:  # an editor replacing the file: look again at the next poll
        return None
    return (st.st_mtime_ns, st.st_size)


# Errors of an arm that is well formed but too weak: `modc FILE -o OUT` refuses it, the page
# shows it (with the error and the module named) so the user sees what to change.
DRAWABLE_ERRORS = frozenset({codes.TORQUE_OVER_PEAK.name})


class Source:
    """One .mod file, checked again whenever it changes, as `modc FILE -o OUT` checks it (torque
    analysis included). `arm` is the last good robot (None until the file first checks without
    errors other than DRAWABLE_ERRORS); `diagnostics` the text of the last check's diagnostics
    (errors and warnings), empty when there are none; `found` the same as Diagnostic objects, and
    `current` whether `arm` is the one they are about."""

    def __init__(self, path: str | os.PathLike, robot: str | None = None, library: str | None = None,
                 traj: trajectory.Trajectory | None = None):
        self.path = Path(path)
        self.robot_name = robot if robot is not None else (traj.robot if traj is not None else None)
        self.library = library
        self.traj = traj  # as read, checked against every new arm
        self.arm: Arm | None = None
        self.trajectory: trajectory.Trajectory | None = None  # traj in joint_1..n order, when it fits the arm
        self.diagnostics = ""
        self.found: list[Diagnostic] = []
        self.current = False
        self.errors = False
        self.generation = 0  # counts arms: the page rebuilds its scene when it changes
        self._stamp: tuple[int, int] | None = None

    def load(self, strict: bool = False) -> None:
        """Check the file now. strict: an unreadable file or an unknown robot raises (the first
        load, which is a command-line error) instead of showing in the page."""
        self._stamp = _stamp(self.path)
        self.current = False
        try:
            checked = check_file(self.path, self.library, analyses=COMPILE_ANALYSES, torque_severity="error")
            say = '--robot NAME, or "robot" in the trajectory file' if self.traj is not None else "--robot NAME"
            drawable = all(d.code in DRAWABLE_ERRORS for d in checked.diagnostics if d.is_error)
            robot = choose_robot(checked.design, self.robot_name, say=say) if drawable else None
        except (InputError, RobotChoiceError) as e:
            if strict:
                raise
            self.diagnostics, self.found, self.errors = render_text([e.diagnostic]), [e.diagnostic], True
            return
        self.diagnostics, self.errors = render_text(checked.diagnostics, checked.sources), not checked.ok
        self.found = list(checked.diagnostics)
        if robot is None:
            return
        self.current = True
        self.arm = Arm(robot)
        self.generation += 1
        self.trajectory = None
        if self.traj is not None:
            problems = trajectory.validate_for(self.traj, robot)
            if problems:
                self.diagnostics += "\n".join(["", "trajectory:", *problems]).lstrip("\n")
            else:
                self.trajectory = self.traj.in_order(self.arm.joint_names)

    def poll(self) -> bool:
        """Check the file again if it changed on disk since the last check; True if it did."""
        stamp = _stamp(self.path)
        if stamp is None or stamp == self._stamp:
            return False
        self.load()
        return True


def read_trajectory(path: str) -> trajectory.Trajectory:
    try:
        traj, errors = trajectory.load(path)
    except OSError as e:
        raise ViewError(f"cannot read {path}: {e.strerror or e}") from None
    if traj is None:
        raise ViewError(f"{path}: " + "; ".join(errors))
    return traj


class Page:
    """The state behind the page. One source, or a ranking paged through (each design's file
    checked when first shown, then watched while it is on view)."""

    def __init__(self, sources: list[Source], captions: list[str] | None = None):
        self.sources = sources
        self.captions = captions or [str(s.path) for s in sources]
        self.index = 0
        self.q: tuple[float, ...] = ()
        self.playing = False
        self.t = 0.0
        self._shown = -1  # generation of the arm q belongs to
        self._loaded: set[int] = set()
        self._enter()

    @classmethod
    def for_ranking(cls, ranking: Ranking, library: str | None = None) -> Page:
        from .ranking import RankingPage

        return RankingPage(ranking, library)

    @property
    def source(self) -> Source:
        return self.sources[self.index]

    @property
    def arm(self) -> Arm | None:
        return self.source.arm

    @property
    def caption(self) -> str:
        return self.captions[self.index]

    def _enter(self) -> None:
        if self.index not in self._loaded:
            self._loaded.add(self.index)
            self.source.load()
        self._shown = -1
        self._follow()

    def _follow(self) -> None:
        """A new arm of the same file keeps the joint values (clamped to its ranges; joints it
        adds start at home); a design shown for the first time starts at home."""
        arm = self.arm
        if arm is None or self._shown == self.source.generation:
            return
        home = arm.poses[0][1]
        kept = self.q[: arm.dof] if self._shown != -1 else ()
        self.q = arm.clamp(tuple(kept) + tuple(home[len(kept):]))
        self._shown = self.source.generation
        self.playing, self.t = False, 0.0

    def poll(self) -> bool:
        changed = self.source.poll()
        if changed:
            self._follow()
        return changed

    def go(self, delta: int) -> None:
        """Page to the next (+1) or previous (-1) design, wrapping around."""
        self.index = (self.index + delta) % len(self.sources)
        self._enter()

    def set_joint(self, i: int, value: float) -> None:
        assert self.arm is not None
        q = list(self.q)
        q[i] = value
        self.q = self.arm.clamp(q)
        self.playing = False

    def go_pose(self, name: str) -> None:
        assert self.arm is not None
        self.q = self.arm.clamp(dict(self.arm.poses)[name])
        self.playing = False

    def play(self) -> None:
        if self.source.trajectory is not None:
            if self.t >= self.source.trajectory.t[-1]:
                self.t = 0.0
            self.playing = True

    def pause(self) -> None:
        self.playing = False

    def seek(self, t: float, stop: bool = False) -> None:
        """Show the trajectory at time t (s); stop: the user moved the time slider, playback pauses."""
        self.playing = self.playing and not stop
        traj = self.source.trajectory
        assert traj is not None and self.arm is not None
        self.t = min(max(t, 0.0), traj.t[-1])
        self.q = self.arm.clamp(traj.at(self.t))

    def tick(self, dt: float) -> bool:
        """Advance playback by dt seconds; True if the pose moved."""
        traj = self.source.trajectory
        if not self.playing or traj is None:
            return False
        self.seek(self.t + dt)
        if self.t >= traj.t[-1]:
            self.playing = False
        return True


def __getattr__(name: str) -> Any:
    """Ranking lives in ranking.py, which builds on this module; `from modc.view.page import Ranking` still works."""
    if name == "Ranking":
        from .ranking import Ranking

        return Ranking
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
