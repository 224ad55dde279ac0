"""Calibrating joint stiffness, backlash and instrument noise from plain arrays.

``tribokin.calibration.fit.fit`` takes NumPy arrays, no file: per measured pose the tool point's position Jacobian,
each joint's mean friction torque and its standard deviation, and per approach direction the joints' approach signs
and the measured points. Here the points are drawn from a known 3-joint model (4 poses, 2 directions, 40 cycles
each), so the fit can be checked: the script prints each parameter's estimate, its 95 % interval and the truth.
"""

import numpy as np

from tribokin.calibration.data import PoseData, SeriesData
from tribokin.calibration.fit import fit
from tribokin.calibration.model import JointModel

JOINTS = ("shoulder", "elbow", "wrist")
STIFFNESS = np.array([4.0e4, 2.0e4, 8.0e3])  # N·m/rad, the truth
BACKLASH = np.array([2.0e-5, 3.0e-5, 4.0e-5])  # rad
NOISE_FLOOR_M = 1.0e-6  # m, the instrument's
DIRECTIONS = {"+": np.ones(3), "-": -np.ones(3)}  # each joint's approach sign
rng = np.random.default_rng(12)

poses = []
for p in range(4):
    jacobian = rng.normal(0.0, 0.5, (3, 3))  # m/rad, at this pose
    torque_mean = rng.uniform(0.5, 1.5, 3)  # N·m, friction torque
    torque_std = 0.3 * torque_mean
    origin = rng.normal(0.0, 0.5, 3)  # m, where the pose is
    series = []
    for label, signs in DIRECTIONS.items():
        torque = rng.normal(torque_mean, torque_std, (40, 3))
        dq = signs * (torque / STIFFNESS + BACKLASH / 2)  # each cycle's lost motion [rad]
        points = origin + dq @ jacobian.T + rng.normal(0.0, NOISE_FLOOR_M, (40, 3))
        series.append(SeriesData(label, signs, points))
    poses.append(PoseData(f"P{p + 1}", jacobian, torque_mean, torque_std, tuple(series)))

# the nominal model the fit starts from: every value 2x off the truth, all of them free
model = JointModel(JOINTS, 2 * STIFFNESS, 2 * BACKLASH, 2 * NOISE_FLOOR_M, fit_stiffness=(True,) * 3,
                   fit_backlash=(True,) * 3, fit_noise_floor=True)
calibration = fit(model, poses)
print(f"converged: {calibration.converged}, log L = {calibration.log_likelihood:.2f}")

truth = {**{f"joints.{j}.stiffness": k for j, k in zip(JOINTS, STIFFNESS, strict=True)},
         **{f"joints.{j}.backlash": b for j, b in zip(JOINTS, BACKLASH, strict=True)},
         "noise_floor_m": NOISE_FLOOR_M}
for estimate in calibration.parameters:
    if estimate.ci95 is None:  # on the information's null space: the data do not determine it
        print(f"{estimate.name}: not identifiable ({estimate.hint})")
        continue
    low, high = estimate.ci95
    inside = "inside" if low <= truth[estimate.name] <= high else "OUTSIDE"
    print(f"{estimate.name}: {estimate.value:.4g} {estimate.unit}, 95 % interval [{low:.4g}, {high:.4g}], "
          f"truth {truth[estimate.name]:.4g} ({inside})")
