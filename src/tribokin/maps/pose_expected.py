"""A pose's expected figures beside its one simulated test: per approach direction, each figure's mean over ISO tests
of ``cycles`` cycles, computed as a map target's (:func:`~tribokin.maps.expected_figures.direction_tests`), under their
own keys (``expected_RP_l_um``...; never a second ``RP_l_um``). Where a joint's friction is a time series, sampled
tests through the study's engine instead (:func:`series_expected_figures`)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from tribokin.iso9283.gaussian_tests import ASYMPTOTIC_CYCLES, BAND_PERCENTILES
from tribokin.iso9283.metrics import orientation_repeatability, position_spread
from tribokin.kinematics.robot import Robot
from tribokin.maps.expected_figures import (
    SAMPLED_CYCLES,
    SPLIT_FIGURES,
    ExpectedSetup,
    direction_tests,
    shape_table,
    tests_for,
)
from tribokin.propagation.exact import tool_deviations
from tribokin.simulation.joint_errors import JointErrorModel, friction_lever, friction_loads
from tribokin.simulation.pose_result import PoseResult
from tribokin.simulation.pose_test import PoseRunner, PoseTask, TestSettings, pose_task, run_poses
from tribokin.streams import expected_stream
from tribokin.tribology.laws import FrictionLaw
from tribokin.units import MDEG_PER_RAD, UM_PER_M


def expected_key(name: str) -> str:
    """A pose's key of expected figure ``name`` (``RP_l_um`` -> ``expected_RP_l_um``)."""
    return f"expected_{name}"


def pose_expected_figures(runner: PoseRunner, task: PoseTask) -> dict[str, dict[str, float]]:
    """Per approach direction the ``approach`` mode tests at ``task`` (label -> figures), the expected figures
    (:data:`~tribokin.maps.expected_figures.SPLIT_FIGURES`, :func:`expected_key`) [µm, mdeg] of tests of the runner's
    ``cycles`` cycles every one from that direction: at the pose's configuration, bearing loads and joint models (its
    own friction law too), as a map target's with the same settings gives them; where a joint's friction is a time
    series, by :func:`series_expected_figures`."""
    task = task.tested(runner.settings.approach)
    if task.friction is not None:  # the sampled tests draw from the pose's own law
        runner = PoseRunner(runner.settings, runner.robot, runner.models_at(task), runner.locate)
    if any(m.correlated for m in runner.models):
        forces = runner.normal_forces(task)
        return {label: series_expected_figures(runner, task, forces, direction.astype(float))
                for label, direction in zip(task.labels, task.directions, strict=True)}
    cycles, seed = runner.settings.cycles, runner.settings.seed
    setup = ExpectedSetup.build(runner, None if cycles >= ASYMPTOTIC_CYCLES else shape_table(cycles, seed), "expected")
    forces = runner.normal_forces(task)[None]
    lever = friction_loads(runner.models, forces) * friction_lever(runner.models, runner.robot.joint_is_prismatic)
    commanded = runner.robot.tool_placement(task.q).translation[None]
    figures = {}
    for label, direction in zip(task.labels, task.directions, strict=True):
        tests = direction_tests(runner, setup, task.q[None], lever, direction.astype(float), commanded)
        figures[label] = {expected_key(name): float(tests.values[name][0]) for name in SPLIT_FIGURES}
    return figures


def series_expected_figures(runner: PoseRunner, task: PoseTask, forces_N: np.ndarray, direction: np.ndarray
                            ) -> dict[str, float]:
    """The expected figures (:data:`~tribokin.maps.expected_figures.SPLIT_FIGURES`, :func:`expected_key`) [µm, mdeg]
    of tests of the runner's ``cycles`` cycles at ``task``'s pose under bearing loads ``forces_N`` (nv,) [N], every
    cycle approached with joint signs ``direction`` (nv,), where a joint's friction is a time series: cycles that move
    together are not the independent ones the closed forms and the map's common random numbers assume, and a
    running-in or warm-up moves the mean about which the first-order model is taken. So the tests are sampled whole
    (:func:`~tribokin.maps.expected_figures.tests_for` of ``SAMPLED_CYCLES`` cycles: 2 000 tests of 30 cycles), each
    joint's series from its start in every test (:meth:`PoseRunner.deviations`), through the study's engine (fast with
    its bound, or exact FK): each figure the mean over the tests, the band RP_l's 2.5 and 97.5 % points. The numbers
    are common to every pose and direction (:func:`~tribokin.streams.expected_stream` ``"series tests"``)."""
    cycles = runner.settings.cycles
    tests = tests_for(SAMPLED_CYCLES, cycles)
    signs = np.broadcast_to(direction, (tests * cycles, len(direction)))
    dq, _ = runner.deviations(task, forces_N, signs, expected_stream(runner.settings.seed, "series tests"), tests)
    positions, angles = tool_deviations(runner.robot, task.q, dq, runner.settings.engine)
    spread = position_spread(positions.reshape(tests, cycles, 3))
    rp_l = spread.RP_l_m * UM_PER_M
    rp_abc = orientation_repeatability(angles.reshape(tests, cycles, 3)) * MDEG_PER_RAD
    commanded = runner.robot.tool_placement(task.q).translation
    low, high = np.percentile(rp_l, BAND_PERCENTILES)
    figures = {"RP_l_um": rp_l.mean(), "RP_l_lo_um": low, "RP_l_hi_um": high,
               "AP_p_um": np.linalg.norm(spread.barycenter_m - commanded, axis=-1).mean() * UM_PER_M,
               **{f"RP_{axis}_mdeg": rp_abc[:, i].mean() for i, axis in enumerate("abc")}}
    return {expected_key(name): float(figures[name]) for name in SPLIT_FIGURES}


def with_expected_figures(runner: PoseRunner, tasks: list[PoseTask], results: list[PoseResult]) -> list[PoseResult]:
    """``results`` (of ``tasks``, :func:`~tribokin.simulation.pose_test.run_poses`) with each direction's expected
    figures (:func:`pose_expected_figures`) among its further figures."""
    out = []
    for task, result in zip(tasks, results, strict=True):
        expected = pose_expected_figures(runner, task)
        extra = {label: {**result.direction_extra.get(label, {}), **expected.get(label, {})}
                 for label in dict.fromkeys([*result.direction_extra, *expected])}
        out.append(replace(result, direction_extra=extra))
    return out


def pose_test(robot: Robot, joints: list[JointErrorModel], q, *, name: str = "pose",
              directions: tuple[str, ...] | None = None, normal_force_N: float | None = None,
              friction: FrictionLaw | None = None, cycles: int = 30, seed: int = 0, approach: str = "unidirectional",
              engine: str = "fast", payload_kg: float = 0.0, index: int = 0,
              cycle_time_s: float | None = None) -> PoseResult:
    """A pose's ISO 9283 test: the cycles of each approach direction sampled, propagated to the tool and measured, and
    each direction's expected figures beside them (:func:`with_expected_figures`).

    Args:
        robot: the robot (:class:`~tribokin.kinematics.robot.Robot`).
        joints: one error model per joint (:func:`~tribokin.simulation.joint_errors.joint_models`).
        q: (nv,) the commanded configuration [m or rad].
        name: the pose's name.
        directions: the pose's approach directions (``"+x"``...; ``None``: joint space; :func:`pose_task`).
        normal_force_N: every joint's bearing load at this pose [N] (``None``: the joint models', else statics).
        friction: every joint's friction law at this pose (``None``: the joint models').
        cycles: cycles of each approach direction's test (:class:`TestSettings`).
        seed: the random streams' seed.
        approach: ``"unidirectional"``, ``"bidirectional"`` or ``"random"``.
        engine: ``"fast"`` or ``"exact"``.
        payload_kg: the payload at the tool point [kg].
        index: the pose's number in a study (its random streams: a study's pose ``index`` gives the same figures).
        cycle_time_s: one cycle's duration [s], what a joint's friction warm-up (its ``series``' ``thermal``) reads.

    Returns:
        its samples and ISO 9283 figures per approach direction, the expected ones beside them (µm, mdeg in
        :meth:`~tribokin.simulation.pose_result.PoseResult.report_row`).

    Raises:
        ConfigurationError: a bad ``q``.
        SettingsError: a bad setting.
        JointRangeError: a joint whose deviation could exceed its range.
    """
    runner = PoseRunner(TestSettings(cycles, seed, approach, engine, payload_kg, cycle_time_s), robot, joints)
    task = pose_task(robot, name, q, directions, normal_force_N, friction)
    return with_expected_figures(runner, [task], run_poses(runner, [task], index))[0]
