"""ISO 9283's drift test at a pose, simulated (a study's ``[drift]``): the pose approached from one direction once a
cycle for a span of cycles, its first and last sets of cycles measured.

Per test (ISO 9283:1998 §7.2.3, drift of pose characteristics): dAP_p, the distance between the two sets'
barycentres; dRP_l, |RP_l of the first set − RP_l of the last|; dRP_a, dRP_b, dRP_c likewise of RP_a, RP_b, RP_c.
Each figure here is its mean over simulated tests (each joint's friction series from its start in every test: cold,
or warm), with the mean's relative Monte Carlo standard error and the 2.5 and 97.5 % points of its tests. The figures
are absolute differences: with stationary friction and no warm-up they are not zero but E|AP₁ − AP₂| and
E|RP₁ − RP₂| of two independent sets, what two ISO tests of the same robot differ by.

Along the span, for its figure (:class:`PoseDrift`): the AP_p and RP_l of sets of the same size at several times
between the start and end sets (:meth:`DriftTest.set_starts`; the start and end sets the figures' own), means over the
same tests with their standard errors and bands, and each warming joint's temperature at every cycle's start, the one
its friction was drawn at (:class:`~tribokin.simulation.joint_errors.FrictionDraws`), its mean over the tests.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np

from tribokin.iso9283.gaussian_tests import BAND_PERCENTILES, mean_error
from tribokin.iso9283.metrics import orientation_repeatability, position_spread
from tribokin.propagation.exact import tool_deviations
from tribokin.simulation.joint_errors import warming_joints
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
#: Sets along the span in a pose's drift figure, the start and end sets included: at most this many, apart.
SERIES_SETS = 5


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
    def start(self) -> str:
        """``"warm"`` or ``"cold"``: how each test's joints start."""
        return "warm" if self.warm else "cold"

    @property
    def tests(self) -> int:
        """Simulated tests: about ``MEASURED_CYCLES`` measured cycles, within ``MIN_TESTS`` .. ``MAX_TESTS``."""
        return int(np.clip(math.ceil(MEASURED_CYCLES / (2 * self.set_cycles)), MIN_TESTS, MAX_TESTS))

    def set_starts(self) -> np.ndarray:
        """(k,) the first cycle of each set along the span in the drift figure: the start set (0), the end set (span −
        set) and evenly between, at most :data:`SERIES_SETS` and as many as fit without overlapping (rounded
        starts stay at least a set apart, since their spacing is)."""
        count = min(SERIES_SETS, self.span_cycles // self.set_cycles)
        return np.round(np.linspace(0, self.span_cycles - self.set_cycles, count)).astype(int)


@dataclass(frozen=True, eq=False)
class SetSeries:
    """An approach direction's sets along the span (:meth:`DriftTest.set_starts`), over the simulated tests.

    Attributes:
        AP_p_m: (k,) each set's AP_p (its barycentre's distance from the commanded position) [m], mean over the tests.
        RP_l_m: (k,) each set's RP_l [m], mean over the tests.
        AP_p_change_error_m: (k,) the standard error (Monte Carlo) of each set's mean change of AP_p from the start
            set's, ``AP_p_m - AP_p_m[0]`` [m] (the tests' own changes: paired; 0 at the start set).
        RP_l_change_error_m: (k,) the same of RP_l [m].
    """

    AP_p_m: np.ndarray
    RP_l_m: np.ndarray
    AP_p_change_error_m: np.ndarray
    RP_l_change_error_m: np.ndarray

    @classmethod
    def of(cls, ap_m: np.ndarray, rp_m: np.ndarray) -> SetSeries:
        """The means over the tests of their (tests, k) AP_p and RP_l [m], and their changes' standard errors."""
        root = math.sqrt(len(ap_m))
        return cls(ap_m.mean(axis=0), rp_m.mean(axis=0), (ap_m - ap_m[:, :1]).std(axis=0, ddof=1) / root,
                   (rp_m - rp_m[:, :1]).std(axis=0, ddof=1) / root)


@dataclass(frozen=True, eq=False)
class PoseDrift:
    """A pose's drift test along its span, what its figure shows (``drift_<pose>.png``).

    Attributes:
        pose: the pose's name.
        test: the drift test.
        cycle_time_s: one cycle's duration [s].
        set_starts: (k,) each set's first cycle (:meth:`DriftTest.set_starts`).
        directions: per approach direction label, its sets' AP_p and RP_l.
        joints: the names of the joints whose friction warms them (their series' ``thermal``), in the robot's order.
        temperature_C: (span, j) each of those joints' temperature at each cycle's start [°C], mean over the tests
            of every direction.
        temperature_error_C: (span, j) its standard error [°C] (Monte Carlo).
    """

    pose: str
    test: DriftTest
    cycle_time_s: float
    set_starts: np.ndarray
    directions: dict[str, SetSeries]
    joints: tuple[str, ...]
    temperature_C: np.ndarray
    temperature_error_C: np.ndarray

    @property
    def set_times_s(self) -> np.ndarray:
        """(k,) the middle of each set [s] from the test's start."""
        return (self.set_starts + self.test.set_cycles / 2) * self.cycle_time_s

    @property
    def cycle_times_s(self) -> np.ndarray:
        """(span,) the start of each cycle [s] from the test's start."""
        return np.arange(self.test.span_cycles) * self.cycle_time_s


class DriftBlock(NamedTuple):
    """A block of simulated drift tests: each of :data:`DRIFT_FIGURES` (tests,) [µm, mdeg]; the AP_p and RP_l
    (tests, k) [m] of each set along the span (:meth:`DriftTest.set_starts`); each warming joint's temperature
    (span, j) [°C] at each cycle's start, its mean over the block's tests, and the sum of its squared deviations
    from that mean [K²]."""

    figures: dict[str, np.ndarray]
    AP_p_m: np.ndarray
    RP_l_m: np.ndarray
    temperature_C: np.ndarray
    temperature_squares: np.ndarray


def pooled(blocks: list[DriftBlock]) -> tuple[np.ndarray, np.ndarray]:
    """The temperature's mean [°C] over every test of ``blocks`` and its standard error [°C] (Chan et al.'s pooled
    sum of squares)."""
    counts = np.array([len(block.AP_p_m) for block in blocks], dtype=float)
    means = np.array([block.temperature_C for block in blocks])
    mean = np.tensordot(counts, means, axes=1) / counts.sum()
    squares = sum(block.temperature_squares for block in blocks) + \
        np.tensordot(counts, (means - mean) ** 2, axes=1)
    return mean, np.sqrt(squares / (counts.sum() - 1) / counts.sum())


def drift_tests(runner: PoseRunner, task: PoseTask, forces_N: np.ndarray, direction: np.ndarray, drift: DriftTest,
                tests: int, rng: np.random.Generator) -> DriftBlock:
    """``tests`` simulated drift tests at ``task``'s pose under bearing loads ``forces_N`` (nv,) [N], every cycle
    approached with joint signs ``direction`` (nv,): the span drawn as the pose's test draws it
    (:meth:`~tribokin.simulation.pose_test.PoseRunner.deviations`), the start and end sets through the study's engine
    (the figures), then the sets between them (the figure's; apart, so the figures' engine sees their cycles alone)."""
    span, size, nv = drift.span_cycles, drift.set_cycles, len(direction)
    state = WARM if drift.warm else COLD
    dq, drawn = runner.deviations(task, forces_N, np.broadcast_to(direction, (tests * span, nv)), rng, tests, state,
                                  temperatures=True)
    dq = dq.reshape(tests, span, nv)
    sets = np.concatenate([dq[:, :size], dq[:, span - size:]], axis=1).reshape(-1, nv)
    positions, angles = tool_deviations(runner.robot, task.q, sets, runner.settings.engine)
    spread = position_spread(positions.reshape(tests, 2, size, 3))
    rp_abc = orientation_repeatability(angles.reshape(tests, 2, size, 3)) * MDEG_PER_RAD
    figures = {"dAP_p_um": np.linalg.norm(spread.barycenter_m[:, 0] - spread.barycenter_m[:, 1], axis=-1) * UM_PER_M,
               "dRP_l_um": np.abs(spread.RP_l_m[:, 0] - spread.RP_l_m[:, 1]) * UM_PER_M}
    for i, axis in enumerate("abc"):
        figures[f"dRP_{axis}_mdeg"] = np.abs(rp_abc[:, 0, i] - rp_abc[:, 1, i])
    barycentres, rp_l = spread.barycenter_m, spread.RP_l_m
    between = drift.set_starts()[1:-1]
    if between.size:
        cycles = (between[:, None] + np.arange(size)).ravel()
        inner, _ = tool_deviations(runner.robot, task.q, dq[:, cycles].reshape(-1, nv), runner.settings.engine)
        inner = position_spread(inner.reshape(tests, between.size, size, 3))
        barycentres = np.concatenate([barycentres[:, :1], inner.barycenter_m, barycentres[:, 1:]], axis=1)
        rp_l = np.concatenate([rp_l[:, :1], inner.RP_l_m, rp_l[:, 1:]], axis=1)
    ap_p = np.linalg.norm(barycentres - runner.robot.tool_placement(task.q).translation, axis=-1)
    temperature = drawn.temperature_C
    mean = temperature.mean(axis=0)
    squares = np.array([((temperature[..., k] - mean[:, k]) ** 2).sum(axis=0) for k in range(mean.shape[1])])
    return DriftBlock(figures, ap_p, rp_l, mean, squares.T.reshape(mean.shape))


def pose_drift(runner: PoseRunner, task: PoseTask, drift: DriftTest, index: int) -> tuple[dict[str, dict], PoseDrift]:
    """Per approach direction the ``approach`` mode tests at ``task`` (label -> ``{"drift": ...}``): each of
    :data:`DRIFT_FIGURES` as its mean over :attr:`DriftTest.tests` simulated tests, ``mc_errors`` (each mean's
    relative standard error) and ``band`` (each figure's 2.5 and 97.5 % points over the tests); and the tests along
    their span (:class:`PoseDrift`). Pose ``index``'s drift stream (:func:`~tribokin.streams.drift_stream`), each
    direction's tests drawn from it in turn."""
    task = task.tested(runner.settings.approach)
    forces, rng, tests = runner.normal_forces(task), drift_stream(runner.settings.seed, index), drift.tests
    each = max(1, BLOCK_CYCLES // drift.span_cycles)
    out, series, every = {}, {}, []
    for label, direction in zip(task.labels, task.directions, strict=True):
        blocks = [drift_tests(runner, task, forces, direction.astype(float), drift, min(each, tests - start), rng)
                  for start in range(0, tests, each)]
        figures = {name: np.concatenate([block.figures[name] for block in blocks]) for name in DRIFT_FIGURES}
        out[label] = {"drift": {
            **{name: float(values.mean()) for name, values in figures.items()},
            "tests": tests, "span_cycles": drift.span_cycles, "set_cycles": drift.set_cycles,
            "start": drift.start,
            "mc_errors": {name: float(mean_error(values)) for name, values in figures.items()},
            "band": {name: np.percentile(values, BAND_PERCENTILES).tolist() for name, values in figures.items()}}}
        series[label] = SetSeries.of(np.concatenate([block.AP_p_m for block in blocks]),
                                     np.concatenate([block.RP_l_m for block in blocks]))
        every += blocks
    temperature, error = pooled(every)
    joints = tuple(runner.robot.joint_names[i] for i in warming_joints(runner.models_at(task)))
    return out, PoseDrift(task.name, drift, runner.settings.cycle_time_s, drift.set_starts(), series, joints,
                          temperature, error)


def with_drift(runner: PoseRunner, tasks: list[PoseTask], results: list[PoseResult], drift: DriftTest,
               first: int = 0) -> tuple[list[PoseResult], tuple[PoseDrift, ...]]:
    """``results`` (of ``tasks``; task ``k`` pose number ``first + k``) with each direction's drift test
    (:func:`pose_drift`) among its further figures, under ``drift``; and each pose's tests along their span."""
    out, drifts = [], []
    for k, (task, result) in enumerate(zip(tasks, results, strict=True)):
        figures, along = pose_drift(runner, task, drift, first + k)
        out.append(replace(result, direction_extra={label: {**extra, **figures.get(label, {})}
                                                    for label, extra in result.direction_extra.items()}))
        drifts.append(along)
    return out, tuple(drifts)
