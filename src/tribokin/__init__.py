"""tribokin: friction-induced pose repeatability (ISO 9283) of robots.

Tribological statistics of each joint's friction -> joint lost motion ->
Pinocchio forward kinematics -> ISO 9283 figures, at any pose of any robot.
"""

from tribokin.errors import InputError
from tribokin.provenance import __version__
from tribokin.run import run_study
from tribokin.study.map_spec import BoxMap, JointMap, PlaneMap
from tribokin.study.reading import load_study
from tribokin.study.spec import IsoCubeSpec, JointSpec, PoseSpec, RobotSpec, ScenarioSpec, Study

__all__ = ["InputError", "load_study", "run_study", "__version__", "Study", "RobotSpec", "JointSpec", "PoseSpec",
           "IsoCubeSpec", "PlaneMap", "BoxMap", "JointMap", "ScenarioSpec"]
