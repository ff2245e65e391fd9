"""Dynamics of a compiled robot (pinocchio) and the worst-case static torque check."""
