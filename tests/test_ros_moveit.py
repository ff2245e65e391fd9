"""MoveIt 2's own tools accept the ROS 2 package: `MoveItConfigsBuilder(robot, package_name=pkg)
.to_moveit_configs()` with its defaults, and the Setup Assistant's launch files.

moveit_configs_utils is on neither PyPI nor Debian, so its default file lookups are re-implemented
here, rule by rule, from moveit/moveit2 moveit_configs_utils/moveit_configs_utils/
moveit_configs_builder.py (MoveItConfigsBuilder, Jazzy/main) and launches.py; each rule names
the method it comes from. The files are loaded the way the builder loads them: YAML with a YAML
parser, URDF and SRDF through xacro (the PyPI xacro the builder's load_xacro calls).
"""
from __future__ import annotations

import re
import sys
import types
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
import yaml
from conftest import ARM_EXAMPLES

from modc.compiler import build, check_file

xacro = pytest.importorskip("xacro", reason="the builder loads URDF and SRDF with xacro")


class FileNotFound(Exception):
    """parameter_builder's ParameterBuilderFileNotFoundError."""


def load_yaml(path: Path):
    if not path.is_file():
        raise FileNotFound(f"File {path} doesn't exist")
    return yaml.safe_load(path.read_text())


def load_xacro(path: Path) -> str:
    if not path.is_file():
        raise FileNotFound(f"File {path} doesn't exist")
    return xacro.process_file(str(path)).toxml()


class Lookups:
    """MoveItConfigsBuilder's defaults, for one package directory."""

    def __init__(self, robot_name: str, package_name: str, shares: dict[str, Path]):
        self.robot_name, self.package = robot_name, shares[package_name]  # __init__: get_package_share_directory
        self.shares = shares
        self.urdf = self.srdf = None
        # __init__: config/<robot_name>.urdf.xacro (the Setup Assistant's modified URDF) first
        modified = self.package / "config" / f"{robot_name}.urdf.xacro"
        if modified.exists():
            self.urdf = modified
        # __init__: else .setup_assistant's urdf (or URDF) package + relative_path; its srdf (or SRDF)
        sa = self.package / ".setup_assistant"
        if sa.exists():
            config = load_yaml(sa).get("moveit_setup_assistant_config", {})
            urdf = config.get("urdf", config.get("URDF"))
            if urdf and self.urdf is None:
                self.urdf = shares[urdf["package"]] / urdf["relative_path"]
            srdf = config.get("srdf", config.get("SRDF"))
            if srdf:
                self.srdf = self.package / srdf["relative_path"]
        # __init__: else config/<robot_name>.urdf and config/<robot_name>.srdf
        self.urdf = self.urdf or self.package / "config" / f"{robot_name}.urdf"
        self.srdf = self.srdf or self.package / "config" / f"{robot_name}.srdf"

    def controllers_file(self) -> Path:
        """trajectory_execution(): config/*_controllers.yaml, the only one or the first of
        moveit, moveit2, <robot_name>; else "Unable to guess which parameter file to load"."""
        config = self.package / "config"
        names = sorted(m.group(1) for p in config.iterdir() if (m := re.match(r"^(.*)_controllers.yaml$", p.name)))
        if len(names) == 1:
            return config / f"{names[0]}_controllers.yaml"
        for name in ("moveit", "moveit2", self.robot_name):
            if name in names:
                return config / f"{name}_controllers.yaml"
        raise RuntimeError(f"trajectory_execution: Unable to guess which parameter file to load: {names}")

    def to_moveit_configs(self) -> dict:
        """to_moveit_configs(): every default loader, in its order."""
        config = self.package / "config"
        sensors = config / "sensors_3d.yaml"  # sensors_3d(): optional
        return {
            "robot_description": load_xacro(self.urdf),
            "robot_description_semantic": load_xacro(self.srdf),
            "robot_description_kinematics": load_yaml(config / "kinematics.yaml"),
            # planning_pipelines(): config/*_planning.yaml, else moveit_configs_utils' default_configs
            "planning_pipelines": sorted(p.name for p in config.glob("*_planning.yaml")),
            "trajectory_execution": load_yaml(self.controllers_file()),
            "sensors_3d": load_yaml(sensors) if sensors.exists() else None,
            "robot_description_planning": load_yaml(config / "joint_limits.yaml"),
            "pilz_cartesian_limits": load_yaml(config / "pilz_cartesian_limits.yaml"),
        }


@pytest.fixture(scope="module")
def packages(tmp_path_factory):
    out = {}
    for ex in ARM_EXAMPLES:
        c = check_file(ex)
        files = build(c)
        d = tmp_path_factory.mktemp(ex.stem)
        for rel, content in files.items():
            p = d / rel
            p.parent.mkdir(parents=True, exist_ok=True)
            p.write_bytes(content) if isinstance(content, bytes) else p.write_text(content, encoding="utf-8")
        pkg = re.search(r"<name>(\w+)</name>", files["package.xml"]).group(1)
        out[ex.stem] = (c.design.robots[0], pkg, d)
    return out


@pytest.mark.slow
def test_moveit_configs_builder_defaults_resolve(packages):
    for robot, pkg, d in packages.values():
        cfg = Lookups(robot.file_stem, pkg, {pkg: d}).to_moveit_configs()
        urdf, srdf = ET.fromstring(cfg["robot_description"]), ET.fromstring(cfg["robot_description_semantic"])
        assert urdf.get("name") == srdf.get("name") == robot.file_stem
        assert urdf.find("ros2_control") is not None, "robot_description must carry ros2_control for ros2_control_node"
        links = {e.get("name") for e in urdf.findall("link")}
        joints = {j.get("name") for j in urdf.findall("joint")}
        # the SRDF names only what the URDF has
        (vj,) = srdf.findall("virtual_joint")
        assert vj.get("child_link") in links
        for g in srdf.findall("group"):
            for chain in g.findall("chain"):
                assert {chain.get("base_link"), chain.get("tip_link")} <= links
        for dc in srdf.findall("disable_collisions"):
            assert {dc.get("link1"), dc.get("link2")} <= links
        groups = {g.get("name") for g in srdf.findall("group")}
        assert set(cfg["robot_description_kinematics"]) <= groups
        assert set(cfg["robot_description_planning"]["joint_limits"]) <= joints
        # MoveIt's controllers come from moveit_controllers.yaml, and they exist in ros2_control
        manager = cfg["trajectory_execution"]["moveit_simple_controller_manager"]
        ros2 = yaml.safe_load((d / "config/ros2_controllers.yaml").read_text())
        declared = set(ros2["controller_manager"]["ros__parameters"]) - {"update_rate"}
        for name in manager["controller_names"]:
            assert name in declared and set(manager[name]["joints"]) <= joints
        assert cfg["pilz_cartesian_limits"]["cartesian_limits"]["max_trans_vel"] > 0


def test_controllers_guess_is_unambiguous(packages, tmp_path):
    robot, pkg, d = packages["farm"]
    assert Lookups(robot.file_stem, pkg, {pkg: d}).controllers_file().name == "moveit_controllers.yaml"
    # the guess fails the way the issue saw it when controller files multiply
    config = tmp_path / "config"
    config.mkdir()
    for name in ("mod3_farm_ros", "mod3_farm_ros2", "mod3_farm_simple_moveit"):
        (config / f"{name}_controllers.yaml").write_text("{}\n")
    with pytest.raises(RuntimeError, match="Unable to guess"):
        Lookups("mod3_farm", "x", {"x": tmp_path}).controllers_file()


def test_setup_assistant_file_reopens_the_package(packages):
    for _, pkg, d in packages.values():
        config = load_yaml(d / ".setup_assistant")["moveit_setup_assistant_config"]
        assert config["urdf"]["package"] == pkg
        urdf = ET.fromstring(load_xacro(d / config["urdf"]["relative_path"]))
        srdf = ET.fromstring(load_xacro(d / config["srdf"]["relative_path"]))
        assert urdf.get("name") == srdf.get("name")
        assert config["package_settings"]["generated_timestamp"] == 0
        assert config["control_xacro"]["command"] == ["position"]


# --- the Setup Assistant's launch files, run against stand-ins for moveit_configs_utils --------------

def launch_api(monkeypatch, shares: dict[str, Path], calls: list):
    """moveit_configs_utils with the builder above; launches.generate_*_launch check what launches.py reads."""

    class MoveItConfigsBuilder:
        def __init__(self, robot_name, robot_description="robot_description", package_name=None):
            self.lookups = Lookups(robot_name, package_name or f"{robot_name}_moveit_config", shares)

        def to_moveit_configs(self):
            cfg = types.SimpleNamespace(**self.lookups.to_moveit_configs())
            cfg.package_path = self.lookups.package
            return cfg

    def generate(kind):
        def generate_launch(moveit_config):
            path = moveit_config.package_path
            if kind == "demo":  # generate_demo_launch includes these and reads ros2_controllers.yaml
                for name in ("static_virtual_joint_tfs", "rsp", "move_group", "moveit_rviz", "warehouse_db",
                             "spawn_controllers"):
                    assert (path / "launch" / f"{name}.launch.py").is_file(), name
                assert (path / "config/ros2_controllers.yaml").is_file()
            if kind == "moveit_rviz":
                assert (path / "config/moveit.rviz").is_file()
            if kind == "spawn_controllers":  # the controllers MoveIt uses, then joint_state_broadcaster
                names = moveit_config.trajectory_execution["moveit_simple_controller_manager"]["controller_names"]
                ros2 = yaml.safe_load((path / "config/ros2_controllers.yaml").read_text())
                assert set(names) | {"joint_state_broadcaster"} <= set(ros2["controller_manager"]["ros__parameters"])
            if kind == "static_virtual_joint_tfs":
                srdf = ET.fromstring(moveit_config.robot_description_semantic)
                assert srdf.findall("virtual_joint")
            calls.append(kind)
            return ("launch", kind)
        return generate_launch

    kinds = ("demo", "move_group", "moveit_rviz", "rsp", "spawn_controllers", "static_virtual_joint_tfs",
             "warehouse_db", "setup_assistant")
    pkg = types.ModuleType("moveit_configs_utils")
    pkg.MoveItConfigsBuilder = MoveItConfigsBuilder
    launches = types.ModuleType("moveit_configs_utils.launches")
    for kind in kinds:
        setattr(launches, f"generate_{kind}_launch", generate(kind))
    pkg.launches = launches
    monkeypatch.setitem(sys.modules, "moveit_configs_utils", pkg)
    monkeypatch.setitem(sys.modules, "moveit_configs_utils.launches", launches)
    return kinds


@pytest.mark.slow
def test_launch_files_build_the_moveit_config(packages, monkeypatch):
    for _, pkg, d in packages.values():
        calls: list = []
        kinds = launch_api(monkeypatch, {pkg: d}, calls)
        for kind in kinds:
            path = d / "launch" / f"{kind}.launch.py"
            ns: dict = {"__file__": str(path), "__name__": "launch_under_test"}
            exec(compile(path.read_text(), str(path), "exec"), ns)
            assert ns["generate_launch_description"]() == ("launch", kind)
        assert calls == list(kinds)
