"""tribokin: friction-induced pose repeatability (ISO 9283) of robots.

Tribological statistics of each joint's friction -> joint lost motion ->
Pinocchio forward kinematics -> ISO 9283 figures, at any pose of any robot.

What users touch: :func:`run_study` and :func:`load_study`, the :class:`Study` they read, the results
(:class:`StudyResult`, :class:`PoseResult`, :class:`MapResult`) and the errors, all subclasses of
:class:`TribokinError`.
"""

from tribokin.errors import (ConfigurationError, InputError, JointRangeError, LawError, RobotDescriptionError,
                             TribokinError)
from tribokin.maps.result import MapResult
from tribokin.provenance import __version__
from tribokin.run import StudyResult, run_study
from tribokin.simulation.pose_result import PoseResult
from tribokin.study.map_spec import BoxMap, JointMap, PlaneMap
from tribokin.study.reading import load_study
from tribokin.study.spec import IsoCubeSpec, JointSpec, PoseSpec, RobotSpec, ScenarioSpec, Study

__all__ = ["run_study", "load_study", "Study", "RobotSpec", "JointSpec", "PoseSpec", "IsoCubeSpec", "PlaneMap",
           "BoxMap", "JointMap", "ScenarioSpec", "StudyResult", "PoseResult", "MapResult", "TribokinError",
           "InputError", "ConfigurationError", "RobotDescriptionError", "LawError", "JointRangeError", "__version__"]
