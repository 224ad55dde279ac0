"""A pose's expected figures beside its one simulated test: per approach direction, each figure's mean over ISO tests
of ``cycles`` cycles, computed as a map target's (:func:`~tribokin.maps.expected_figures.direction_tests`), under their
own keys (``expected_RP_l_um``...; never a second ``RP_l_um``). Where a joint's friction is a time series, sampled
tests, or in closed form where the model allows, with their Monte Carlo errors (:func:`series_expected_figures`)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from tribokin.iso9283.gaussian_tests import ASYMPTOTIC_CYCLES
from tribokin.kinematics.robot import Robot
from tribokin.maps.expected_figures import SPLIT_FIGURES, ExpectedSetup, direction_tests, shape_table
from tribokin.maps.schema import mc_error_name
from tribokin.maps.series_expected import correlated_figures, series_factor
from tribokin.simulation.joint_errors import JointErrorModel, friction_lever, friction_loads
from tribokin.simulation.pose_result import PoseResult
from tribokin.simulation.pose_test import PoseRunner, PoseTask, TestSettings, pose_task, run_poses
from tribokin.tribology.laws import FrictionLaw


def expected_key(name: str) -> str:
    """A pose's key of expected figure ``name`` (``RP_l_um`` -> ``expected_RP_l_um``)."""
    return f"expected_{name}"


def pose_expected_figures(runner: PoseRunner, task: PoseTask, factor: int | None = None
                          ) -> dict[str, dict[str, float]]:
    """Per approach direction the ``approach`` mode tests at ``task`` (label -> figures), the expected figures
    (:data:`~tribokin.maps.expected_figures.SPLIT_FIGURES`, :func:`expected_key`) [µm, mdeg] of tests of the runner's
    ``cycles`` cycles every one from that direction: at the pose's configuration, bearing loads and joint models (its
    own friction law too), as a map target's with the same settings gives them; where a joint's friction is a time
    series, by :func:`series_expected_figures` (``factor``: :func:`~tribokin.maps.series_expected.series_factor`,
    computed here when not given)."""
    task = task.tested(runner.settings.approach)
    if task.friction is not None:  # the sampled tests draw from the pose's own law
        runner = PoseRunner(runner.settings, runner.robot, runner.models_at(task), runner.locate)
    if any(m.correlated for m in runner.models):
        forces = runner.normal_forces(task)
        factor = series_factor(runner) if factor is None else factor
        return {label: series_expected_figures(runner, task, forces, direction.astype(float), factor)
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


def series_expected_figures(runner: PoseRunner, task: PoseTask, forces_N: np.ndarray, direction: np.ndarray,
                            factor: int) -> dict[str, float | str]:
    """The expected figures (:data:`~tribokin.maps.expected_figures.SPLIT_FIGURES`, :func:`expected_key`) [µm, mdeg]
    of tests of the runner's ``cycles`` cycles at ``task``'s pose under bearing loads ``forces_N`` (nv,) [N], every
    cycle approached with joint signs ``direction`` (nv,), where a joint's friction is a time series
    (:func:`~tribokin.maps.series_expected.correlated_figures`, ``factor`` times the default tests), each with its
    relative Monte Carlo standard error (``expected_<stem>_mc_error``: ``expected_RP_l_mc_error``...) and how they were
    computed (``expected_method``: ``"analytic"`` or ``"sampled"``)."""
    figures = correlated_figures(runner, task, forces_N, direction, factor)
    return {**{expected_key(name): figures.values[name] for name in SPLIT_FIGURES},
            **{expected_key(mc_error_name(name)): figures.mc_errors[name] for name in SPLIT_FIGURES},
            expected_key("method"): figures.method}


def with_expected_figures(runner: PoseRunner, tasks: list[PoseTask], results: list[PoseResult]) -> list[PoseResult]:
    """``results`` (of ``tasks``, :func:`~tribokin.simulation.pose_test.run_poses`) with each direction's expected
    figures (:func:`pose_expected_figures`) among its further figures."""
    out = []
    factor = series_factor(runner) if any(m.correlated for m in runner.models) else None  # the same at every pose
    for task, result in zip(tasks, results, strict=True):
        expected = pose_expected_figures(runner, task, factor)
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
