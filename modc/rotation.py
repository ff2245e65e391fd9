"""Rotations in the URDF convention (fixed axes x, y, z: R = Rz(yaw) Ry(pitch) Rx(roll)), in numpy.

Their one home: modc.kinematics builds the paper's frames from them, and the model (a turned
region's box) places points with them, below the kinematics in the layers.
"""
from __future__ import annotations

import numpy as np


def Rx(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def Ry(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def Rz(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rpy_matrix(rpy) -> np.ndarray:
    """URDF convention: fixed axes X, Y, Z -> R = Rz(yaw) Ry(pitch) Rx(roll)."""
    return Rz(rpy[2]) @ Ry(rpy[1]) @ Rx(rpy[0])


def matrix_rpy(R: np.ndarray) -> tuple[float, float, float]:
    """Inverse of rpy_matrix, accurate everywhere including pitch = ±90° (pivots of ±90° hit it).

    Yaw first, then roll and pitch from M = Rz(-yaw) R = Ry(pitch) Rx(roll), whose entries used
    here are all of order one: no division by cos(pitch), so no loss of accuracy near the pole.
    """
    if np.hypot(R[0, 0], R[1, 0]) < 1e-12:
        yaw = 0.0  # gimbal lock: only roll - yaw is defined; a canonical choice keeps output stable
    else:
        yaw = float(np.arctan2(R[1, 0], R[0, 0]))
    M = Rz(-yaw) @ R
    roll = float(np.arctan2(-M[1, 2], M[1, 1]))
    pitch = float(np.arctan2(-M[2, 0], M[0, 0]))
    return roll, pitch, yaw
