"""tribokin: friction-induced pose repeatability (ISO 9283) of robots.

Tribological statistics of each joint's friction -> joint lost motion ->
Pinocchio forward kinematics -> ISO 9283 figures, at any pose of any robot.
"""

from importlib import metadata

from tribokin.errors import InputError
from tribokin.run import load_study, run_study

try:
    __version__ = metadata.version("tribokin")  # pyproject.toml's, as installed
except metadata.PackageNotFoundError:  # sources on the path, never installed
    __version__ = "unknown"
__all__ = ["InputError", "load_study", "run_study", "__version__"]
