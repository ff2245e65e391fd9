"""Physical constants every model of the arm shares (SI).

One value each, so that the numpy statics, pinocchio, PyBullet (`modc sim`) and the MJCF scene
agree on the torques they compute and the time they step. No imports: any layer may read it.
"""
from __future__ import annotations

GRAVITY = 9.81  # m/s², standard gravity as pinocchio's default model uses it
GRAVITY_VECTOR = (0.0, 0.0, -GRAVITY)  # m/s², world (and upright base_link) z up
TIME_STEP = 1e-3  # s: `modc sim` steps at 1 kHz and the MJCF scene declares the same step
# Acceleration limits: neither the paper nor Kinova's table gives one. Each actuator may reach its
# rated speed in ACCEL_RAMP_TIME (max_acceleration = max_velocity / 0.5 s): the ROS package's
# joint_limits.yaml and `modc plan`'s time parameterisation.
ACCEL_RAMP_TIME = 0.5  # s

__all__ = ["ACCEL_RAMP_TIME", "GRAVITY", "GRAVITY_VECTOR", "TIME_STEP"]
