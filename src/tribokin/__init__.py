"""tribokin: friction-induced pose repeatability (ISO 9283) of robots.

Tribological statistics of each joint's friction -> joint lost motion ->
Pinocchio forward kinematics -> ISO 9283 figures, at any pose of any robot.
"""

from tribokin.errors import InputError
from tribokin.study import load_study, run_study

__version__ = "0.1.0"
__all__ = ["InputError", "load_study", "run_study", "__version__"]
