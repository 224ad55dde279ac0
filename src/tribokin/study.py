"""Study file -> run -> results on disk.

``run_study`` takes a TOML path or a mapping and returns a
:class:`~tribokin.results.StudyResult`; ``write_results`` writes it to an
output folder atomically (a temporary folder renamed into place).
"""

from __future__ import annotations

import copy
import json
import os
import shutil
import sys
from pathlib import Path

import numpy as np

from tribokin.config import PoseSpec, Study, parse_study
from tribokin.errors import InputError, closest_hint
from tribokin.iso9283 import pose_metrics
from tribokin.joints import JointErrorModel, approach_signs, sample_joint_deviations
from tribokin.propagate import tool_deviations_exact
from tribokin.results import PoseResult, StudyResult
from tribokin.robot import Robot, load_example_robot, load_urdf
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
    try:
        mapping = tomllib.loads(path.read_text(encoding="utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as error:
        raise InputError(f"not valid TOML: {error}", path) from None
    return parse_study(mapping, str(path), path.parent)


def load_study(study, cycles: int | None = None, seed: int | None = None) -> Study:
    """A :class:`Study` from a path, a mapping or a Study, with ``cycles``/``seed`` overriding the file."""
    if isinstance(study, Study):
        study = copy.copy(study)
    elif isinstance(study, dict):
        study = parse_study(study, "<mapping>", Path.cwd())
    else:
        study = read_study_file(study)
    if cycles is not None:
        if isinstance(cycles, bool) or not isinstance(cycles, int) or cycles < 1:
            raise InputError(f"must be a whole number >= 1 (got {cycles!r})", "command line", "--cycles")
        study.cycles = cycles
    if seed is not None:
        if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
            raise InputError(f"must be a whole number >= 0 (got {seed!r})", "command line", "--seed")
        study.seed = seed
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


def normal_forces(models: list[JointErrorModel], pose: PoseSpec, study: Study) -> np.ndarray:
    """Bearing loads [N] of each joint at a pose: the pose's value, else each joint's."""
    if pose.normal_force_N is not None:
        return np.full(len(models), pose.normal_force_N)
    if any(m.normal_force_N is None for m in models):
        raise InputError("normal_force_N is required for every joint (or for the pose)", study.source,
                         "joints.normal_force_N")
    return np.array([m.normal_force_N for m in models])


def pose_rng(seed: int, index: int) -> np.random.Generator:
    """The random stream of pose ``index``: depends on the seed and the index only."""
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(index,)))


def run_pose(robot: Robot, models: list[JointErrorModel], name: str, q: np.ndarray, forces_N: np.ndarray,
             cycles: int, approach: str, rng: np.random.Generator) -> PoseResult:
    """Sample ``cycles`` cycles at configuration ``q`` and measure them."""
    nv = robot.model.nv
    directions = np.vstack([np.ones(nv), -np.ones(nv)])
    signs, group = approach_signs(approach, cycles, directions, rng)
    dq, mu = sample_joint_deviations(models, robot.joint_is_prismatic, forces_N, signs, rng)
    positions, angles = tool_deviations_exact(robot, q, dq)
    commanded = robot.tool_placement(q)
    reference = robot.tool_placement(q + np.array([m.offset for m in models]))
    metrics = pose_metrics(positions, angles, commanded.translation, None if approach == "unidirectional" else group)
    return PoseResult(name, q, commanded.translation.copy(), commanded.rotation.copy(),
                      reference.translation.copy(), positions, angles, group, mu, dq, forces_N, metrics)


def run_study(study, cycles: int | None = None, seed: int | None = None) -> StudyResult:
    """Run a study from a TOML path, a mapping or a :class:`Study`.

    Args:
        study: the study; relative paths in a mapping resolve against the current folder.
        cycles, seed: override the file's values.

    Returns:
        the per-pose samples and ISO 9283 figures.
    """
    study = load_study(study, cycles, seed)
    robot = load_robot(study)
    models = joint_models(study, robot)
    poses = []
    for index, pose in enumerate(study.poses):
        q = robot.check_configuration(pose.q, study.source, f"poses[{index}].q")
        forces = normal_forces(models, pose, study)
        poses.append(run_pose(robot, models, pose.name, q, forces, study.cycles, study.approach,
                              pose_rng(study.seed, index)))
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
        "friction": {name: m.friction.describe() for name, m in zip(robot.joint_names, models)},
    }
    return StudyResult(study.name, poses, settings, robot)
