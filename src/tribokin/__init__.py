"""tribokin: friction-induced pose repeatability (ISO 9283) of robots.

Tribological statistics of each joint's friction -> joint lost motion ->
Pinocchio forward kinematics -> ISO 9283 figures, at any pose of any robot.

What users touch: :func:`run_study` and :func:`load_study`, the :class:`Study` they read, the results
(:class:`StudyResult`, :class:`PoseResult`, :class:`MapResult`) and the errors, all subclasses of
:class:`TribokinError`; without a study file, the library under it: a :class:`Robot` (``Robot.from_pinocchio``,
``from_urdf``, ``from_example_robot_data``), its :func:`joint_models` and friction laws (:class:`Gaussian`...,
:func:`preset`), a pose's ISO test (:func:`pose_test`) and a workspace map (:func:`workspace_map`, its
:class:`MapScenario`); measured data: a measurement file's ISO figures (:func:`measure`), a study fitted to it
(:func:`calibrate`), both in the measuring frame kept, registered by a best fit or turned by a :class:`Transform`,
friction laws fitted to a tribometer log (:func:`fit_friction`) and a surface profile's asperities
(:func:`analyse_surface`), each a frozen result that writes its command's folder. The errors and
``__version__`` load with the package; the rest on first use (PEP 562), so ``tribokin --version`` and a refused
command line do not import the physics chain.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

from tribokin.errors import (
    ConfigurationError,
    InputError,
    JointModelError,
    JointRangeError,
    LawError,
    RobotDescriptionError,
    SettingsError,
    TribokinError,
)
from tribokin.output.dispatch import registered_by as _registered_by
from tribokin.output.provenance import __version__

if TYPE_CHECKING:
    from tribokin.kinematics.robot import Robot
    from tribokin.maps.grid import GridError
    from tribokin.maps.mapping import MapScenario, workspace_map
    from tribokin.maps.pose_expected import pose_test
    from tribokin.maps.result import MapResult
    from tribokin.measured.calibrated import CalibrationResult, calibrate
    from tribokin.measured.iso_figures import MeasurementResult, Segmenting, measure
    from tribokin.measurement.registration import RegistrationWarning, Transform
    from tribokin.run import StudyResult, run_study
    from tribokin.simulation.joint_errors import JointErrorModel, joint_models
    from tribokin.simulation.pose_result import PoseResult
    from tribokin.simulation.pose_test import TestSettings
    from tribokin.study.map_spec import BoxMap, JointMap, PlaneMap
    from tribokin.study.reading import load_study
    from tribokin.study.spec import IsoCubeSpec, JointSpec, PoseSpec, RobotSpec, ScenarioSpec, Study
    from tribokin.tribology.friction_fit import FrictionFitResult, fit_friction
    from tribokin.tribology.laws import Constant, Empirical, FrictionLaw, Gaussian, Lognormal, Uniform
    from tribokin.tribology.presets import preset
    from tribokin.tribology.surface_result import SurfaceResult, analyse_surface

#: Where each name loaded on first use lives.
_LAZY = {"MapResult": "tribokin.maps.result", "StudyResult": "tribokin.run", "run_study": "tribokin.run",
         "PoseResult": "tribokin.simulation.pose_result", "BoxMap": "tribokin.study.map_spec",
         "JointMap": "tribokin.study.map_spec", "PlaneMap": "tribokin.study.map_spec",
         "load_study": "tribokin.study.reading", "IsoCubeSpec": "tribokin.study.spec",
         "JointSpec": "tribokin.study.spec", "PoseSpec": "tribokin.study.spec", "RobotSpec": "tribokin.study.spec",
         "ScenarioSpec": "tribokin.study.spec", "Study": "tribokin.study.spec",
         "Robot": "tribokin.kinematics.robot",
         "MapScenario": "tribokin.maps.mapping", "workspace_map": "tribokin.maps.mapping",
         "JointErrorModel": "tribokin.simulation.joint_errors", "joint_models": "tribokin.simulation.joint_errors",
         "TestSettings": "tribokin.simulation.pose_test", "pose_test": "tribokin.maps.pose_expected",
         "FrictionLaw": "tribokin.tribology.laws", "Constant": "tribokin.tribology.laws",
         "Uniform": "tribokin.tribology.laws", "Gaussian": "tribokin.tribology.laws",
         "Lognormal": "tribokin.tribology.laws", "Empirical": "tribokin.tribology.laws",
         "preset": "tribokin.tribology.presets", "GridError": "tribokin.maps.grid",
         "measure": "tribokin.measured.iso_figures", "MeasurementResult": "tribokin.measured.iso_figures",
         "Segmenting": "tribokin.measured.iso_figures", "calibrate": "tribokin.measured.calibrated",
         "Transform": "tribokin.measurement.registration", "RegistrationWarning": "tribokin.measurement.registration",
         "CalibrationResult": "tribokin.measured.calibrated", "fit_friction": "tribokin.tribology.friction_fit",
         "FrictionFitResult": "tribokin.tribology.friction_fit", "analyse_surface": "tribokin.tribology.surface_result",
         "SurfaceResult": "tribokin.tribology.surface_result"}

__all__ = ["run_study", "load_study", "Study", "RobotSpec", "JointSpec", "PoseSpec", "IsoCubeSpec", "PlaneMap",
           "BoxMap", "JointMap", "ScenarioSpec", "StudyResult", "PoseResult", "MapResult", "Robot", "joint_models",
           "JointErrorModel", "TestSettings", "pose_test", "workspace_map", "MapScenario", "FrictionLaw", "Constant",
           "Uniform", "Gaussian", "Lognormal", "Empirical", "preset", "TribokinError", "InputError",
           "ConfigurationError", "RobotDescriptionError", "LawError", "JointRangeError", "SettingsError",
           "JointModelError", "GridError", "measure", "MeasurementResult", "Segmenting", "Transform",
           "RegistrationWarning", "calibrate",
           "CalibrationResult", "fit_friction", "FrictionFitResult", "analyse_surface", "SurfaceResult", "__version__"]


# The modules that register the results' folder writers, figures and scenes (each result's ``write``, ``figures``,
# ``_repr_html_``) in :mod:`tribokin.output.dispatch`, imported when first used, in turn (the writers first, each
# lighter than the next) until the result's type is registered.
@_registered_by
def _tribology_writers() -> None:
    import tribokin.output.tribology  # noqa: F401 - FrictionFitResult, SurfaceResult


@_registered_by
def _study_writer() -> None:
    import tribokin.output.writers  # noqa: F401 - StudyResult


@_registered_by
def _measured_writers() -> None:
    import tribokin.output.measured  # noqa: F401 - MeasurementResult, CalibrationResult


@_registered_by
def _study_figures() -> None:
    import tribokin.viz.contents  # noqa: F401 - StudyResult.figures


@_registered_by
def _notebook_views() -> None:
    import tribokin.viz.notebook  # noqa: F401 - PoseResult, MapResult, StudyResult._repr_html_


def __getattr__(name: str):
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'tribokin' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
