"""One home per concept (issue 25, item 2): each shared value and helper has one definition,
and the modules that use it take it from there rather than typing it again."""
from __future__ import annotations

import math

import numpy as np

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
    from modc.physical import multibody, statics
    from modc.sim import play, scene, smoke

    assert constants.GRAVITY_VECTOR == (0.0, 0.0, -constants.GRAVITY)
    assert np.array_equal(statics.G, constants.GRAVITY_VECTOR)
    assert np.array_equal(multibody.G_WORLD, constants.GRAVITY_VECTOR)
    assert scene.GRAVITY is smoke.GRAVITY is constants.GRAVITY
    assert smoke.TIME_STEP is play.TIME_STEP is mjcf.TIME_STEP is constants.TIME_STEP
