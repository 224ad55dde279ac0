"""A pose's ISO 9283 test: sample the cycles of each approach direction, propagate them, take their figures."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Protocol

import numpy as np

from tribokin.errors import JointRangeError, SettingsError, TribokinError
from tribokin.iso9283.cube import label_approach_signs
from tribokin.iso9283.gaussian_tests import BAND_PERCENTILES, percentile_error
from tribokin.iso9283.metrics import (
    covariance_semi_axes,
    directional_metrics,
    position_repeatability,
    variance_contributions,
)
from tribokin.kinematics.loads import BearingLoads
from tribokin.kinematics.robot import Robot
from tribokin.propagation.exact import engine_bound, tool_deviations
from tribokin.simulation.joint_errors import (
    APPROACH_MODES,
    JointErrorModel,
    approach_signs,
    check_travel,
    draw_friction,
    joint_travel,
    require_cycle_time,
    sample_joint_deviations,
    torque_per_value,
)
from tribokin.simulation.pose_result import PoseResult
from tribokin.streams import pose_stream, replicate_stream
from tribokin.tribology.friction_series import COLD, FrictionState
from tribokin.tribology.laws import FrictionLaw
from tribokin.units import UM_PER_M

#: Replicate tests for the 95 % interval of RP_l: rounds of about ``REPLICATE_SAMPLES`` cycles (at least
#: ``MIN_REPLICATES`` tests each) until each end's relative Monte Carlo standard error is at most
#: ``REPLICATE_ERROR_AIM`` (:func:`~tribokin.iso9283.gaussian_tests.percentile_error`), at most
#: ``MAX_REPLICATE_ROUNDS`` rounds.
REPLICATE_SAMPLES, MIN_REPLICATES, REPLICATE_ERROR_AIM, MAX_REPLICATE_ROUNDS = 240_000, 20, 0.008, 16


class RunSettings(Protocol):
    """What a :class:`PoseRunner` reads of its settings: a :class:`TestSettings` (a
    :class:`tribokin.study.spec.Study` has them too)."""

    cycles: int
    seed: int
    approach: str
    engine: str
    payload_kg: float  # the robot's payload [kg]
    cycle_time_s: float | None  # one cycle's duration [s], what a joint's friction warm-up reads


#: The propagation engines (:func:`~tribokin.propagation.exact.tool_deviations`).
ENGINES = ("fast", "exact")


@dataclass(frozen=True)
class TestSettings:
    """How a pose's ISO 9283 test is run, a study's ``[study]`` values as a plain spec.

    Attributes:
        cycles: cycles n of each approach direction's test (at least 2: ISO's S_l divides by n - 1).
        seed: the random streams' seed (0 to 2**64 - 1).
        approach: ``"unidirectional"`` (ISO's), ``"bidirectional"`` or ``"random"`` (:data:`APPROACH_MODES`).
        engine: ``"fast"`` (the product of exponentials with its bound, falling back to the exact one) or
            ``"exact"`` (Pinocchio's forward kinematics) (:data:`ENGINES`).
        payload_kg: the payload at the tool point [kg], for the bearing loads from statics.
        cycle_time_s: one cycle's duration [s] (an approach to the pose, its dwell included): what a joint's friction
            warm-up (:attr:`~tribokin.simulation.joint_errors.JointErrorModel.series`' ``thermal``) reads; ``None``:
            not given.

    Raises:
        SettingsError: a value outside its range, naming it.
    """

    __test__ = False  # not a pytest test class, whatever its name

    cycles: int = 30
    seed: int = 0
    approach: str = "unidirectional"
    engine: str = "fast"
    payload_kg: float = 0.0
    cycle_time_s: float | None = None

    def __post_init__(self):
        whole = isinstance(self.cycles, (int, np.integer)) and not isinstance(self.cycles, bool)
        if not whole or self.cycles < 2:
            raise SettingsError(f"cycles must be a whole number >= 2 (got {self.cycles!r})", "cycles")
        if isinstance(self.seed, bool) or not isinstance(self.seed, (int, np.integer)) or not 0 <= self.seed < 2 ** 64:
            raise SettingsError(f"seed must be a whole number from 0 to 2**64 - 1 (got {self.seed!r})", "seed")
        for name, valid in (("approach", APPROACH_MODES), ("engine", ENGINES)):
            if getattr(self, name) not in valid:
                raise SettingsError(f"{name} must be one of {', '.join(valid)} (got {getattr(self, name)!r})", name)
        if not (isinstance(self.payload_kg, (int, float)) and math.isfinite(self.payload_kg) and self.payload_kg >= 0):
            raise SettingsError(f"payload_kg must be a finite number >= 0 (got {self.payload_kg!r})", "payload_kg")
        time = self.cycle_time_s
        if time is not None and not (isinstance(time, (int, float)) and math.isfinite(time) and time > 0):
            raise SettingsError(f"cycle_time_s must be a finite number > 0 s (got {time!r})", "cycle_time_s")

    @classmethod
    def of(cls, settings: RunSettings) -> TestSettings:
        """The settings of anything that has them (a :class:`tribokin.study.spec.Study`)."""
        return cls(settings.cycles, settings.seed, settings.approach, settings.engine, settings.payload_kg,
                   settings.cycle_time_s)


#: Approach directions of a joint-space pose: every joint travelling +, then every joint travelling -.
JOINT_SPACE_DIRECTIONS = ("+", "-")


@dataclass
class PoseTask:
    """A pose to run: configuration [m or rad] and its approach directions: the joints' signs of
    travel (m, nv; 0 for a joint that does not move) and a label for each (``"+"``, ``"-"`` in joint space;
    ``"+x"``... for a cube pose); ``every_direction``: each is tested whatever the approach mode."""

    name: str
    q: np.ndarray
    directions: np.ndarray
    labels: tuple[str, ...]
    normal_force_N: float | None = None
    friction: FrictionLaw | None = None
    every_direction: bool = False

    def tested(self, mode: str) -> PoseTask:
        """The task with the directions an ``approach`` mode tests: the + ones (unidirectional) or all
        (bidirectional, random); all of them when the task names its directions (``every_direction``)."""
        if mode != "unidirectional" or self.every_direction:
            return self
        keep = [k for k, label in enumerate(self.labels) if label.startswith("+")]
        return replace(self, directions=self.directions[keep], labels=tuple(self.labels[k] for k in keep))


def joint_space_task(name: str, q: np.ndarray, normal_force_N: float | None = None,
                     friction: FrictionLaw | None = None) -> PoseTask:
    """A pose approached in joint space: every joint travelling + (or - for the second direction)."""
    return PoseTask(name, q, np.vstack([np.ones(len(q)), -np.ones(len(q))]), JOINT_SPACE_DIRECTIONS,
                    normal_force_N=normal_force_N, friction=friction)


def pose_task(robot: Robot, name: str, q, directions: tuple[str, ...] | None = None,
              normal_force_N: float | None = None, friction: FrictionLaw | None = None) -> PoseTask:
    """A pose to test at configuration ``q`` (nv,) [m or rad]: approached in joint space (:func:`joint_space_task`),
    or along each of ``directions`` (labels such as ``"+x"``, ``"-z"``:
    :func:`~tribokin.iso9283.cube.label_approach_signs`), each then tested whatever the approach mode;
    ``normal_force_N`` [N] and ``friction``, when given, every joint's at this pose.

    Raises:
        ConfigurationError: ``q`` of the wrong size, not finite or outside the joint limits.
        SettingsError: a direction that names no approach.
    """
    q = robot.check_configuration(q)
    task = joint_space_task(name, q, normal_force_N, friction)
    if directions is not None:
        signs = [label_approach_signs(robot, q, label) for label in directions]
        if any(sign is None for sign in signs):
            raise SettingsError(f"unknown approach direction {directions[signs.index(None)]!r}: +x, -y, ..., "
                                "+0.58+0.58+0.58, + or -", "directions")
        signs = np.array(signs)
        task = replace(task, directions=signs, labels=tuple(directions), every_direction=True)
    return task


class PoseRunner:
    """Runs poses of one robot and its joint models: samples the cycles, propagates them, measures them.

    Args:
        settings: cycles, seed, approach, engine and payload (a :class:`TestSettings`, or a study).
        robot: the robot.
        models: one error model per active joint, in the robot's joint order.
        locate: what a :class:`~tribokin.errors.JointRangeError` becomes (a study's: an error naming its file and
            key); ``None``: raised as it is. Picklable, when a map's job carries it to its workers.
        state: where the joints' friction series start in every test
            (:class:`~tribokin.tribology.friction_series.FrictionState`; a map's ``state``).
        warm_up_loads_N: (nv,) the bearing loads [N] a warming joint's power rests on in every test (a map's, the same
            at every target); ``None``: the tested pose's.
    """

    def __init__(self, settings: RunSettings, robot: Robot, models: list[JointErrorModel],
                 locate: Callable[[TribokinError], TribokinError] | None = None, state: FrictionState = COLD,
                 warm_up_loads_N: np.ndarray | None = None):
        self.settings, self.robot, self.models, self.locate = settings, robot, list(models), locate
        self.state, self.warm_up_loads_N = state, warm_up_loads_N
        require_cycle_time(self.models, settings.cycle_time_s)
        self.offsets = np.array([m.offset for m in models])
        self.loads = None
        if any(m.normal_force_N is None for m in models):
            self.loads = BearingLoads(robot, settings.payload_kg, [m.bearing_span_m for m in models])
        self.travel = joint_travel(robot.lower_limits, robot.upper_limits, robot.joint_is_prismatic)

    def normal_forces(self, task: PoseTask) -> np.ndarray:
        """Bearing loads [N]: the pose's value, else each joint's fixed value, else statics at the pose;
        refused (:meth:`check_travel`) if they would move a joint beyond its range."""
        if task.normal_force_N is not None:
            forces = np.full(len(self.models), task.normal_force_N)
        else:
            forces = self._loads_at(task.q)
        self.check_travel(forces, self.models_at(task))
        return forces

    def normal_forces_at(self, q: np.ndarray, placements: np.ndarray | None = None) -> np.ndarray:
        """Bearing loads [N] at configuration ``q`` (nv,) or configurations (poses, nv): each joint's
        fixed value, else statics (from ``placements``, the robot's serial chain's
        :meth:`~tribokin.kinematics.chain.SerialChain.tool_in_joint` at ``q``, when given); refused
        (:meth:`check_travel`) if they would move a joint beyond its range."""
        forces = self._loads_at(q, placements)
        self.check_travel(forces, self.models)
        return forces

    def _loads_at(self, q: np.ndarray, placements: np.ndarray | None = None) -> np.ndarray:
        fixed = np.array([np.nan if m.normal_force_N is None else m.normal_force_N for m in self.models])
        if self.loads is None:
            return np.broadcast_to(fixed, np.shape(q)[:-1] + fixed.shape).copy()
        return np.where(np.isnan(fixed), self.loads(q, placements), fixed)

    def check_travel(self, forces_N: np.ndarray, models: list[JointErrorModel]) -> None:
        """Refuse loads ``forces_N`` (..., nv) [N] under which a joint's deviation could exceed its range."""
        try:
            check_travel(models, self.robot.joint_is_prismatic, forces_N, self.travel, self.robot.joint_names)
        except JointRangeError as error:
            if self.locate is None:
                raise
            raise self.locate(error) from None

    def models_at(self, task: PoseTask) -> list[JointErrorModel]:
        """The joint error models at a pose: the runner's, with the pose's friction law if it has one (a law only:
        its cycles independent, whatever time series the joints' own friction is)."""
        if task.friction is None:
            return self.models
        return [replace(m, friction=task.friction, series=None) for m in self.models]

    def draw(self, task: PoseTask, forces_N, cycles: int, mode: str, rng):
        """Joint deviations of the cycles at one pose: (dq (n, nv) [m or rad], mu (n, nv), approach index (n,))."""
        signs, group = approach_signs(mode, cycles, task.directions, rng)
        dq, drawn = self.deviations(task, forces_N, signs, rng)
        return dq, drawn.values, group

    def deviations(self, task: PoseTask, forces_N, signs: np.ndarray, rng, tests: int = 1,
                   state: FrictionState | None = None, temperatures: bool = False):
        """Joint deviations dq (n, nv) [m or rad] and the friction laws' draws (n, nv) of n cycles at a pose under
        bearing loads ``forces_N`` (nv,) [N], joint signs ``signs`` (n, nv): ``tests`` tests one after another, a
        joint's friction series running through each from its start, ``state`` (``None``: the runner's), with
        ``temperatures`` the warming joints' temperatures they were drawn at
        (:func:`~tribokin.simulation.joint_errors.sample_joint_deviations`)."""
        return sample_joint_deviations(self.models_at(task), self.robot.joint_is_prismatic, forces_N, signs, rng,
                                       tests, self.settings.cycle_time_s, self.state if state is None else state,
                                       self.warm_up_loads_N, temperatures)

    def at(self, state: FrictionState) -> PoseRunner:
        """This runner with its joints' friction series starting from ``state``."""
        return PoseRunner(self.settings, self.robot, self.models, self.locate, state, self.warm_up_loads_N)

    @property
    def correlated(self) -> bool:
        """A joint's friction is a time series
        (:attr:`~tribokin.simulation.joint_errors.JointErrorModel.correlated`)."""
        return any(m.correlated for m in self.models)

    def friction_tests(self, tests: int, cycles: int, rng: np.random.Generator) -> np.ndarray:
        """(tests, cycles, nv) the joints' friction draws of ``tests`` tests of ``cycles`` cycles, each from the
        runner's ``state``, a warming joint's power on its ``warm_up_loads_N`` (a map's common random numbers: the
        same at every target)."""
        torque = None
        if self.warm_up_loads_N is not None:
            torque = torque_per_value(self.models, self.robot.joint_is_prismatic, self.warm_up_loads_N)
        mu = draw_friction(self.models, tests * cycles, rng, tests, torque, self.settings.cycle_time_s,
                           self.state).values
        return mu.reshape(tests, cycles, len(self.models))

    def approach_sequence(self, task: PoseTask, rng) -> tuple[np.ndarray, np.ndarray]:
        """The joints' signs of travel (n, nv) and the approach index (n,) of every cycle at a pose:
        ``settings.cycles`` from each direction, one series after another (unidirectional) or in turn
        (bidirectional); or as many cycles in all, each from a direction drawn at random (random). A joint's friction
        series starts afresh with each unidirectional series (each its own test), and runs through the others."""
        mode, count, cycles = self.settings.approach, len(task.directions), self.settings.cycles
        if mode == "unidirectional":
            group = np.repeat(np.arange(count), cycles)
            return task.directions[group].astype(float), group
        return approach_signs(mode, count * cycles, task.directions, rng)

    def measure(self, task: PoseTask, rng: np.random.Generator) -> PoseResult:
        """Sample the cycles of every approach direction the ``approach`` mode tests at ``task`` from
        ``rng`` and take their ISO 9283 figures."""
        task = task.tested(self.settings.approach)
        forces = self.normal_forces(task)
        signs, group = self.approach_sequence(task, rng)
        tests = len(task.directions) if self.settings.approach == "unidirectional" else 1
        dq, drawn = self.deviations(task, forces, signs, rng, tests)
        positions, angles = tool_deviations(self.robot, task.q, dq, self.settings.engine)
        commanded = self.robot.tool_placement(task.q)
        metrics = directional_metrics(positions, angles, commanded.translation, group, task.labels)
        reference = self.robot.tool_placement(task.q + self.offsets)
        return PoseResult(task.name, task.q, commanded.translation.copy(), commanded.rotation.copy(),
                          reference.translation.copy(), positions, angles, task.labels, group, drawn.values, dq,
                          forces, metrics, joint_names=tuple(self.robot.joint_names), robot=self.robot)

    def run(self, task: PoseTask, index: int) -> PoseResult:
        """Measure pose ``index`` (ISO 9283 per approach direction and across them, and beyond)."""
        result = self.measure(task, pose_stream(self.settings.seed, index))
        if task.friction is not None:
            result.extra["friction"] = task.friction.describe()
        result = replace(result, direction_extra=self.beyond_iso(task, result.normal_forces_N, result, index))
        if self.settings.engine == "fast":  # the bound of the engine used, over every cycle it computed
            used = engine_bound(self.robot, task.q, result.dq)
            result.extra["engine_used"] = used.engine if used.engine == "exact" else f"fast, order {used.order}"
            result.extra["engine_max_deviation_nm"] = used.position_m * 1e9
            result.extra["engine_max_angle_deviation_nrad"] = used.angle_rad * 1e9
        return result

    def beyond_iso(self, task: PoseTask, forces_N, result: PoseResult, index: int) -> dict[str, dict]:
        """Per approach direction with ISO figures: joint shares of the position variance, 1-sigma
        ellipsoid semi-axes [µm], 95 % interval of RP_l [µm] and its ends' relative Monte Carlo standard errors.

        The interval comes from replicate tests of ``settings.cycles`` cycles each from that direction
        (fresh random streams), propagated to first order through the position Jacobian: how much
        a test of this length can vary (:func:`replicate_interval`).
        """
        jacobian = self.robot.tool_jacobian(task.q)[:3]
        cycles = self.settings.cycles
        rng = replicate_stream(self.settings.seed, index)
        figures = {}
        for label in result.metrics.directions:
            mine = result.approach == result.directions.index(label)
            shares = variance_contributions(jacobian, result.dq[mine])
            extra = {f"contribution_{name}": None if np.isnan(share) else float(share)
                     for name, share in zip(self.robot.joint_names, shares, strict=True)}
            extra["ellipsoid_semi_axes_um"] = (covariance_semi_axes(result.positions_m[mine]) * UM_PER_M).tolist()
            signs = task.directions[task.labels.index(label)].astype(float)

            def replicates(tests: int, signs=signs) -> np.ndarray:  # (tests,) RP_l [m] of replicate tests
                dq, _ = self.deviations(task, forces_N, np.broadcast_to(signs, (tests * cycles, len(signs))), rng,
                                        tests)
                return position_repeatability((dq @ jacobian.T).reshape(tests, cycles, 3))[0]

            interval, errors = replicate_interval(replicates, cycles)
            extra["RP_l_95_um"] = (interval * UM_PER_M).tolist()
            extra["RP_l_95_mc_error"] = errors.tolist()
            figures[label] = extra
        return figures


def replicate_interval(replicates: Callable[[int], np.ndarray], cycles: int) -> tuple[np.ndarray, np.ndarray]:
    """The 2.5 and 97.5 % points of RP_l over replicate tests of ``cycles`` cycles, ``replicates(tests)`` giving each
    round's, and their relative Monte Carlo standard errors: rounds of ``REPLICATE_SAMPLES`` cycles (at least
    ``MIN_REPLICATES`` tests) until both errors are within ``REPLICATE_ERROR_AIM`` (or ``MAX_REPLICATE_ROUNDS``)."""
    tests = max(MIN_REPLICATES, math.ceil(REPLICATE_SAMPLES / cycles))
    each = max(1, REPLICATE_SAMPLES // cycles)  # tests drawn at once: about REPLICATE_SAMPLES cycles in memory
    rp = np.empty(0)
    for _ in range(MAX_REPLICATE_ROUNDS):
        rp = np.concatenate([rp, *(replicates(min(each, tests - start)) for start in range(0, tests, each))])
        errors = np.array([percentile_error(rp, p) for p in BAND_PERCENTILES])
        if errors.max() <= REPLICATE_ERROR_AIM:
            break
    return np.percentile(rp, BAND_PERCENTILES), errors


def run_poses(runner: PoseRunner, tasks: list[PoseTask], first: int = 0) -> list[PoseResult]:
    """Every task's :meth:`PoseRunner.run`, the loads of all of them checked before any is sampled; task ``k`` is pose
    number ``first + k``, whose random streams it draws from."""
    for task in tasks:
        runner.normal_forces(task)
    return [runner.run(task, first + k) for k, task in enumerate(tasks)]
