"""Tasks (docs/language.md): regions, visit tasks, straight paths, base placement; `modc plan --task`.

The language tests are fast. The planning tests (marked slow) plan examples/farm_task.mod once
and check the result independently: collisions with the compiler's collision model, joint limits,
the straight path's tolerance, and the timing re-derived from the trajectory's samples with a
pinocchio model read from the compiled URDF (speeds within the library's RPM, torques within the
peak torque, and some joint at its limit: the time is not trivially loose).
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from modc.compiler import check_file, check_text

ROOT = Path(__file__).resolve().parent.parent
EXAMPLE = ROOT / "examples" / "farm_task.mod"

STATEMENTS = """robot farm {
    chain H1 - L4(pivot=-90deg, port=45deg) - L3(link=180mm)
    target plant at (0.30, 0, 0.25) m
    region tray box size (0.20, 0.10, 0) m at (0.35, 0, 0.15) m grid 3 x 2 x 1 rpy (0, 90, 0) deg within 4 mm, 3 deg
    task serve { visit plant, tray, tray[1,0,0] }
    path seam from plant to tray[2,1,0] straight
}

design cell {
    target plant at (0.30, 0, 0.25) m
    region tray box size (0.20, 0.10, 0) m at (0.35, 0, 0.15) m grid 3 x 2 x 1
    task serve { visit plant, tray }
    base within box size (0.20, 0.20, 0) m at (0, 0, 0) m step 50 mm yaw 0 to 90 deg step 45 deg
    rank cycle_time, energy, coverage
}
"""

YAML = """robots:
  - name: farm
    chain: [H1, "L4(pivot=-90deg, port=45deg)", "L3(link=180mm)"]
    targets:
      plant: (0.30, 0, 0.25) m
    regions:
      tray: {size: "(0.20, 0.10, 0) m", at: "(0.35, 0, 0.15) m", grid: 3 x 2 x 1, rpy: "(0, 90, 0) deg",
             within: "4 mm, 3 deg"}
    tasks:
      serve: [plant, tray, "tray[1,0,0]"]
    paths:
      seam: {from: plant, to: "tray[2,1,0]"}
designs:
  - name: cell
    targets:
      plant: (0.30, 0, 0.25) m
    regions:
      tray: {size: "(0.20, 0.10, 0) m", at: "(0.35, 0, 0.15) m", grid: [3, 2, 1]}
    tasks:
      serve: [plant, tray]
    base_within: {size: "(0.20, 0.20, 0) m", at: "(0, 0, 0) m", step: 50 mm, yaw: 0 to 90 deg step 45 deg}
    rank: [cycle_time, energy, coverage]
"""


def _checked(text: str, name: str = "t.mod"):
    checked = check_text(text, name)
    errors = [d for d in checked.diagnostics if d.is_error]
    return checked.design, errors


# --- regions ------------------------------------------------------------------------------------


def test_region_points_cover_the_box_faces_included():
    design, errors = _checked(STATEMENTS)
    assert not errors
    (region,) = design.robots[0].regions
    points = region.points()
    assert len(points) == 6
    xyz = np.array([p.xyz for p in points])
    # faces included: the extreme points lie on the box's faces; the size-0 axis is the centre
    assert xyz[:, 0].min() == pytest.approx(0.25) and xyz[:, 0].max() == pytest.approx(0.45)
    assert sorted(set(np.round(xyz[:, 0], 9))) == pytest.approx([0.25, 0.35, 0.45])
    assert sorted(set(np.round(xyz[:, 1], 9))) == pytest.approx([-0.05, 0.05])
    assert set(np.round(xyz[:, 2], 9)) == {0.15}
    assert [p.name for p in points] == ["tray[0,0,0]", "tray[0,1,0]", "tray[1,0,0]", "tray[1,1,0]", "tray[2,0,0]",
                                        "tray[2,1,0]"]
    p = design.robots[0].task_target("tray[2,1,0]")
    assert p.xyz == pytest.approx((0.45, 0.05, 0.15))
    assert p.rpy == pytest.approx((0, math.pi / 2, 0))
    assert p.position_tolerance == pytest.approx(0.004) and p.orientation_tolerance == pytest.approx(math.radians(3))
    assert design.robots[0].task_target("tray[3,0,0]") is None


def test_region_single_point_is_the_centre():
    text = STATEMENTS.replace("grid 3 x 2 x 1", "grid 1 x 1 x 1").replace("tray[1,0,0]", "tray[0,0,0]")
    design, errors = _checked(text.replace("tray[2,1,0]", "tray[0,0,0]"))
    assert not errors
    (point,) = design.robots[0].regions[0].points()
    assert point.xyz == pytest.approx((0.35, 0, 0.15)) and point.name == "tray[0,0,0]"


def test_tasks_and_paths_expand_regions_in_order():
    design, _ = _checked(STATEMENTS)
    robot, cell = design.robots[0], design.problems[0]
    assert robot.tasks[0].visits == ("plant", "tray[0,0,0]", "tray[0,1,0]", "tray[1,0,0]", "tray[1,1,0]",
                                     "tray[2,0,0]", "tray[2,1,0]", "tray[1,0,0]")
    assert (robot.paths[0].start, robot.paths[0].end) == ("plant", "tray[2,1,0]")
    assert cell.rank[:3] == ("cycle_time", "energy", "coverage")
    grid = cell.base_grid
    assert grid is not None and len(grid.positions()) == 25 and len(grid.poses()) == 25 * 3
    assert sorted({p.rpy[2] for p in grid.poses()}) == pytest.approx([0, math.pi / 4, math.pi / 2])
    xs = sorted({p[0] for p in grid.positions()})
    assert xs == pytest.approx([-0.1, -0.05, 0, 0.05, 0.1])


# --- the two input forms, and fmt ----------------------------------------------------------------


def _task_model(design):
    r, p = design.robots[0], design.problems[0]
    dump = lambda items: [x.model_dump() for x in items]  # noqa: E731  (spans differ between the forms)
    return (dump(r.regions), dump(r.tasks), dump(r.paths), dump(p.cell.regions), dump(p.cell.tasks),
            p.base_grid.model_dump() if p.base_grid else None, p.rank)


def test_yaml_form_means_the_same(tmp_path):
    mod, yml = tmp_path / "t.mod", tmp_path / "t.yaml"
    mod.write_text(STATEMENTS, encoding="utf-8")
    yml.write_text(YAML, encoding="utf-8")
    a, b = check_file(mod), check_file(yml)
    assert not [d for d in a.diagnostics + b.diagnostics if d.is_error]
    assert _task_model(a.design) == _task_model(b.design)


def test_fmt_canonical_and_idempotent():
    from modc.syntax.format import format_text

    messy = STATEMENTS.replace("grid 3 x 2 x 1", "grid 3 x 2  x 1").replace("tray[1,0,0] }", "tray [ 1, 0,0 ]}")
    messy = messy.replace("    path seam", "  path   seam").replace("step 50 mm yaw", "step 50 mm\n        yaw")
    out, diags = format_text(messy)
    assert not diags and out is not None
    once, _ = format_text(STATEMENTS)
    assert out == once == STATEMENTS
    assert format_text(out)[0] == out
    # formatting changes no meaning
    assert _task_model(_checked(out)[0]) == _task_model(_checked(STATEMENTS)[0])


def test_schema_lists_the_task_keys():
    import yaml

    from modc.syntax.document import json_schema

    jsonschema = pytest.importorskip("jsonschema")
    schema = json_schema()
    jsonschema.validate(yaml.safe_load(YAML), schema)
    bad = yaml.safe_load(YAML)
    bad["robots"][0]["paths"]["seam"]["via"] = "plant"
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.validate(bad, schema)


# --- diagnostics ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("old", "new", "code"),
    [
        ("grid 3 x 2 x 1 rpy", "grid 2.5 x 2 x 1 rpy", "region-grid"),
        ("grid 3 x 2 x 1 rpy", "grid 3 x 2 x 4 rpy", "region-grid"),
        ("grid 3 x 2 x 1 rpy", "grid 101 x 100 x 1 rpy", "region-grid"),
        ("visit plant, tray, tray[1,0,0]", "visit plant, tray, tray[1,2,0]", "unknown-task-target"),
        ("visit plant, tray, tray[1,0,0]", "visit plant, bowl", "unknown-task-target"),
        ("path seam from plant to tray[2,1,0]", "path seam from plant to tray", "unknown-task-target"),
        ("path seam from", "path plant from", "duplicate-name"),
        ("step 50 mm yaw", "step 0.1 mm yaw", "design-bound"),
        ("step 45 deg", "step 0 deg", "design-bound"),
        ("yaw 0 to 90 deg", "yaw 90 to 0 deg", "design-bound"),
        ("    target plant at (0.30, 0, 0.25) m\n    region", "    target plant at (0.30, 0, 0.25) m\n"
         "    base within box size (0.2, 0.2, 0) m at (0, 0, 0) m step 50 mm\n    region", "base-within-robot"),
        ("rank cycle_time", "rank cycle_tme", "unknown-objective"),
    ],
)
def test_diagnostics(old, new, code):
    assert old in STATEMENTS
    _, errors = _checked(STATEMENTS.replace(old, new, 1))
    assert [d.code for d in errors] == [code], [d.message for d in errors]
    assert errors[0].span.line > 1 and errors[0].hint


# --- modc plan --task ------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def farm():
    checked = check_file(EXAMPLE)
    assert checked.ok, [d.message for d in checked.diagnostics]
    return checked.design.robots[0]


@pytest.fixture(scope="module")
def serve(farm):
    from modc.plan.task import plan_task_robot

    return plan_task_robot(farm, "serve")


@pytest.fixture(scope="module")
def seam(farm):
    from modc.plan.task import plan_task_robot

    return plan_task_robot(farm, "seam")


@pytest.fixture(scope="module")
def urdf_model(tmp_path_factory):
    """An independent dynamic model: pinocchio reading the URDF `modc FILE -o OUT` writes."""
    import pinocchio as pin

    from modc.cli import main

    out = tmp_path_factory.mktemp("farm_task")
    with pytest.raises(SystemExit) as e:
        main([str(EXAMPLE), "-o", str(out)])
    assert e.value.code == 0
    urdf = out / "urdf" / "mod3_farm.urdf"
    model = pin.buildModelFromUrdf(str(urdf))
    return model, model.createData()


def _samples(result):
    return np.array(result.t), np.array(result.q)


@pytest.mark.slow
def test_visit_task_goes_around_the_shelf(farm, serve):
    from modc.plan.collision import CollisionChecker

    checker = CollisionChecker(farm)
    seg = next(s for s in serve.segments if s.start == "plant" and s.end == "tray[0,0,0]")
    a, b = np.array(seg.waypoints[0]), np.array(seg.waypoints[-1])
    assert len(seg.waypoints) > 2 and not checker.motion_valid(a, b), "the direct swing must hit the shelf"
    assert [s.end for s in serve.segments] == ["plant", *[f"tray[{i},{j},0]" for i in range(3) for j in range(2)],
                                               "plant"]
    t, q = _samples(serve)
    assert np.all(np.diff(t) > 0)
    for row in q:
        assert not checker.contacts(row, 0.0)
        assert np.all(row >= checker.lower - 1e-9) and np.all(row <= checker.upper + 1e-9)
    # every visited target is reached, within its tolerance, where its segment ends
    for s in serve.segments:
        target = farm.task_target(s.end)
        k = int(np.argmin(np.abs(t - (s.t0 + s.duration))))
        assert np.linalg.norm(checker.tool_position(q[k]) - np.array(target.xyz)) <= target.position_tolerance


@pytest.mark.slow
def test_straight_path_stays_on_the_segment(farm, seam):
    from modc.plan.collision import CollisionChecker
    from modc.plan.task import distance_to_segment

    checker = CollisionChecker(farm)
    seg = seam.segments[-1]
    assert seg.kind == "straight"
    a, b = (np.array(farm.task_target(n).xyz) for n in ("plant", "row_end"))
    t, q = _samples(seam)
    on = (t >= seg.t0 - 1e-9) & (t <= seg.t0 + seg.duration + 1e-9)
    assert on.sum() > 10
    for row in q[on]:
        assert distance_to_segment(checker.tool_position(row), a, b) <= 0.005
        assert not checker.contacts(row, 0.0)
    # continuous joints: no step between samples larger than the speed limit allows
    vmax = np.array([farm.library.variants[u.variant].actuator.velocity for u in farm.units])
    dq = np.abs(np.diff(q[on], axis=0)) / np.diff(t[on])[:, None]
    assert np.all(dq <= vmax * 1.01)
    assert np.linalg.norm(checker.tool_position(q[on][-1]) - b) <= 0.005


def _retime_check(farm, result, urdf_model):
    """Speeds and torques at the samples, from finite differences and an independent RNEA."""
    import pinocchio as pin

    model, data = urdf_model
    acts = [farm.library.variants[u.variant].actuator for u in farm.units]
    vmax = np.array([a.velocity for a in acts])
    tmax = np.array([a.torque_peak for a in acts])
    t, q = _samples(result)
    dt = np.diff(t)
    v_mid = np.diff(q, axis=0) / dt[:, None]
    assert np.all(np.abs(v_mid) <= vmax * 1.005), np.max(np.abs(v_mid) / vmax)
    torque_share = []
    for k in range(1, len(t) - 1):
        h0, h1 = t[k] - t[k - 1], t[k + 1] - t[k]
        v = (v_mid[k - 1] * h1 + v_mid[k] * h0) / (h0 + h1)
        a = 2 * (v_mid[k] - v_mid[k - 1]) / (h0 + h1)
        tau = pin.rnea(model, data, q[k], v, a)
        torque_share.append(np.max(np.abs(tau) / tmax))
    speed_share = np.max(np.abs(v_mid) / vmax)
    # within the limits (finite differences across an acceleration switch blur the torque a little)
    assert max(torque_share) <= 1.1
    # and not trivially loose: some joint runs at its speed or torque limit
    assert max(speed_share, max(torque_share)) >= 0.9
    return speed_share, max(torque_share)


@pytest.mark.slow
def test_cycle_time_retimed_independently(farm, serve, seam, urdf_model):
    for result in (serve, seam):
        _retime_check(farm, result, urdf_model)
        total = sum(s.duration for s in result.segments)
        assert result.t[-1] == pytest.approx(total, abs=1e-6)
        assert result.cycle_time == pytest.approx(total - result.segments[0].duration)
        assert result.energy > 0 and 0 < result.peak_share <= 1.0
        # like cycle time and energy, the task's peak torque leaves out the approach from home
        assert result.peak_share == max(s.peak_share for s in result.segments if s.kind != "approach")
    # each segment is no faster than its slowest joint moving at full speed the whole way
    acts = [farm.library.variants[u.variant].actuator for u in farm.units]
    vmax = np.array([a.velocity for a in acts])
    for s in serve.segments:
        path = np.array(s.waypoints)
        bound = sum(float(np.max(np.abs(b - a) / vmax)) for a, b in zip(path, path[1:], strict=False))
        assert s.duration >= bound - 1e-6


@pytest.mark.slow
def test_the_written_trajectory_keeps_every_speed_limit_between_samples(serve, seam, urdf_model):
    """A trajectory file moves linearly from sample to sample (docs/conventions.md): every chord
    is within the URDF's joint velocity, also where toppra's speed peaks between two samples."""
    model, _ = urdf_model
    for result in (serve, seam):
        t, q = _samples(result)
        chords = np.abs(np.diff(q, axis=0)) / np.diff(t)[:, None]
        assert np.all(chords <= np.asarray(model.velocityLimit) * (1 + 1e-9))


@pytest.mark.slow
def test_plan_task_cli_json(tmp_path, capsys):
    from modc.cli import main
    from modc.trajectory import parse

    with pytest.raises(SystemExit) as e:
        main(["plan", str(EXAMPLE), "--task", "serve", "--json"])
    out = capsys.readouterr().out
    assert e.value.code == 0
    doc = json.loads(out)
    traj, errors = parse(doc)
    assert not errors and traj is not None and traj.joint_names == ("joint_1", "joint_2", "joint_3")
    assert doc["cycle_time_s"] == pytest.approx(sum(s["duration_s"] for s in doc["segments"][1:]))
    assert [s["kind"] for s in doc["segments"]] == ["approach"] + ["motion"] * 7
    with pytest.raises(SystemExit) as e:
        main(["plan", str(EXAMPLE), "--task", "serve"])
    text = capsys.readouterr().out
    assert e.value.code == 0 and "cycle time" in text and "plant -> tray[0,0,0]" in text


def test_plan_needs_to_or_task(capsys):
    from modc.cli import main

    with pytest.raises(SystemExit) as e:
        main(["plan", str(EXAMPLE)])
    assert e.value.code == 2 and "--to TARGET or --task NAME" in capsys.readouterr().err


def test_lsp_outline_and_definition():
    from modc.lsp.document import Analysis
    from modc.lsp.symbols import definition, symbols

    text = EXAMPLE.read_text(encoding="utf-8")
    an = Analysis(text, str(EXAMPLE))
    outline = {s.name: s.detail for s in symbols(an)[0].children}
    assert outline["tray"] == "region" and outline["serve"] == "task" and outline["seam"] == "path"
    at = text.index("visit plant, tray") + len("visit plant, ") + 1
    (loc,) = definition(an, at, EXAMPLE.as_uri())
    assert loc.range.start.line == text[: text.index("region tray")].count("\n")


@pytest.mark.slow
def test_straight_path_through_the_shelf_is_refused(tmp_path, capsys):
    from modc.cli import main

    text = EXAMPLE.read_text(encoding="utf-8").replace(
        "    path seam",
        "    target over at (0.05, -0.40, 0.25) m\n    path cross from plant to over straight\n    path seam")
    cell = tmp_path / "cell.mod"
    cell.write_text(text, encoding="utf-8")
    with pytest.raises(SystemExit) as e:
        main(["plan", str(cell), "--task", "cross"])
    err = capsys.readouterr().err
    assert e.value.code == 1 and "error[task-segment-failed]" in err
    assert "path 'cross', segment 1 (plant -> over): the arm collides" in err and "box 'shelf'" in err
    assert "Traceback" not in err


ORIENTED = ("    target a at (0.30, 0, 0.25) m rpy (109.0, 34.6, 62.9) deg within 5 mm, 2 deg\n"
            "    target b at (0.30, 0.10, 0.25) m rpy (111.4, 31.0, 79.3) deg within 5 mm, 2 deg\n"
            "    path turn from a to b straight\n")


def _turn(tmp_path, targets: str):
    """Plan path 'turn' of the example with these targets added: (file, its text, targets a and
    b, tool0's placement at every sample of the timed straight segment)."""
    import pinocchio as pin

    from modc.plan.collision import CollisionChecker
    from modc.plan.task import plan_task

    text = EXAMPLE.read_text(encoding="utf-8").replace("    path seam", targets + "    path seam")
    cell = tmp_path / "cell.mod"
    cell.write_text(text, encoding="utf-8")
    result = plan_task(cell, "turn")
    robot = check_file(cell).design.robots[0]
    checker = CollisionChecker(robot)
    t, q = _samples(result)
    placements = []
    for row in q[t >= result.segments[-1].t0 - 1e-9]:
        pin.forwardKinematics(checker.model, checker.data, row)
        placements.append(pin.updateFramePlacement(checker.model, checker.data, checker.tool_frame).copy())
    return cell, text, robot.task_target("a"), robot.task_target("b"), placements


@pytest.mark.slow
def test_oriented_straight_path_follows_the_slerp(tmp_path, capsys):
    """tool0's orientation is interpolated along the segment (slerp), within the targets'
    tolerance at every sample; a constant orientation the arm cannot hold is refused."""
    import pinocchio as pin

    from modc.kinematics import rpy_matrix

    cell, text, a, b, placements = _turn(tmp_path, ORIENTED)
    Ra, Rb = np.array(rpy_matrix(a.rpy)), np.array(rpy_matrix(b.rpy))
    pa, pb = np.array(a.xyz), np.array(b.xyz)
    for M in placements:
        x = float(np.clip(np.dot(M.translation - pa, pb - pa) / np.dot(pb - pa, pb - pa), 0, 1))
        R = Ra @ pin.exp3(x * pin.log3(Ra.T @ Rb))
        assert np.linalg.norm(pin.log3(R.T @ M.rotation)) <= math.radians(2) + 1e-9
        assert np.linalg.norm(M.translation - (pa + x * (pb - pa))) <= 0.005
    # the same segment with tool0 held at a's orientation all the way: the 3-joint arm cannot
    from modc.cli import main

    cell.write_text(text.replace("rpy (111.4, 31.0, 79.3) deg", "rpy (109.0, 34.6, 62.9) deg"), encoding="utf-8")
    with pytest.raises(SystemExit) as e:
        main(["plan", str(cell), "--task", "turn"])
    err = capsys.readouterr().err
    assert e.value.code == 1 and "path 'turn', segment 1 (a -> b): tool0 cannot stay on the segment" in err


POINTING = ("    target a at (0.30, 0, 0.25) m pointing (0.375, 0.7328, -0.5678) within 5 mm, 3 deg\n"
            "    target b at (0.30, 0.10, 0.25) m pointing (0.1591, 0.8423, -0.515) within 5 mm, 3 deg\n"
            "    path turn from a to b straight\n")


@pytest.mark.slow
def test_pointing_straight_path_turns_the_approach_axis(tmp_path, capsys):
    """With `pointing` ends, tool0's x axis follows the great circle between the two directions
    (within the targets' tolerance at every sample of the timed motion); a direction the arm
    cannot hold along the segment is refused, not ignored."""
    cell, text, a, b, placements = _turn(tmp_path, POINTING)
    da, db = np.array(a.pointing) / np.linalg.norm(a.pointing), np.array(b.pointing) / np.linalg.norm(b.pointing)
    theta = math.acos(float(np.clip(da @ db, -1, 1)))
    pa, pb = np.array(a.xyz), np.array(b.xyz)
    for M in placements:
        x = float(np.clip(np.dot(M.translation - pa, pb - pa) / np.dot(pb - pa, pb - pa), 0, 1))
        d = (math.sin((1 - x) * theta) * da + math.sin(x * theta) * db) / math.sin(theta)  # the great circle
        axis = np.array(M.rotation)[:, 0]
        assert math.acos(float(np.clip(axis @ d, -1, 1))) <= math.radians(3) + 1e-9
        assert np.linalg.norm(M.translation - (pa + x * (pb - pa))) <= 0.005
    # the same segment asking for a's direction all the way: the 3-joint arm cannot hold it
    from modc.cli import main

    cell.write_text(text.replace("pointing (0.1591, 0.8423, -0.515)", "pointing (0.375, 0.7328, -0.5678)"),
                    encoding="utf-8")
    with pytest.raises(SystemExit) as e:
        main(["plan", str(cell), "--task", "turn"])
    err = capsys.readouterr().err
    assert e.value.code == 1 and "path 'turn', segment 1 (a -> b): tool0 cannot stay on the segment" in err


def test_written_robot_file_keeps_the_task():
    """modc.model.write (what `modc design` emits): regions, tasks and paths survive a round trip."""
    from modc.model.write import robot_file_text

    robot = check_file(EXAMPLE).design.robots[0]
    design, errors = _checked(robot_file_text(robot))
    assert not errors, [d.message for d in errors]
    again = design.robots[0]
    for a, b in ((robot.regions, again.regions), (robot.tasks, again.tasks), (robot.paths, again.paths)):
        assert [x.model_dump() for x in a] == [x.model_dump() for x in b]


CEILING = """robot ceiling {
    chain H1 - L4(pivot=-45deg, port=-45deg) - L3
    tool at (0.05, 0, 0) m
    box ceiling size (1.2, 1.2, 0.02) m at (0, 0, 0.62) m
    target rest at (0.22, 0.18, 0.25) m
    target low at (0.30, 0.0, 0.10) m
    task pick { visit rest, low, rest }
}
"""


@pytest.mark.slow
def test_a_home_pose_that_touches_the_cell_does_not_veto_the_task():
    """A ceiling over the arm catches its upright home pose: the task, clear of it, starts at its
    first waypoint (no approach, which is not counted anyway) instead of failing."""
    from modc.plan.collision import CollisionChecker
    from modc.plan.task import plan_task_robot

    c = check_text(CEILING, "ceiling.mod")
    assert c.ok, [d.message for d in c.diagnostics]
    robot = c.design.resolved_robots()[0]
    checker = CollisionChecker(robot)
    assert not checker.valid(np.asarray(robot.home(), float))  # the premise: home hits the ceiling
    plan = plan_task_robot(robot, "pick", seed=0)
    assert [(s.kind, s.start, s.end) for s in plan.segments] == [("motion", "rest", "low"), ("motion", "low", "rest")]
    t, q = _samples(plan)
    assert np.linalg.norm(checker.tool_position(q[0]) - np.array(robot.task_target("rest").xyz)) <= 1e-3
    assert all(not checker.contacts(row, 0.0) for row in q)
    assert plan.cycle_time == pytest.approx(t[-1], abs=1e-6)  # nothing before the task's own segments
    assert "no approach" in plan.summary() and " 1 motion" in plan.summary()


def test_energy_counts_the_short_torque_limited_ramps():
    """Joint 1 (vertical) alone, from rest through its speed limit back to rest: ∫|τ·q̇| dt is
    exactly M11 v² (speeding up, then braking), however short the ramps are - they last about
    2 ms, less than the 10 ms between samples, and were missed (0 J reported)."""
    from modc import api
    from modc.plan.retime import Limits, time_polyline

    robot = api.load(ROOT / "examples" / "farm.mod")
    limits = Limits.of(robot)
    z = np.zeros(robot.dof)
    q1, e1 = z.copy(), z.copy()
    q1[0], e1[0] = 1.0, 1.0
    timed = time_polyline([z, q1], limits)
    inertia = float((limits.rnea(z, z, e1) - limits.rnea(z, z, z))[0])
    v = float(np.abs(timed.qd[:, 0]).max())
    assert v > 0.5 * limits.velocity[0]  # it does cruise near its speed limit
    assert timed.energy == pytest.approx(inertia * v**2, rel=0.02)
