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


def test_gravity_and_time_step_have_one_value():
    from modc.backends import mjcf
    from modc.physical import multibody
    from modc.sim import play, scene, smoke

    assert constants.GRAVITY_VECTOR == (0.0, 0.0, -constants.GRAVITY)
    assert np.array_equal(multibody.G_WORLD, constants.GRAVITY_VECTOR)
    assert scene.GRAVITY is smoke.GRAVITY is constants.GRAVITY
    assert smoke.TIME_STEP is play.TIME_STEP is mjcf.TIME_STEP is constants.TIME_STEP


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
            # the statics leave out tool0's placeholder inertial (1 mg): up to 1e-5 N·m on these arms
            assert np.allclose(statics.torques(q), dyn.gravity(q), rtol=0, atol=2e-5)


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
