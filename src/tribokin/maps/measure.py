"""Measuring a block of map targets: each target's cycles drawn from its own stream and measured like a single
pose (joint-space approach), keeping only its scalar figures (``map.statistic = "one-test"``,
:func:`~tribokin.maps.schema.map_figures`)."""

from __future__ import annotations

import math

import numpy as np

from tribokin.iso9283.metrics import orientation_repeatability, position_spread, variance_contributions
from tribokin.maps.budget import TARGET_BLOCK_SAMPLES
from tribokin.maps.schema import map_figures
from tribokin.propagation.exact import tool_deviations_at_poses
from tribokin.simulation.pose_test import PoseRunner, joint_space_task
from tribokin.streams import map_target_stream
from tribokin.units import MDEG_PER_RAD, UM_PER_M


def measure_targets(runner: PoseRunner, qs: np.ndarray, indices: np.ndarray, twists: np.ndarray,
                    translations: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One-test figures (targets, ``map_figures("one-test")``), bearing loads [N] (targets, nv) and dominant joint
    (-1: none) of the targets ``indices`` at configurations ``qs`` (targets, nv), each drawn from its own stream
    and measured like a single pose (joint-space approach); ``twists``, ``translations``: their
    :func:`~tribokin.propagation.exact.tool_frames`. Targets go through in blocks of even sizes, of at most about
    ``TARGET_BLOCK_SAMPLES`` cycles: few enough for the arrays to stay small, enough to share the
    per-call costs."""
    study = runner.settings
    task = joint_space_task("map target", np.zeros(qs.shape[1]))  # the draws use its approach directions only
    forces = runner.normal_forces_at(qs)
    figures = np.empty((len(qs), len(map_figures("one-test"))))
    dominant = np.empty(len(qs), dtype=int)
    blocks = math.ceil(len(qs) / max(1, TARGET_BLOCK_SAMPLES // study.cycles))
    for b in range(blocks):  # blocks of even sizes: no small last one paying the per-call costs alone
        members = slice(len(qs) * b // blocks, len(qs) * (b + 1) // blocks)
        per_joint = np.empty((len(indices[members]), qs.shape[1], study.cycles))  # cycles contiguous
        for k, (load, index) in enumerate(zip(forces[members], indices[members], strict=True)):
            per_joint[k] = runner.draw(task, load, study.cycles, study.approach,
                                       map_target_stream(study.seed, int(index)))[0].T
        figures[members], dominant[members] = block_figures(runner, qs[members], np.swapaxes(per_joint, 1, 2),
                                                            twists[members], translations[members])
    return figures, forces, dominant


def block_figures(runner: PoseRunner, qs: np.ndarray, dq: np.ndarray, twists: np.ndarray, translations: np.ndarray):
    """One-test figures (targets, 7) and dominant joint (targets,) of deviations ``dq`` (targets, n, nv)."""
    positions, angles = tool_deviations_at_poses(runner.robot, qs, dq, runner.settings.engine, twists, translations)
    shares = variance_contributions(twists[:, :3], dq)
    dominant = np.where(np.isnan(shares).all(axis=1), -1, np.argmax(np.nan_to_num(shares, nan=-1.0), axis=1))
    spread = position_spread(positions)
    figures = np.column_stack([
        spread.RP_l_m * UM_PER_M,
        np.linalg.norm(spread.barycenter_m - translations, axis=1) * UM_PER_M,
        orientation_repeatability(angles) * MDEG_PER_RAD,
        spread.largest_semi_axis_m * UM_PER_M,
        np.where(dominant < 0, np.nan, np.take_along_axis(shares, np.maximum(dominant, 0)[:, None], axis=1)[:, 0]),
    ])
    return figures, dominant
