"""A pose's expected figures beside its one simulated test: per approach direction, each figure's mean over ISO tests
of ``cycles`` cycles, computed as a map target's (:func:`~tribokin.maps.expected_figures.direction_tests`), under their
own keys (``expected_RP_l_um``...; never a second ``RP_l_um``)."""

from __future__ import annotations

from dataclasses import replace

from tribokin.iso9283.gaussian_tests import ASYMPTOTIC_CYCLES
from tribokin.maps.expected_figures import SPLIT_FIGURES, ExpectedSetup, direction_tests, shape_table
from tribokin.simulation.joint_errors import friction_lever, friction_loads
from tribokin.simulation.pose_result import PoseResult
from tribokin.simulation.pose_test import PoseRunner, PoseTask


def expected_key(name: str) -> str:
    """A pose's key of expected figure ``name`` (``RP_l_um`` -> ``expected_RP_l_um``)."""
    return f"expected_{name}"


def pose_expected_figures(runner: PoseRunner, task: PoseTask) -> dict[str, dict[str, float]]:
    """Per approach direction the ``approach`` mode tests at ``task`` (label -> figures), the expected figures
    (:data:`~tribokin.maps.expected_figures.SPLIT_FIGURES`, :func:`expected_key`) [µm, mdeg] of tests of the runner's
    ``cycles`` cycles every one from that direction: at the pose's configuration, bearing loads and joint models (its
    own friction law too), as a map target's with the same settings gives them."""
    task = task.tested(runner.settings.approach)
    if task.friction is not None:  # the sampled tests draw from the pose's own law
        runner = PoseRunner(runner.settings, runner.robot, runner.models_at(task), runner.locate)
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

