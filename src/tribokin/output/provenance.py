"""What produced a result: the versions of tribokin, Python and the libraries that shape the numbers."""

from __future__ import annotations

import platform
from importlib import metadata

try:
    __version__ = metadata.version("tribokin")  # pyproject.toml's, as installed
except metadata.PackageNotFoundError:  # sources on the path, never installed
    __version__ = "unknown"

#: What ``summary.json`` records the versions of (``reproduce.versions``), besides Python and tribokin:
#: name in the summary -> distribution.
RECORDED_DISTRIBUTIONS = {"numpy": "numpy", "scipy": "scipy", "pinocchio": "pin",
                          "example-robot-data": "example-robot-data"}


def software_versions() -> dict[str, str | None]:
    """Versions of Python, tribokin and ``RECORDED_DISTRIBUTIONS`` (``None``: not installed)."""
    versions = {"tribokin": __version__, "python": platform.python_version()}
    for name, distribution in RECORDED_DISTRIBUTIONS.items():
        try:
            versions[name] = metadata.version(distribution)
        except metadata.PackageNotFoundError:
            versions[name] = None
    return versions
