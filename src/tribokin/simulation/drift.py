"""ISO 9283's drift test at a pose, simulated (a study's ``[drift]``): the pose approached from one direction once a
cycle for a span of cycles, its first and last sets of cycles measured.

Per test (ISO 9283:1998 §7.2.3, drift of pose characteristics): dAP_p, the distance between the two sets'
barycentres; dRP_l, |RP_l of the first set − RP_l of the last|; dRP_a, dRP_b, dRP_c likewise of RP_a, RP_b, RP_c.
Each figure here is its mean over simulated tests (each joint's friction series from its start in every test: cold,
or warm), with the mean's relative Monte Carlo standard error and the 2.5 and 97.5 % points of its tests. The figures
are absolute differences: with stationary friction and no warm-up they are not zero but E|AP₁ − AP₂| and
E|RP₁ − RP₂| of two independent sets, what two ISO tests of the same robot differ by.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from tribokin.iso9283.gaussian_tests import BAND_PERCENTILES, mean_error
from tribokin.iso9283.metrics import orientation_repeatability, position_spread
from tribokin.propagation.exact import tool_deviations
from tribokin.simulation.pose_result import PoseResult
from tribokin.simulation.pose_test import PoseRunner, PoseTask
from tribokin.streams import drift_stream
from tribokin.tribology.friction_series import COLD, WARM
from tribokin.units import MDEG_PER_RAD, UM_PER_M

#: The drift figures of a test [µm, mdeg].
DRIFT_FIGURES = ("dAP_p_um", "dRP_l_um", "dRP_a_mdeg", "dRP_b_mdeg", "dRP_c_mdeg")
#: Simulated tests: about this many measured cycles in all (the two sets of each test), at least ``MIN_TESTS``, at
#: most ``MAX_TESTS``; drawn in blocks of at most ``BLOCK_CYCLES`` cycles of the span (bounded memory).
MEASURED_CYCLES, MIN_TESTS, MAX_TESTS, BLOCK_CYCLES = 480_000, 100, 8_000, 2_000_000


@dataclass(frozen=True)
class DriftTest:
    """A drift test: ``span_cycles`` cycles from one approach direction (the test's duration over the cycle time),
    its first and last ``set_cycles`` measured; ``warm``: each joint's warm-up starts where its mean friction settles
    it (:meth:`~tribokin.tribology.thermal.Thermal.settled_C`), else at ambient (cold)."""

    span_cycles: int
    set_cycles: int
    warm: bool = False

    def __post_init__(self):
        if not 2 <= self.set_cycles <= self.span_cycles // 2:
            raise ValueError(f"{self.span_cycles} cycles hold no two sets of {self.set_cycles}")

    @property
    def tests(self) -> int:
        """Simulated tests: about ``MEASURED_CYCLES`` measured cycles, within ``MIN_TESTS`` .. ``MAX_TESTS``."""
        return int(np.clip(math.ceil(MEASURED_CYCLES / (2 * self.set_cycles)), MIN_TESTS, MAX_TESTS))


def drift_tests(runner: PoseRunner, task: PoseTask, forces_N: np.ndarray, direction: np.ndarray, drift: DriftTest,
                tests: int, rng: np.random.Generator) -> dict[str, np.ndarray]:
    """(tests,) each of :data:`DRIFT_FIGURES` [µm, mdeg] of ``tests`` simulated drift tests at ``task``'s pose under
    bearing loads ``forces_N`` (nv,) [N], every cycle approached with joint signs ``direction`` (nv,): the span drawn
    as the pose's test draws it (:meth:`~tribokin.simulation.pose_test.PoseRunner.deviations`), the two sets through
    the study's engine."""
    span, size, nv = drift.span_cycles, drift.set_cycles, len(direction)
    dq, _ = runner.deviations(task, forces_N, np.broadcast_to(direction, (tests * span, nv)), rng, tests,
                               WARM if drift.warm else COLD)
    dq = dq.reshape(tests, span, nv)
    sets = np.concatenate([dq[:, :size], dq[:, span - size:]], axis=1).reshape(-1, nv)
    positions, angles = tool_deviations(runner.robot, task.q, sets, runner.settings.engine)
    spread = position_spread(positions.reshape(tests, 2, size, 3))
    rp_abc = orientation_repeatability(angles.reshape(tests, 2, size, 3)) * MDEG_PER_RAD
    figures = {"dAP_p_um": np.linalg.norm(spread.barycenter_m[:, 0] - spread.barycenter_m[:, 1], axis=-1) * UM_PER_M,
               "dRP_l_um": np.abs(spread.RP_l_m[:, 0] - spread.RP_l_m[:, 1]) * UM_PER_M}
    for i, axis in enumerate("abc"):
        figures[f"dRP_{axis}_mdeg"] = np.abs(rp_abc[:, 0, i] - rp_abc[:, 1, i])
    return figures


def pose_drift(runner: PoseRunner, task: PoseTask, drift: DriftTest, index: int) -> dict[str, dict]:
    """Per approach direction the ``approach`` mode tests at ``task`` (label -> ``{"drift": ...}``): each of
    :data:`DRIFT_FIGURES` as its mean over :attr:`DriftTest.tests` simulated tests, ``mc_errors`` (each mean's
    relative standard error) and ``band`` (each figure's 2.5 and 97.5 % points over the tests). Pose ``index``'s
    drift stream (:func:`~tribokin.streams.drift_stream`), each direction's tests drawn from it in turn."""
    task = task.tested(runner.settings.approach)
    forces, rng, tests = runner.normal_forces(task), drift_stream(runner.settings.seed, index), drift.tests
    each = max(1, BLOCK_CYCLES // drift.span_cycles)
    out = {}
    for label, direction in zip(task.labels, task.directions, strict=True):
        blocks = [drift_tests(runner, task, forces, direction.astype(float), drift, min(each, tests - start), rng)
                  for start in range(0, tests, each)]
        figures = {name: np.concatenate([block[name] for block in blocks]) for name in DRIFT_FIGURES}
        out[label] = {"drift": {
            **{name: float(values.mean()) for name, values in figures.items()},
            "tests": tests, "span_cycles": drift.span_cycles, "set_cycles": drift.set_cycles,
            "start": "warm" if drift.warm else "cold",
            "mc_errors": {name: float(mean_error(values)) for name, values in figures.items()},
            "band": {name: np.percentile(values, BAND_PERCENTILES).tolist() for name, values in figures.items()}}}
    return out


def with_drift(runner: PoseRunner, tasks: list[PoseTask], results: list[PoseResult], drift: DriftTest,
               first: int = 0) -> list[PoseResult]:
    """``results`` (of ``tasks``; task ``k`` pose number ``first + k``) with each direction's drift test
    (:func:`pose_drift`) among its further figures, under ``drift``."""
    out = []
    for k, (task, result) in enumerate(zip(tasks, results, strict=True)):
        figures = pose_drift(runner, task, drift, first + k)
        out.append(replace(result, direction_extra={label: {**extra, **figures.get(label, {})}
                                                    for label, extra in result.direction_extra.items()}))
    return out
