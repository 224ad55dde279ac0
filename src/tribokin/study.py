"""Study file -> run -> results on disk.

``run_study`` takes a TOML path or a mapping and returns a
:class:`~tribokin.results.StudyResult`; ``write_results`` writes it to an
output folder atomically (a temporary folder renamed into place).
"""

from __future__ import annotations

import copy
import hashlib
import sys
import tempfile
from dataclasses import dataclass, fields, replace
from pathlib import Path

import numpy as np

from tribokin.config import Study, cycle_count, parse_study, seed_int

#: Replicate tests simulated for the 95 % interval of RP_l (fewer when they would exceed
#: REPLICATE_SAMPLES cycles in all, never fewer than 20).
RP_REPLICATES = 200
REPLICATE_SAMPLES = 200_000
from tribokin.errors import InputError, closest_hint
from tribokin.cube import APPROACH_DIRECTIONS, place_cube
from tribokin.executors import check_executor
from tribokin.iso9283 import covariance_semi_axes, directional_metrics, position_repeatability, variance_contributions
from tribokin.joints import JointErrorModel, approach_signs, check_travel, joint_travel, sample_joint_deviations
from tribokin.loads import BearingLoads
from tribokin.propagate import max_deviation_from_exact, tool_deviations
from tribokin.memory import check_disk, check_memory
from tribokin.names import check_file_name_part, check_files_apart, check_name, pose_figure_file, scenario_files
from tribokin.results import UM_PER_M, PoseResult, StudyResult, software_versions
from tribokin.robot import Robot, load_example_robot, load_urdf
from tribokin.tribology.laws import FrictionLaw
from tribokin.tribology.spec import law_from_spec

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib


def read_study_file(path) -> Study:
    """Read and validate a TOML study file."""
    path = Path(path)
    if not path.is_file():
        raise InputError("study file not found", path)
    content = path.read_bytes()
    try:
        mapping = tomllib.loads(content.decode("utf-8"))
    except ValueError as error:  # also a number of more than 4300 digits
        raise InputError(f"not valid TOML: {error}", path) from None
    study = parse_study(mapping, str(path), path.parent)
    study.sha256 = hashlib.sha256(content).hexdigest()
    return study


def load_study(study, cycles: int | None = None, seed: int | None = None) -> Study:
    """A :class:`Study` from a path, a mapping or a Study, with ``cycles``/``seed`` overriding the file."""
    if isinstance(study, Study):
        study = copy.copy(study)
    elif isinstance(study, dict):
        study = parse_study(study, "<mapping>", Path.cwd())
    else:
        study = read_study_file(study)
    if cycles is not None:
        study.cycles = cycle_count(cycles, "command line", "--cycles")
    if seed is not None:
        study.seed = seed_int(seed, "command line", "--seed")
    study.scenarios = [replace(s, study=_with_run_overrides(s.study, s.overrides.get("study", {}), study))
                       for s in study.scenarios]
    return study


def robot_spec(study: Study) -> dict:
    """The study's ``[robot]`` table with absolute paths: loads the same robot from any folder."""
    spec = dict(study.robot)
    if spec["urdf"] is not None:
        spec["urdf"] = str((study.base_dir / spec["urdf"]).absolute())
    spec["package_dirs"] = [str((study.base_dir / p).absolute()) for p in spec["package_dirs"]]
    return spec


def load_robot_spec(spec: dict, source=None) -> Robot:
    """The robot a ``[robot]`` table with absolute paths names (see :func:`robot_spec`)."""
    if spec["name"] is not None:
        return load_example_robot(spec["name"], spec["tool_frame"], source)
    return load_urdf(spec["urdf"], spec["tool_frame"], spec["package_dirs"], source)


def _with_run_overrides(scenario: Study, own: dict, base: Study) -> Study:
    """A scenario's study with the base's ``cycles`` and ``seed`` (command-line overrides included),
    unless the scenario sets its own."""
    return replace(scenario, cycles=own.get("cycles", base.cycles), seed=own.get("seed", base.seed))


def load_robot(study: Study) -> Robot:
    """The robot a study names, reduced to its tool frame's chain."""
    return load_robot_spec(robot_spec(study), study.source)


def joint_models(study: Study, robot: Robot) -> list[JointErrorModel]:
    """One error model per active joint: the ``[joints]`` defaults with ``[joints.<name>]`` overrides."""
    names = robot.joint_names
    for joint in study.joint_overrides:
        if joint not in names:
            raise InputError(f"unknown joint '{joint}'{closest_hint(joint, names)}; joints of {robot.label}: "
                             f"{', '.join(names)}", study.source, f"joints.{joint}")
    models = []
    for name in names:
        values = {**study.joints, **study.joint_overrides.get(name, {})}
        for key in ("friction", "stiffness"):
            if values[key] is None:
                raise InputError(f"joint '{name}' has no {key}: set joints.{key} or joints.{name}.{key}",
                                 study.source, f"joints.{key}")
        key = f"joints.{name}.friction" if "friction" in study.joint_overrides.get(name, {}) else "joints.friction"
        values["friction"] = law_from_spec(values["friction"], study.source, key, study.base_dir)
        models.append(JointErrorModel(**values))
    return models


def pose_rng(seed: int, index: int, stream: int = 0) -> np.random.Generator:
    """Random stream ``stream`` of pose ``index``: depends on the seed, the index and the stream only."""
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(index, stream)))


#: Approach directions of a joint-space pose: every joint travelling +, then every joint travelling -.
JOINT_SPACE_DIRECTIONS = ("+", "-")


@dataclass
class PoseTask:
    """A pose to run: configuration [m or rad] and its approach directions: the joints' signs of
    travel (m, nv) and a label for each (``"+"``, ``"-"`` in joint space; ``"+x"``... for a cube pose)."""

    name: str
    q: np.ndarray
    directions: np.ndarray
    labels: tuple[str, ...]
    normal_force_N: float | None = None
    friction: FrictionLaw | None = None

    def tested(self, mode: str) -> PoseTask:
        """The task with the directions an ``approach`` mode tests: the + ones (unidirectional) or all
        (bidirectional, random)."""
        if mode != "unidirectional":
            return self
        keep = [k for k, label in enumerate(self.labels) if label.startswith("+")]
        return replace(self, directions=self.directions[keep], labels=tuple(self.labels[k] for k in keep))


def joint_space_task(name: str, q: np.ndarray, normal_force_N: float | None = None,
                     friction: FrictionLaw | None = None) -> PoseTask:
    """A pose approached in joint space: every joint travelling + (or - for the second direction)."""
    return PoseTask(name, q, np.vstack([np.ones(len(q)), -np.ones(len(q))]), JOINT_SPACE_DIRECTIONS,
                    normal_force_N=normal_force_N, friction=friction)


def pose_tasks(study: Study, robot: Robot) -> tuple[list[PoseTask], dict | None]:
    """The study's joint-space poses, then the ISO cube's P1-P5 (solved by IK)."""
    tasks = [joint_space_task(p.name, robot.check_configuration(p.q, study.source, f"poses[{i}].q"),
                              p.normal_force_N,
                              None if p.friction is None else
                              law_from_spec(p.friction, study.source, f"poses[{i}].friction", study.base_dir))
             for i, p in enumerate(study.poses)]
    cube = None
    if study.iso_cube is not None:
        cube_poses, cube = place_cube(robot, study.iso_cube["center_m"], study.iso_cube["side_m"],
                                      study.iso_cube["rpy_deg"], study.source)
        tasks += [PoseTask(p.name, p.q, p.approach_signs, tuple(APPROACH_DIRECTIONS)) for p in cube_poses]
    return tasks, cube


def check_names(study: Study, tasks: list[PoseTask]) -> None:
    """Refuse names that cannot name what they name (:mod:`tribokin.names`), and poses (``tasks``: the study's
    poses, then the ISO cube's) or scenarios whose files would be the same (a clash with an ISO cube pose
    names the study's pose, the one to rename)."""
    check_name(study.name, study.source, "study.name")
    poses = [(f"poses[{i}].name", pose.name) for i, pose in enumerate(study.poses)]
    scenarios = [(f"scenarios[{i}].name", scenario.name) for i, scenario in enumerate(study.scenarios)]
    for key, name in poses + scenarios:
        check_file_name_part(name, study.source, key)
    cube = [("iso_cube", task.name) for task in tasks[len(study.poses):]]
    files = [(key, pose_figure_file(name)) for key, name in cube + poses]
    files += [(key, file) for key, name in scenarios[1:] for file in scenario_files(name)]  # [0]: the reference
    check_files_apart(files, study.source)


class PoseRunner:
    """Runs poses of one study: samples the cycles, propagates them, measures them."""

    def __init__(self, study: Study, robot: Robot, models: list[JointErrorModel]):
        self.study, self.robot, self.models = study, robot, models
        self.offsets = np.array([m.offset for m in models])
        self.loads = None
        if any(m.normal_force_N is None for m in models):
            self.loads = BearingLoads(robot, study.robot["payload_kg"], [m.bearing_span_m for m in models])
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

    def normal_forces_at(self, q: np.ndarray) -> np.ndarray:
        """Bearing loads [N] at configuration ``q`` (nq,) or configurations (poses, nq): each joint's
        fixed value, else statics; refused (:meth:`check_travel`) if they would move a joint beyond its range."""
        forces = self._loads_at(q)
        self.check_travel(forces, self.models)
        return forces

    def _loads_at(self, q: np.ndarray) -> np.ndarray:
        fixed = np.array([np.nan if m.normal_force_N is None else m.normal_force_N for m in self.models])
        if self.loads is None:
            return np.broadcast_to(fixed, np.shape(q)[:-1] + fixed.shape).copy()
        return np.where(np.isnan(fixed), self.loads(q), fixed)

    def check_travel(self, forces_N: np.ndarray, models: list[JointErrorModel]) -> None:
        """Refuse loads ``forces_N`` (..., nv) [N] under which a joint's deviation could exceed its range."""
        overrides = self.study.joint_overrides

        def key_of(joint: str, part: str) -> str:
            return f"joints.{joint}.{part}" if part in overrides.get(joint, {}) else f"joints.{part}"

        check_travel(models, self.robot.joint_is_prismatic, forces_N, self.travel, self.robot.joint_names,
                     self.study.source, key_of)

    def models_at(self, task: PoseTask) -> list[JointErrorModel]:
        """The joint error models at a pose: the study's, with the pose's friction law if it has one."""
        return self.models if task.friction is None else [replace(m, friction=task.friction) for m in self.models]

    def draw(self, task: PoseTask, forces_N, cycles: int, mode: str, rng):
        """Joint deviations of the cycles at one pose: (dq (n, nv) [m or rad], mu (n, nv), approach index (n,))."""
        signs, group = approach_signs(mode, cycles, task.directions, rng)
        dq, mu = sample_joint_deviations(self.models_at(task), self.robot.joint_is_prismatic, forces_N, signs, rng)
        return dq, mu, group

    def approach_sequence(self, task: PoseTask, rng) -> tuple[np.ndarray, np.ndarray]:
        """The joints' signs of travel (n, nv) and the approach index (n,) of every cycle at a pose:
        ``study.cycles`` from each direction, one series after another (unidirectional) or in turn
        (bidirectional); or as many cycles in all, each from a direction drawn at random (random)."""
        mode, count, cycles = self.study.approach, len(task.directions), self.study.cycles
        if mode == "unidirectional":
            group = np.repeat(np.arange(count), cycles)
            return task.directions[group].astype(float), group
        return approach_signs(mode, count * cycles, task.directions, rng)

    def measure(self, task: PoseTask, rng: np.random.Generator) -> PoseResult:
        """Sample the cycles of every approach direction the study's ``approach`` mode tests at ``task`` from
        ``rng`` and take their ISO 9283 figures."""
        task = task.tested(self.study.approach)
        forces = self.normal_forces(task)
        signs, group = self.approach_sequence(task, rng)
        dq, mu = sample_joint_deviations(self.models_at(task), self.robot.joint_is_prismatic, forces, signs, rng)
        positions, angles = tool_deviations(self.robot, task.q, dq, self.study.engine)
        commanded = self.robot.tool_placement(task.q)
        metrics = directional_metrics(positions, angles, commanded.translation, group, task.labels)
        reference = self.robot.tool_placement(task.q + self.offsets)
        return PoseResult(task.name, task.q, commanded.translation.copy(), commanded.rotation.copy(),
                          reference.translation.copy(), positions, angles, task.labels, group, mu, dq, forces,
                          metrics)

    def run(self, task: PoseTask, index: int) -> PoseResult:
        """Measure pose ``index`` (ISO 9283 per approach direction and across them, and beyond)."""
        result = self.measure(task, pose_rng(self.study.seed, index))
        if task.friction is not None:
            result.extra["friction"] = task.friction.describe()
        result.direction_extra = self.beyond_iso(task, result.normal_forces_N, result, index)
        if self.study.engine == "fast":
            check = max_deviation_from_exact(self.robot, task.q, result.dq)
            result.extra["engine_check_cycles"] = check.samples
            result.extra["engine_max_deviation_nm"] = check.position_m * 1e9
            result.extra["engine_max_angle_deviation_nrad"] = check.angle_rad * 1e9
        return result

    def beyond_iso(self, task: PoseTask, forces_N, result: PoseResult, index: int) -> dict[str, dict]:
        """Per approach direction with ISO figures: joint shares of the position variance, 1-sigma
        ellipsoid semi-axes [µm], 95 % interval of RP_l [µm].

        The interval comes from replicate tests of ``study.cycles`` cycles each from that direction
        (fresh random streams), propagated to first order through the position Jacobian: how much
        a test of this length can vary.
        """
        jacobian = self.robot.tool_jacobian(task.q)[:3]
        cycles = self.study.cycles
        replicates = int(np.clip(REPLICATE_SAMPLES // cycles, 20, RP_REPLICATES))
        rng = pose_rng(self.study.seed, index, stream=1)
        figures = {}
        for label in result.metrics.directions:
            mine = result.approach == result.directions.index(label)
            shares = variance_contributions(jacobian, result.dq[mine])
            extra = {f"contribution_{name}": None if np.isnan(share) else float(share)
                     for name, share in zip(self.robot.joint_names, shares)}
            extra["ellipsoid_semi_axes_um"] = (covariance_semi_axes(result.positions_m[mine]) * UM_PER_M).tolist()
            signs = np.broadcast_to(task.directions[task.labels.index(label)].astype(float), (cycles, len(task.q)))
            rp = np.empty(replicates)
            for j in range(replicates):
                dq, _ = sample_joint_deviations(self.models_at(task), self.robot.joint_is_prismatic, forces_N, signs,
                                                rng)
                rp[j] = position_repeatability(dq @ jacobian.T)[0]
            extra["RP_l_95_um"] = (np.percentile(rp, [2.5, 97.5]) * UM_PER_M).tolist()
            figures[label] = extra
        return figures


def run_study(study, cycles: int | None = None, seed: int | None = None, *, workers: int = 1,
              scheduler: str | None = None, checkpoint=None, resume: bool = False,
              progress: bool = False) -> StudyResult:
    """Run a study from a TOML path, a mapping or a :class:`Study`.

    Args:
        study: the study; relative paths in a mapping resolve against the current folder.
        cycles, seed: override the file's values.
        workers, scheduler: where the map's chunks run: local processes, or a dask scheduler's address.
        checkpoint, resume: folder where the map's finished chunks are saved, and whether to reuse them.
        progress: show a progress bar for the map.

    Returns:
        the per-pose samples and ISO 9283 figures, and the map's per-target figures.
    """
    from tribokin.mapping import prepare_map, run_map  # mapping builds on this module

    check_executor(workers, scheduler)
    study = load_study(study, cycles, seed)
    if resume and study.map is None and checkpoint is not None and Path(checkpoint).exists():
        raise InputError("this study has no [map], so these chunks are another run's; run that study with "
                         "--resume, or pass --force without --resume to start over", checkpoint, "--resume")
    robot = load_robot(study)
    models = joint_models(study, robot)
    tasks, cube = pose_tasks(study, robot)
    check_names(study, tasks)
    check_memory(study, robot.model.nv, [len(t.tested(study.approach).labels) for t in tasks], workers,
                 cycles_from_command_line=cycles is not None)
    check_disk(study, robot.model.nv, tempfile.gettempdir() if checkpoint is None else checkpoint)
    prepared_map = None if study.map is None else prepare_map(study, robot)
    runner = PoseRunner(study, robot, models)
    for task in tasks:  # every pose's loads, checked before any is sampled
        runner.normal_forces(task)
    poses = [runner.run(task, index) for index, task in enumerate(tasks)]
    workspace_map = None
    if prepared_map is not None:
        workspace_map = run_map(study, robot, *prepared_map, workers, scheduler, checkpoint, resume, progress)
    settings = {
        "name": study.name,
        "source": study.source,
        "robot": robot.label,
        "robot_spec": robot_spec(study),
        "tool_frame": robot.tool_frame,
        "joints": robot.joint_names,
        "cycles": study.cycles,
        "seed": study.seed,
        "approach": study.approach,
        "engine": study.engine,
        "payload_kg": study.robot["payload_kg"],
        "iso_cube": cube,
        "friction": {name: m.friction.describe() for name, m in zip(robot.joint_names, models)},
        "joint_models": {name: {f.name: getattr(m, f.name) for f in fields(m) if f.name != "friction"}
                         for name, m in zip(robot.joint_names, models)},
        "scenarios": [{"name": s.name, "overrides": s.overrides} for s in study.scenarios],
    }
    reproduce = {"seed": study.seed, "study_sha256": study.sha256, "versions": software_versions(), "command": None}
    return StudyResult(study.name, poses, settings, robot, workspace_map, reproduce)
