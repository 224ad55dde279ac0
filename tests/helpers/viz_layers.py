"""Synthetic map layers, a test cube and a small study for the viewer tests."""

from __future__ import annotations

import numpy as np

from conftest import axis_study
from tribokin.viz.scene import Cube, MapLayer


def grid_layers() -> dict[str, MapLayer]:
    """Two scenarios on a 7 x 5 grid beside the prismatic axis; the first target unreachable (NaN)."""
    grid = np.stack(np.meshgrid(np.linspace(0.3, 0.9, 7), np.linspace(-0.3, 0.3, 5), [0.0]), -1).reshape(-1, 3)
    baseline = 2.0 + 10.0 * (grid[:, 0] - 0.3)
    baseline[0] = np.nan
    return {"baseline": MapLayer(grid, baseline, "baseline"),
            "treated": MapLayer(grid + [0, 0, 0.15], 0.5 * baseline, "treated")}


CUBE = Cube((0.6, 0.0, 0.1), 0.3)

UNIFORM_AXIS = axis_study(friction={"law": "uniform", "low": 0.09, "high": 0.16})
