"""One home per concept (issue 25, item 2): each shared value and helper has one definition,
and the modules that use it take it from there rather than typing it again."""
from __future__ import annotations

import math

import numpy as np
import pytest

from modc import formatting
from modc.physical import constants


def test_numbers_and_angles_are_written_one_way():
    assert formatting.num(-0.0) == "0" and formatting.num(1 / 3) == "0.333333333333"
    assert formatting.vec([0.5, -1e-13, 2]) == "0.5 -1e-13 2"
    assert formatting.angle(math.pi / 4) == "45deg" and formatting.angle(0.1) == "5.72958deg"
    assert formatting.degrees(22.5) == "22.5deg"
    assert formatting.angle_text(-math.pi / 2) == "-90.0°"


def test_every_user_takes_the_formatting_from_its_home():
    from modc.backends import format as backend_format
    from modc.dh import convert
    from modc.passes import check_poses, check_twists
    from modc.sim import verdict

    assert backend_format.num is formatting.num and backend_format.vec is formatting.vec
    assert convert.angle is formatting.angle and check_poses.angle is formatting.angle
    assert check_twists.degrees is formatting.degrees and verdict.angle_text is formatting.angle_text
    for module in (convert, check_poses, check_twists, verdict):
        assert not hasattr(module, "_deg")


def test_source_numbers_and_trajectory_numbers_have_their_home_too():
    from modc import trajectory
    from modc.model import write

    assert write._num is formatting.fixed and trajectory._num is formatting.json_number
    assert formatting.fixed(-1e-12) == "0" and formatting.fixed(45.0000000001) == "45"
    assert formatting.fixed(0.1234567, 6) == "0.123457" and formatting.fixed(12.5) == "12.5"
    assert formatting.json_number(-1e-13) == "0.0" and formatting.json_number(0.1 + 0.2) == "0.3"
    assert formatting.json_number(2) == "2.0"


def test_gravity_and_time_step_have_one_value():
    from modc.backends import mjcf
    from modc.physical import multibody
    from modc.sim import play, scene, smoke

    assert constants.GRAVITY_VECTOR == (0.0, 0.0, -constants.GRAVITY)
    assert np.array_equal(multibody.G_WORLD, constants.GRAVITY_VECTOR)
    assert scene.GRAVITY is smoke.GRAVITY is constants.GRAVITY
    assert smoke.TIME_STEP is play.TIME_STEP is mjcf.TIME_STEP is constants.TIME_STEP


def test_the_acceleration_ramp_has_one_value():
    from modc.backends import ros
    from modc.plan import timing

    assert ros.ACCEL_RAMP_TIME is constants.ACCEL_RAMP_TIME
    assert timing.ACCEL_RAMP_TIME == constants.ACCEL_RAMP_TIME  # plan/timing.py's copy: to import it


TILTED = ("robot r {\n    chain H1 - H3 - L1\n    payload 0.2 kg at (0, 0, 0.03) m\n"
          "    base at (0, 0, 0) m rpy (90, 30, 0) deg\n}\n")


def _robots():
    from conftest import ROOT

    from modc.compiler import check_file, check_text

    (tilted,) = check_text(TILTED, "t.mod").design.robots
    return [*(check_file(ROOT / "examples" / f"{s}.mod").design.robots[0] for s in ("example_b", "farm")), tilted]


def test_the_numpy_statics_equal_pinocchios_gravity_torques_also_on_a_tilted_base():
    pytest.importorskip("pinocchio")
    from modc.dynamics.model import Dynamics
    from modc.physical.statics import Statics

    for robot in _robots():
        statics, dyn = Statics(robot), Dynamics(robot)
        for q in np.random.default_rng(7).uniform(dyn.lower, dyn.upper, size=(20, robot.dof)):
            # the same bodies (every inertial of the Description, tool0's placeholder too): equal to rounding
            assert np.allclose(statics.torques(q), dyn.gravity(q), rtol=0, atol=1e-12)


def test_the_sampled_worst_case_is_a_lower_bound_of_the_refined_search():
    pytest.importorskip("pinocchio")
    from modc.dynamics.model import Dynamics
    from modc.dynamics.worst import worst_case
    from modc.physical.statics import Statics

    for robot in _robots():
        sampled = Statics(robot).worst(samples=64)
        refined = np.array([j.tau for j in worst_case(Dynamics(robot))])
        assert np.all(sampled <= refined + 2e-5)
        assert np.all(sampled >= 0.5 * refined)  # a ranking the DH conversion may rely on


def _exp(v: np.ndarray) -> np.ndarray:
    """Rodrigues: the rotation matrix of a rotation vector."""
    a = float(np.linalg.norm(v))
    K = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]]) / (a if a > 0 else 1.0)
    return np.eye(3) + np.sin(a) * K + (1 - np.cos(a)) * K @ K


def test_rotation_error_has_one_home_that_the_copies_equal():
    from modc.design.batch import rotation_error as batched_copy
    from modc.kinematics import rotation_error, rotation_vector
    from modc.plan import ik

    assert ik.rotation_error is rotation_error and not hasattr(ik, "rotation_vector")  # the IK calls the home

    rng = np.random.default_rng(11)
    vs = [*rng.normal(size=(50, 3)), np.zeros(3), np.array([np.pi, 0, 0]), np.array([0, 1, 1]) / np.sqrt(2) * np.pi,
          np.array([1e-10, 0, 0]), np.array([0, 0, np.pi - 1e-7])]
    vs = [v if np.linalg.norm(v) <= np.pi else v / np.linalg.norm(v) * 3.0 for v in vs]
    Rs = np.array([_exp(v) for v in vs])
    got = rotation_vector(Rs)
    for v, R, g in zip(vs, Rs, got, strict=True):
        assert np.allclose(g, rotation_vector(R), atol=1e-12)  # one matrix or a batch: the same answer
        if np.linalg.norm(v) < np.pi - 1e-3:  # at 180°, v and -v are the same turn
            assert np.allclose(g, v, atol=1e-7)
        else:
            assert np.allclose(_exp(g), R, atol=1e-6)
    Rt = Rs[::-1]
    assert np.allclose(rotation_error(Rt, Rs), batched_copy(Rt, Rs), atol=1e-12)


def test_sim_skips_the_pairs_plan_and_the_srdf_skip_from_the_matrix_in_memory(tmp_path):
    """`modc sim` without --srdf-from used to check every non-adjacent pair; it now takes the
    collision matrix in memory, the one rule (CollisionMatrix.unchecked) plan and the SRDF use."""
    pytest.importorskip("pinocchio")
    from conftest import ROOT

    from modc.compiler import build, check_file
    from modc.files import write_files
    from modc.physical.assembly import describe
    from modc.physical.collisions import UNCHECKED_REASONS, cached_matrix
    from modc.sim.contacts import srdf_disabled_pairs
    from modc.sim.smoke import allowed_pairs

    checked = check_file(ROOT / "examples" / "example_a.mod")
    (robot,) = checked.design.robots
    write_files(build(checked, ["srdf"]), tmp_path)
    matrix = cached_matrix(describe(robot))
    skipped = matrix.unchecked()
    assert skipped and skipped == {frozenset((p.link1, p.link2)) for p in matrix.disabled if p.reason != "Never"}
    assert set(UNCHECKED_REASONS) == {"Adjacent", "Default", "Always"}
    assert allowed_pairs(None, robot) == skipped
    assert allowed_pairs(tmp_path, robot) == srdf_disabled_pairs(tmp_path / "config" / f"{robot.file_stem}.srdf")
    assert allowed_pairs(tmp_path, robot) == skipped


def test_a_targets_tolerance_is_read_from_the_target():
    """What counts as reaching a target: Target.tolerance (plan's goals, the IK's acceptance)."""
    from modc.model.robot import Target

    plain = Target(name="a", xyz=(0.3, 0, 0.2), position_tolerance=0.002)
    assert plain.tolerance == (0.002, math.inf) and not plain.oriented
    assert Target(name="b", xyz=(0.3, 0, 0.2), rpy=(0, 0, 0)).tolerance == (0.005, math.radians(2.0))
    pointing = Target(name="c", xyz=(0.3, 0, 0.2), pointing=(0, 0, -1), orientation_tolerance=0.1)
    assert pointing.oriented and pointing.tolerance == (0.005, 0.1)


def test_a_targets_errors_have_one_home_that_the_planners_ik_agrees_with():
    """kinematics.target_errors (the design's exact check) measures what plan.ik's PositionIK
    does for the same pose: a full orientation, a pointing axis, or position only."""
    from modc import kinematics as K
    from modc.model.robot import Target
    from modc.plan.ik import PositionIK

    rng = np.random.default_rng(3)
    T = K.transform(rng.uniform(-0.3, 0.3, 3), rng.uniform(-3, 3, 3))

    class Pose:  # what PositionIK reads of pinocchio's placement
        translation, rotation = T[:3, 3], T[:3, :3]

    for kw in ({"rpy": (0.1, -0.4, 2.0)}, {"pointing": (0.0, 0.6, -0.8)}, {}):
        t = Target(name="t", xyz=(0.2, -0.1, 0.3), **kw)
        ik = PositionIK.__new__(PositionIK)
        ik.rotation = K.rpy_matrix(t.rpy) if t.rpy is not None else None
        ik.axis = None if t.pointing is None else np.asarray(t.pointing, float)
        ik.placement = lambda q: Pose  # type: ignore[method-assign]
        position, angle = K.target_errors(t, T)
        ref_p, ref_o = ik.errors(None, np.asarray(t.xyz))
        assert position == pytest.approx(ref_p, abs=1e-12)
        assert (angle is None) == (not kw) and (angle or 0.0) == pytest.approx(ref_o, abs=1e-9)
        assert angle is None or 0.0 < angle < math.pi


def test_the_design_searchs_ik_seeds_are_the_planners():
    """design/reach.py keeps an array form of plan.ik.seeds (the search's batched IK starts
    from zero); the same seeds, in the same order, for the same rng seed."""
    from modc.design import reach
    from modc.plan import ik

    lower, upper = np.array([-2.0, -1.0, 0.5]), np.array([2.0, 1.5, 2.5])
    for seed in (0, 7):
        ours = np.array(ik.seeds(np.zeros(3), lower, upper, 12, seed))
        assert np.array_equal(reach.seeds(3, 12, lower, upper, seed), ours)
    assert np.array_equal(ours[0], [0.0, 0.0, 0.5])  # the zero pose, clipped to the limits


def test_rotations_have_one_home_below_the_model():
    """The URDF rpy convention lives in modc.rotation: the kinematics builds frames from it and the
    model turns a region's box with it (the model may not import the kinematics)."""
    from modc import kinematics, rotation

    assert kinematics.rpy_matrix is rotation.rpy_matrix and kinematics.matrix_rpy is rotation.matrix_rpy
    assert kinematics.Rx is rotation.Rx and kinematics.Ry is rotation.Ry and kinematics.Rz is rotation.Rz
    rpy = (0.1, -0.7, 2.5)
    assert rotation.matrix_rpy(rotation.rpy_matrix(rpy)) == pytest.approx(rpy)
