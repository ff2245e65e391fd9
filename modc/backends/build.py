"""What backends share during one compile: the checked design and per-robot descriptions."""
from __future__ import annotations

from pathlib import Path

from ..diagnostics import Diagnostic
from ..model import Design, ResolvedRobot
from ..physical.assembly import Description, describe
from ..records import Record, field


class Build(Record, kw_only=False, frozen=False):
    design: Design
    diagnostics: list[Diagnostic] = field(default_factory=list)  # warnings that survived the passes
    files: dict[str, str | bytes] = field(default_factory=dict)  # what earlier backends produced
    collision_samples: int | None = None  # SRDF collision matrix: samples (None: 10,000 as MoveIt)
    seed: int | None = None  # and its seed (None: 0)
    # ROS package (modc.backends.ros_target): None = the default (jazzy, the distro's IK
    # solver, position commands, <robot>_moveit_config). The CLI fills these from its options.
    ros_distro: str | None = None
    ik_solver: str | None = None
    command_interface: str | None = None
    ros_package: str | None = None
    # package.xml's license (an SPDX expression) and maintainer ("Name <email>"); None: placeholders
    package_license: str | None = None
    maintainer: str | None = None
    _descriptions: dict[str, Description] = field(default_factory=dict)
    robots: tuple[ResolvedRobot, ...] = field(init=False)  # the design's robots, every library resolved

    def __post_init__(self) -> None:
        self.robots = self.design.resolved_robots()

    @property
    def source_name(self) -> str:
        return Path(self.design.path).name

    def description(self, robot: ResolvedRobot) -> Description:
        if robot.name not in self._descriptions:
            self._descriptions[robot.name] = describe(robot)
        return self._descriptions[robot.name]
