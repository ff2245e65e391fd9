"""How the cell is shown: obstacles and target markers look the same in every picture and model
(PyBullet scenes and renders, the MJCF)."""
from __future__ import annotations

TARGET_RADIUS = 0.012  # m, the visual-only sphere marking a target
OBSTACLE_RGBA = (0.62, 0.70, 0.78, 1.0)
TARGET_RGBA = (0.86, 0.12, 0.22, 1.0)
