"""Predicted ISO 9283 figures with prediction intervals, and leave-one-pose-out cross-validation.

Prediction at a pose: ``draws`` parameter vectors θ, the identifiable parameters drawn from their
marginal N(θ̂, covariance) (the fit's approximate posterior in log space; their covariance holds what
their correlation with the others costs them), the parameters the data do not determine held at θ̂
(a Gaussian in log space is no approximation of a likelihood that is flat on one side and steep on the
other: its draws reach stiffnesses the measured spreads exclude; so the interval does not hold those
parameters' uncertainty, and the fit names them), each giving the series' Σ and m(s) (:func:`~.model.predict_series`);
for each draw one ISO test is simulated as Gaussian clouds of the measured number of cycles per
direction, and its RP_l per direction (l̄ + 3·S_l) and vAP (largest distance between the
directions' barycentres) computed. The 95 % prediction interval runs from the 2.5th to the 97.5th
percentile of those figures (the tests drawn and measured in blocks of about ``PREDICTION_BLOCK_CYCLES``
cycles, the numbers of one draw of them all, so memory stays bounded): it holds both the parameters'
uncertainty and the test-to-test spread of a figure computed from n cycles. The prediction is the
expected figure of one test at the fitted values: the mean over ``draws`` tests simulated at θ̂ (a mean
over the posterior draws would be dominated by the heavy tail of poorly determined parameters). Random numbers:
``numpy.random.default_rng([seed, pose index])`` in leave-one-pose-out.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tribokin.calibration.data import PoseData
from tribokin.calibration.fit import Calibration, fit
from tribokin.calibration.model import JointModel, predict_series
from tribokin.iso9283.metrics import largest_distance
from tribokin.measurement.figures import at_once

DRAWS = 2000
SEED = 9283
#: Cycles of a prediction's simulated tests drawn and measured at once (a few tens of MiB).
PREDICTION_BLOCK_CYCLES = 2 ** 18
#: Bytes per simulated cycle of a block: its normal draws (24), the cloud (24), its offsets (24), distances (8),
#: rounded up for NumPy's temporaries.
PREDICTION_BYTES_PER_CYCLE = 128


@dataclass(frozen=True)
class PredictedFigure:
    """A measured figure beside its prediction [m].

    Attributes:
        measured_m: from the measured cycles.
        predicted_m: expected value of the figure for one test (mean over the draws).
        interval_m: (low, high) 95 % prediction interval of one test's figure.
    """

    measured_m: float
    predicted_m: float
    interval_m: tuple[float, float]


@dataclass(frozen=True)
class PosePrediction:
    """Measured and predicted figures at one pose.

    Attributes:
        pose: pose label.
        directions: approach labels, in the order of ``RP_l``.
        RP_l: one per direction; None for a one-cycle series (too short for RP).
        vAP: across directions, None with one direction.
    """

    pose: str
    directions: tuple[str, ...]
    RP_l: tuple[PredictedFigure | None, ...]
    vAP: PredictedFigure | None


def prediction_bytes(cycles: int, draws: int = DRAWS) -> int:
    """Bytes a prediction at a series of ``cycles`` holds at once (a block of simulated tests) [bytes]."""
    return min(2 * draws, at_once(cycles, PREDICTION_BLOCK_CYCLES)) * cycles * PREDICTION_BYTES_PER_CYCLE


def position_repeatability(points_m: np.ndarray) -> np.ndarray:
    """ISO 9283 RP_l = l̄ + 3·S_l of clouds (..., n, 3) [m] → (...)."""
    distances = np.linalg.norm(points_m - points_m.mean(axis=-2, keepdims=True), axis=-1)
    return distances.mean(axis=-1) + 3 * distances.std(axis=-1, ddof=1)


def _summary(measured: float, figures: np.ndarray) -> PredictedFigure:
    """``figures``: (2·draws,) at θ̂ first, then at the posterior draws."""
    at_fit, drawn = np.split(figures, 2)
    low, high = np.percentile(drawn, [2.5, 97.5])
    return PredictedFigure(float(measured), float(at_fit.mean()), (float(low), float(high)))


def _draw_theta(calibration: Calibration, draws: int, rng: np.random.Generator) -> np.ndarray:
    """(p, 2·draws) θ: θ̂ ``draws`` times, then ``draws`` of the identifiable parameters from their approximate
    posterior (their marginal Gaussian), the others held at θ̂ (module docstring)."""
    theta = np.repeat(calibration.theta[:, None], 2 * draws, axis=1)
    known = np.array([p.identifiable for p in calibration.parameters])
    if not known.any():
        return theta
    covariance = calibration.covariance[np.ix_(known, known)]
    theta[known, draws:] = rng.multivariate_normal(calibration.theta[known], covariance, size=draws,
                                                   method="eigh").T
    return theta


def predict_pose(calibration: Calibration, pose: PoseData, rng: np.random.Generator,
                 draws: int = DRAWS) -> PosePrediction:
    """RP_l per direction and vAP at ``pose`` predicted by a fit, beside those of its measured series.

    The clouds are simulated in the frame of the pose's Jacobian (the base); RP_l (distances to a
    cloud's own barycentre) and vAP (distances between barycentres) do not change with a rigid
    motion, so measured points in an unregistered frame compare as they are.
    """
    model = calibration.nominal
    stiffness, backlash, noise = model.unpack(_draw_theta(calibration, draws, rng))
    tests = 2 * draws
    signs = np.array([s.signs for s in pose.series], dtype=float)
    covariance, shift = predict_series(stiffness[:, None], backlash[:, None], noise[:, None], pose.jacobian,
                                       signs, pose.torque_mean, pose.torque_std, model.joint_noise)
    factor = np.linalg.cholesky(covariance)
    rp_l, barycentres = [], []
    for d, series in enumerate(pose.series):
        cycles = len(series.points_m)
        simulated, centres = np.empty(tests), np.empty((tests, 3))
        for start in range(0, tests, block := at_once(cycles, PREDICTION_BLOCK_CYCLES)):
            tested = slice(start, min(start + block, tests))
            cloud = shift[tested, d, None, :] + np.einsum(
                "kab,knb->kna", factor[tested, d], rng.standard_normal((tested.stop - start, cycles, 3)))
            if cycles > 1:
                simulated[tested] = position_repeatability(cloud)
            centres[tested] = cloud.mean(axis=1)
        rp_l.append(_summary(position_repeatability(np.asarray(series.points_m)), simulated) if cycles > 1 else None)
        barycentres.append(centres)
    vap = None
    if len(pose.series) > 1:
        measured = np.array([np.mean(s.points_m, axis=0) for s in pose.series])
        simulated = np.stack(barycentres, axis=1)
        spans = np.linalg.norm(simulated[:, :, None] - simulated[:, None, :], axis=-1).max(axis=(1, 2))
        vap = _summary(largest_distance(measured), spans)
    return PosePrediction(pose.label, tuple(s.direction for s in pose.series), tuple(rp_l), vap)


def predicted_clouds(calibration: Calibration, pose: PoseData) -> list[tuple[np.ndarray, np.ndarray]]:
    """Per series of ``pose``: its covariance Σ [m²] and barycentre [m] at the fitted values. The pose's own
    position, which friction does not explain, is the V⁻¹-weighted mean of x̄_a - m(s_a) over its series (V = Σ/n),
    as the likelihood takes it."""
    signs = np.array([s.signs for s in pose.series], dtype=float)
    covariance, shift = calibration.model.predict(pose.jacobian, signs, pose.torque_mean, pose.torque_std)
    weights = np.linalg.inv(covariance / np.array([len(s.points_m) for s in pose.series])[:, None, None])
    measured = np.array([np.mean(s.points_m, axis=0) for s in pose.series])
    position = np.linalg.solve(weights.sum(axis=0), np.einsum("mab,mb->a", weights, measured - shift))
    return [(c, position + m) for c, m in zip(covariance, shift, strict=True)]


def leave_one_pose_out(model: JointModel, poses: list[PoseData] | tuple[PoseData, ...], draws: int = DRAWS,
                       seed: int = SEED, frame: str = "registered") -> tuple[PosePrediction, ...]:
    """For each pose: fit ``model`` to the other poses (``frame`` as in :func:`~tribokin.calibration.fit.fit`),
    predict this one (module docstring)."""
    predictions = []
    for i, pose in enumerate(poses):
        calibration = fit(model, [p for j, p in enumerate(poses) if j != i], frame=frame)
        predictions.append(predict_pose(calibration, pose, np.random.default_rng([seed, i]), draws))
    return tuple(predictions)
