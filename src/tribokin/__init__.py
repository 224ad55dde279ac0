"""tribokin: friction-induced pose repeatability (ISO 9283) of robots.

Tribological statistics of each joint's friction -> joint lost motion ->
Pinocchio forward kinematics -> ISO 9283 figures, at any pose of any robot.

What users touch: :func:`run_study` and :func:`load_study`, the :class:`Study` they read, the results
(:class:`StudyResult`, :class:`PoseResult`, :class:`MapResult`) and the errors, all subclasses of
:class:`TribokinError`. The errors and ``__version__`` load with the package; the rest on first use (PEP 562), so
``tribokin --version`` and a refused command line do not import the physics chain.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING

from tribokin.errors import (ConfigurationError, InputError, JointRangeError, LawError, RobotDescriptionError,
                             TribokinError)
from tribokin.provenance import __version__

if TYPE_CHECKING:
    from tribokin.maps.result import MapResult
    from tribokin.run import StudyResult, run_study
    from tribokin.simulation.pose_result import PoseResult
    from tribokin.study.map_spec import BoxMap, JointMap, PlaneMap
    from tribokin.study.reading import load_study
    from tribokin.study.spec import IsoCubeSpec, JointSpec, PoseSpec, RobotSpec, ScenarioSpec, Study

#: Where each name loaded on first use lives.
_LAZY = {"MapResult": "tribokin.maps.result", "StudyResult": "tribokin.run", "run_study": "tribokin.run",
         "PoseResult": "tribokin.simulation.pose_result", "BoxMap": "tribokin.study.map_spec",
         "JointMap": "tribokin.study.map_spec", "PlaneMap": "tribokin.study.map_spec",
         "load_study": "tribokin.study.reading", "IsoCubeSpec": "tribokin.study.spec",
         "JointSpec": "tribokin.study.spec", "PoseSpec": "tribokin.study.spec", "RobotSpec": "tribokin.study.spec",
         "ScenarioSpec": "tribokin.study.spec", "Study": "tribokin.study.spec"}

__all__ = ["run_study", "load_study", "Study", "RobotSpec", "JointSpec", "PoseSpec", "IsoCubeSpec", "PlaneMap",
           "BoxMap", "JointMap", "ScenarioSpec", "StudyResult", "PoseResult", "MapResult", "TribokinError",
           "InputError", "ConfigurationError", "RobotDescriptionError", "LawError", "JointRangeError", "__version__"]


def __getattr__(name: str):
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'tribokin' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
