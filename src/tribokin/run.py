"""A study's run: its poses, then its map or its placement search, into a :class:`StudyResult`."""

from __future__ import annotations

import math
import tempfile
from collections.abc import Callable
from concurrent.futures import Executor
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path

import numpy as np

from tribokin.compiled import kernels_used
from tribokin.errors import InputError
from tribokin.execution import local_workers
from tribokin.kinematics.robot import Robot
from tribokin.maps.budget import check_disk, check_memory
from tribokin.maps.mapping import prepare_map, run_map
from tribokin.maps.pose_expected import with_expected_figures
from tribokin.maps.result import MapResult
from tribokin.maps.schema import MapLayout, study_approaches
from tribokin.output.dispatch import result_figures, result_scene, write_folder
from tribokin.output.provenance import software_versions
from tribokin.placement.result import PlacementResult
from tribokin.placement.search import run_placement
from tribokin.simulation.drift import DriftTest, PoseDrift, with_drift
from tribokin.simulation.pose_result import PoseResult, pose_frame
from tribokin.simulation.pose_test import run_poses
from tribokin.study.assembly import (
    MapRobots,
    check_names,
    joint_models,
    load_robot,
    map_robots,
    pose_tasks,
    refuse_series,
    robot_spec,
    study_runner,
)
from tribokin.study.reading import load_study
from tribokin.study.spec import ScenarioSpec, Study, check_drift


@dataclass
class StudyResult:
    """Results of a whole study: ``poses`` in file order, the workspace ``map`` or, with ``[placement]``, the
    ``placement`` search over its task region (if any), and what produced them (``robot``, for views; ``reproduce``:
    seed, study file hash, versions, command line); with ``[drift]``, each pose's drift test along its span
    (``drifts``, in pose order: their figures, ``drift_<pose>.png``); the ``study`` run, as read (its keys typed:
    ``settings`` records them in ``summary.json``)."""

    name: str
    poses: list[PoseResult]
    settings: dict
    robot: Robot | None = field(default=None, repr=False)
    map: MapResult | None = None
    reproduce: dict = field(default_factory=dict)
    placement: PlacementResult | None = None
    drifts: tuple[PoseDrift, ...] = ()
    study: Study | None = field(default=None, repr=False)

    def display_configuration(self) -> np.ndarray:
        """Where to draw the robot [m or rad]: the first pose, else the first reachable map target,
        else the robot's reference posture."""
        if self.poses:
            return self.poses[0].q
        first = None if self.map is None else self.map.first_reachable_q()
        return self.robot.reference_q if first is None else first

    def pose(self, name: str) -> PoseResult:
        """The pose called ``name``."""
        return next(p for p in self.poses if p.name == name)

    def table(self) -> dict[str, np.ndarray]:
        """Figures per pose and approach direction as columns: ``{"direction": array([...]), "RP_l_um":
        array([...]), ...}`` (scalar figures only; :meth:`PoseResult.direction_rows`)."""
        rows = [row for p in self.poses for row in p.direction_rows()]
        if not rows:
            return {}
        return {key: np.array([r[key] if r[key] is not None else np.nan for r in rows])
                for key, value in rows[0].items() if value is None or isinstance(value, (int, float, str))}

    def to_pandas(self):
        """``poses.csv`` as a pandas DataFrame: one row per pose and approach direction, the same columns and numbers
        (units in the names: ``RP_l_um``, ``AP_a_mdeg``, ``q_<joint>``), NaN where the file's cell is empty (pandas:
        ``pip install 'tribokin[data]'``). The map's targets: ``result.map.to_pandas()``."""
        return pose_frame([row for p in self.poses for row in p.direction_rows()], self.settings["joints"])

    def write(self, folder, force: bool = False, *, report: str = "full", table_format: str = "csv",
              executor: Executor | None = None) -> Path:
        """Write the files ``tribokin run`` writes into ``folder``, the same bytes but for the command line that
        ``summary.json`` records (``None`` here): all at once, refused (:class:`~tribokin.errors.InputError`) if it
        exists, unless ``force``. ``report`` (``"full"``, ``"light"``, ``"none"``) and ``table_format`` (``"csv"``,
        ``"parquet"``) as the command's options; ``executor``: local workers that format the map's tables.

        Returns:
            the folder written.
        """
        return write_folder(self, folder, force, report=report, table_format=table_format,
                            executor=executor)  # output.writers.write_results

    def figures(self) -> dict:
        """The figures ``tribokin run`` writes as PNGs (placement, each pose's field and drift test, the map's) as
        matplotlib ``Figure`` objects, by file name in the report's order; each saved at 110 dpi is the file."""
        return result_figures(self)  # viz.contents.study_figures

    def _repr_html_(self) -> str | None:
        """A notebook's view: ``report.html``'s 3-D scene (robot, poses' clouds, map layers, ISO cube) inline (no
        server, offline); ``None`` (text) when the robot is not known."""
        return result_scene(self)  # viz.notebook.study_scene

    def summary(self) -> dict:
        """The content of ``summary.json``."""
        summary = {"study": self.settings, "reproduce": self.reproduce, "poses": [p.report_row() for p in self.poses]}
        if self.map is not None:
            summary["map"] = self.map.summary()
        if self.placement is not None:
            summary["placement"] = self.placement.summary()
        return summary


def scenario_settings(scenario: ScenarioSpec, robots: MapRobots, place: int) -> dict:
    """A scenario as ``summary.json`` records it: its name and overrides, and when it is measured with another robot
    than the study's (kinematics, base or tool), that robot: its label, spec, tool frame and joints."""
    settings = {"name": scenario.name, "overrides": scenario.overrides}
    if place:
        robot = robots.robots[place]
        settings.update({"robot": robot.label, "robot_spec": robot_spec(scenario.study).as_settings(),
                         "tool_frame": robot.tool_frame, "joints": robot.joint_names})
    return settings


def drift_test(study) -> DriftTest | None:
    """The study's ``[drift]`` as the poses' :class:`~tribokin.simulation.drift.DriftTest` (``None``: none), checked
    again with the study's cycles (a command line's ``--cycles`` may have changed them)."""
    if study.drift is None:
        return None
    check_drift(study.drift, study.cycles, study.cycle_time_s, True, study.source)
    span = math.floor(study.drift.duration_s / study.cycle_time_s * (1 + 1e-12))
    return DriftTest(span, study.drift.set_cycles or study.cycles, study.drift.start == "warm")


def model_settings(model) -> dict:
    """A joint error model as ``summary.json`` records it: its values but its friction law (recorded apart), its
    friction's time series (``series``) and ``travel_per_cycle`` only when given."""
    out = {}
    for f in fields(model):
        value = getattr(model, f.name)
        if f.name == "friction" or (f.name in ("series", "travel_per_cycle") and value is None):
            continue
        out[f.name] = asdict(value) if f.name == "series" else value
    return out


def run_study(study, cycles: int | None = None, seed: int | None = None, *, executor: Executor | None = None,
              checkpoint=None, resume: bool = False, progress: Callable[[int, int], None] | None = None,
              meshes: bool = True, meanwhile: Callable[[], None] | None = None) -> StudyResult:
    """Run a study from a TOML path, a mapping or a :class:`Study`.

    Args:
        study: the study; relative paths in a mapping resolve against the current folder.
        cycles: overrides the file's ``study.cycles``.
        seed: overrides the file's ``study.seed``.
        executor: where the map's chunks, or the placement's candidates, run (``None``: here; local processes or a dask
            cluster: :func:`~tribokin.execution.executor_for`).
        checkpoint: folder where the map's finished chunks (the placement's candidates) are saved.
        resume: reuse the chunks (candidates) already in ``checkpoint``.
        progress: called with the map's targets done and in all (:func:`~tribokin.maps.mapping.run_map`; a placement:
            the targets of the candidates done, :func:`~tribokin.placement.search.run_placement`).
        meshes: load the robot's meshes, to draw it in a report (every mesh of a URDF must then be found);
            ``False``: its kinematics only.
        meanwhile: called once, here, while the map's chunks run (:func:`~tribokin.maps.mapping.run_map`).

    Returns:
        the per-pose samples and ISO 9283 figures, and the map's per-target figures or the placement's per-candidate
        figures (the poses at the study's own base; with ``[placement]``, the map is the task region, not mapped at
        that base).
    """
    study = load_study(study, cycles, seed)
    kernels = kernels_used()  # TRIBOKIN_KERNELS checked before any work
    if not study.has_tests:
        raise InputError("nothing to run: the study has a [calibration] section only; fit it with `tribokin calibrate "
                         "STUDY --measurements FILE`, or add [[poses]], an [iso_cube] or a [map]",
                         study.source, "poses")
    if resume and study.map is None and checkpoint is not None and Path(checkpoint).exists():
        raise InputError("this study has no [map], so these chunks are another run's; run that study with "
                         "--resume, or pass --force without --resume to start over", checkpoint, "--resume")
    if study.placement is not None:
        refuse_series(study, "a placement search", "remove the key, or the study's [placement] to map its task "
                      "region with the robot where it stands")
    drift = drift_test(study)
    robot = load_robot(study, meshes)
    models = joint_models(study, robot)
    tasks, cube = pose_tasks(study, robot)
    check_names(study, tasks)
    robots = None if study.map is None else map_robots(study, robot)
    layout = None if robots is None else MapLayout.of(robots, study.map.figure_set, study_approaches(study),
                                                       study.map.compare is not None)
    check_memory(study, robot.model.nv, [len(t.tested(study.approach).labels) for t in tasks],
                 local_workers(executor), ("command line", "--cycles") if cycles is not None else None, layout=layout)
    check_disk(study, robot.model.nv, tempfile.gettempdir() if checkpoint is None or study.placement else checkpoint,
               layout)
    prepared_map = None if robots is None else prepare_map(study, robots)  # the map's keys checked at any base
    runner = study_runner(study, robot, models)
    poses = with_expected_figures(runner, tasks, run_poses(runner, tasks))
    drifts = ()
    if drift is not None:
        poses, drifts = with_drift(runner, tasks, poses, drift)
    workspace_map = placement = None
    if study.placement is not None:
        placement = run_placement(study, executor, checkpoint, resume, progress)
    elif prepared_map is not None:
        workspace_map = run_map(study, prepared_map, executor, checkpoint, resume, progress, meanwhile)
    settings = {
        "name": study.name,
        "source": study.source,
        "robot": robot.label,
        "robot_spec": robot_spec(study).as_settings(),
        "tool_frame": robot.tool_frame,
        "joints": robot.joint_names,
        "cycles": study.cycles,
        "seed": study.seed,
        "approach": study.approach,
        "engine": study.engine,
        "payload_kg": study.robot.payload_kg,
        "iso_cube": cube,
        **({} if study.cycle_time_s is None else {"cycle_time_s": study.cycle_time_s}),
        **({} if drift is None else {"drift": asdict(drift)}),
        "friction": {name: m.friction.describe() for name, m in zip(robot.joint_names, models, strict=True)},
        "joint_models": {name: model_settings(m) for name, m in zip(robot.joint_names, models, strict=True)},
        "scenarios": [scenario_settings(s, robots, place)
                      for s, place in zip(study.scenarios, robots.places, strict=True)]
        if study.scenarios else [],
    }
    reproduce = {"seed": study.seed, "study_sha256": study.sha256, "versions": software_versions(),
                 "kernels": kernels, "command": None}
    return StudyResult(study.name, poses, settings, robot, workspace_map, reproduce, placement, drifts, study)
