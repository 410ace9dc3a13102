"""Quadrotor frame conventions shared by the views: the same as flyloop's core.

World ENU (x east, y north, z up), body FLU (x forward, y left, z up), quaternion [w, x, y, z]
rotating body to world. Rotor layout is PX4's quad-X (core/src/quadrotor/dynamics.rs).
"""

from __future__ import annotations

import math

import numpy as np

# Rotor i sits at (forward, left) * L/sqrt(2) in the body frame: PX4 quad-X order.
ROTOR_POSITION_SIGNS = np.array([(1.0, -1.0), (-1.0, 1.0), (1.0, 1.0), (-1.0, -1.0)])
# Spin seen from above: -1 counter-clockwise, +1 clockwise (the core's ROTOR_SPIN).
ROTOR_SPIN = (-1, -1, 1, 1)
ROTOR_NAMES = ("FR", "RL", "FL", "RR")


def rotation_matrix(q_wxyz: np.ndarray) -> np.ndarray:
    """The 3x3 matrix of a unit quaternion [w, x, y, z]: world = R @ body."""
    w, x, y, z = q_wxyz
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def euler_rpy(q_wxyz: np.ndarray) -> tuple[float, float, float]:
    """Roll, pitch, yaw in radians (intrinsic Z-Y-X) of a unit quaternion [w, x, y, z]."""
    w, x, y, z = q_wxyz
    roll = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x))))
    yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return roll, pitch, yaw


def quaternion_from_euler(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """The unit quaternion [w, x, y, z] of intrinsic Z-Y-X angles in radians."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return np.array(
        [
            cr * cp * cy + sr * sp * sy,
            sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy,
        ]
    )


def rotor_positions_body(arm_length: float) -> np.ndarray:
    """(4, 3) rotor centres in the body frame, metres, in PX4 motor order."""
    lever = arm_length / math.sqrt(2.0)
    out = np.zeros((4, 3))
    out[:, :2] = ROTOR_POSITION_SIGNS * lever
    return out
