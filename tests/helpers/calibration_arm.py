"""A synthetic 6-joint arm measured at 5 poses × 3 directions, simulated joint by joint (not by the model's code)."""

from __future__ import annotations

import numpy as np

from tribokin.calibration.data import PoseData, SeriesData
from tribokin.calibration.model import JointModel

JOINTS = tuple(f"j{i + 1}" for i in range(6))
#: Truth: distinct stiffnesses [N·m/rad], backlash [rad], instrument noise [m].
STIFFNESS = np.array([6.0, 3.5, 5.0, 1.2, 1.5, 1.0]) * 1e4
BACKLASH = np.array([2.0, 1.0, 1.5, 3.0, 2.0, 2.5]) * 1e-5
NOISE_FLOOR_M = 1e-6
#: Approach signs of the three directions.
DIRECTIONS = {"+": np.ones(6), "-": -np.ones(6), "x": np.array([1.0, -1, 1, -1, 1, -1])}


def arm_kinematics(poses: int = 5, seed: int = 21) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """(J (3, 6) [m/rad], τ̄ (6,) [N·m], σ_τ (6,) [N·m]) at ``poses`` random well-conditioned poses."""
    rng = np.random.default_rng(seed)
    kinematics = []
    while len(kinematics) < poses:
        jacobian = rng.normal(0.0, 0.4, (3, 6))
        if np.linalg.cond(jacobian) < 5:
            torque_mean = rng.uniform(0.3, 0.8, 6)
            kinematics.append((jacobian, torque_mean, 0.25 * torque_mean))
    return kinematics


def simulate(kinematics, rng: np.random.Generator, cycles: int = 30, stiffness=STIFFNESS, backlash=BACKLASH,
             noise_floor_m: float = NOISE_FLOOR_M, directions=DIRECTIONS,
             rotation: np.ndarray | None = None, shift_m: np.ndarray | None = None,
             registered: bool = True) -> list[PoseData]:
    """Measured clouds: each cycle draws every joint's torque, moves the tool by J·dq, adds instrument noise.

    Every pose has its own absolute position (geometric error) and joint offsets; ``rotation`` and
    ``shift_m`` move the measured points into another frame (``x = rotation·x_base + shift_m``); the
    Jacobians are turned alike when ``registered``, else left in the base frame.
    """
    rotation = np.eye(3) if rotation is None else rotation
    shift_m = np.zeros(3) if shift_m is None else shift_m
    poses = []
    for p, (jacobian, torque_mean, torque_std) in enumerate(kinematics):
        origin = rng.normal(0.0, 0.5, 3)
        offset = rng.normal(0.0, 1e-4, 6)
        series = []
        for label, signs in directions.items():
            torque = rng.normal(torque_mean, torque_std, (cycles, 6))
            dq = offset + signs * (torque / stiffness + backlash / 2)
            points = origin + dq @ jacobian.T + rng.normal(0.0, noise_floor_m, (cycles, 3))
            series.append(SeriesData(label, signs, points @ rotation.T + shift_m))
        poses.append(PoseData(f"P{p + 1}", rotation @ jacobian if registered else jacobian, torque_mean, torque_std,
                              tuple(series)))
    return poses


def arm_model(fit_stiffness=(True,) * 6, fit_backlash=(True,) * 6, fit_noise_floor: bool = True,
              tie: str = "none") -> JointModel:
    """The arm's joint model: fixed values true, free ones nominally 2× off (the noise floor 3×)."""
    return JointModel(JOINTS, np.where(fit_stiffness, 2.0, 1.0) * STIFFNESS,
                      np.where(fit_backlash, 2.0, 1.0) * BACKLASH, NOISE_FLOOR_M * (3.0 if fit_noise_floor else 1.0),
                      tuple(fit_stiffness), tuple(fit_backlash), fit_noise_floor, tie=tie)
