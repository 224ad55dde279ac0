"""A measurement file written from rows, and a study calibrating the gantry, for the measurement tests."""

from __future__ import annotations

from pathlib import Path

from conftest import ROOT

#: The gantry with a [calibration] of its stiffness (the noise floor given).
GANTRY_CALIBRATE = f"""[study]
name = "gantry-calibrate"
cycles = 5

[robot]
urdf = "{ROOT / 'urdf' / 'cartesian_xyz.urdf'}"
tool_frame = "tool"

[joints]
stiffness = 2.0e6
friction_force_N = {{ law = "gaussian", mean = 20.0, std = 5.0 }}

[calibration]
fit = ["stiffness"]
noise_floor_m = 1e-6
"""


def write_csv(folder: Path, header: str, rows: list[str], name: str = "tracker.csv",
              comments: tuple[str, ...] = ("# synthetic tracker data",)) -> Path:
    """``folder/name`` holding the comment lines, the header and the rows."""
    path = folder / name
    path.write_text("\n".join([*comments, header, *rows]) + "\n", encoding="utf-8")
    return path
