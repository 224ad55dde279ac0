"""Measuring a block of map targets: each target's cycles drawn from its own stream and measured like a single
pose (joint-space approach; approached from both directions, ``cycles`` from each and their figures per direction),
keeping only its scalar figures (``map.statistic = "one-test"``, :func:`~tribokin.maps.schema.map_figures`)."""

from __future__ import annotations

import math

import numpy as np

from tribokin.iso9283.metrics import orientation_repeatability, position_spread, variance_contributions
from tribokin.maps.budget import TARGET_BLOCK_SAMPLES
from tribokin.maps.schema import DIRECTIONS, direction_figure, map_figures, per_direction
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
    both = per_direction(study.approach)
    cycles = study.cycles * (len(task.labels) if both else 1)
    forces = runner.normal_forces_at(qs)
    figures = np.empty((len(qs), len(map_figures("one-test", both))))
    dominant = np.empty(len(qs), dtype=int)
    blocks = math.ceil(len(qs) / max(1, TARGET_BLOCK_SAMPLES // cycles))
    for b in range(blocks):  # blocks of even sizes: no small last one paying the per-call costs alone
        members = slice(len(qs) * b // blocks, len(qs) * (b + 1) // blocks)
        per_joint = np.empty((len(indices[members]), qs.shape[1], cycles))  # cycles contiguous
        groups = np.empty((len(indices[members]), cycles), dtype=int)
        for k, (load, index) in enumerate(zip(forces[members], indices[members], strict=True)):
            stream = map_target_stream(study.seed, int(index))
            dq, _, groups[k] = runner.draw(task, load, cycles, study.approach, stream)
            per_joint[k] = dq.T
        arguments = runner, qs[members], np.swapaxes(per_joint, 1, 2), twists[members], translations[members]
        figures[members], dominant[members] = (directions_block_figures(*arguments, groups) if both
                                               else block_figures(*arguments))
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


def directions_block_figures(runner: PoseRunner, qs: np.ndarray, dq: np.ndarray, twists: np.ndarray,
                             translations: np.ndarray, groups: np.ndarray):
    """One-test figures (targets, ``map_figures("one-test", True)``) and dominant joint (targets,) of deviations ``dq``
    (targets, n, nv) approached from direction ``groups`` (targets, n) (0: +, 1: -): each direction's figures
    (NaN for one of fewer than two cycles), each unsuffixed figure the larger of the two, RP_l of every cycle pooled;
    the joints' shares of the variance about each direction's mean. Targets of the same sequence of directions
    together (all of a bidirectional map's)."""
    positions, angles = tool_deviations_at_poses(runner.robot, qs, dq, runner.settings.engine, twists, translations)
    columns = {figure.name: k for k, figure in enumerate(map_figures("one-test", True))}
    figures = np.full((len(qs), len(columns)), np.nan)
    centred = dq.copy()
    sequences, inverse = np.unique(groups, axis=0, return_inverse=True)
    for s, sequence in enumerate(sequences):
        members = np.flatnonzero(inverse.ravel() == s)
        for d, label in enumerate(DIRECTIONS):
            mine = sequence == d
            centred[np.ix_(members, mine)] -= dq[np.ix_(members, mine)].mean(axis=1, keepdims=True)
            if np.count_nonzero(mine) < 2:
                continue
            spread = position_spread(positions[np.ix_(members, mine)])
            rp_abc = orientation_repeatability(angles[np.ix_(members, mine)]) * MDEG_PER_RAD
            own = {"RP_l_um": spread.RP_l_m * UM_PER_M, "largest_semi_axis_um": spread.largest_semi_axis_m * UM_PER_M,
                   "AP_p_um": np.linalg.norm(spread.barycenter_m - translations[members], axis=1) * UM_PER_M,
                   **{f"RP_{axis}_mdeg": rp_abc[:, i] for i, axis in enumerate("abc")}}
            for name, value in own.items():
                figures[members, columns[name]] = np.fmax(figures[members, columns[name]], value)
                if direction_figure(name, label) in columns:  # the semi-axis: the larger only
                    figures[members, columns[direction_figure(name, label)]] = value
    figures[:, columns["RP_l_all_directions_um"]] = position_spread(positions).RP_l_m * UM_PER_M
    shares = variance_contributions(twists[:, :3], centred)
    dominant = np.where(np.isnan(shares).all(axis=1), -1, np.argmax(np.nan_to_num(shares, nan=-1.0), axis=1))
    figures[:, columns["dominant_share"]] = np.where(
        dominant < 0, np.nan, np.take_along_axis(shares, np.maximum(dominant, 0)[:, None], axis=1)[:, 0])
    return figures, dominant
