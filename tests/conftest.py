"""Shared fixtures: paths and small study mappings."""

from __future__ import annotations

import copy
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
AXIS_URDF = ROOT / "urdf" / "prismatic_axis.urdf"
STUDIES = ROOT / "studies"


def axis_study(**joints) -> dict:
    """A one-pose study of the prismatic axis; ``joints`` overrides the [joints] table."""
    return {
        "study": {"name": "axis", "cycles": 30, "seed": 1},
        "robot": {"urdf": str(AXIS_URDF), "tool_frame": "tool"},
        "joints": {"friction": {"law": "constant", "mu": 0.0}, "stiffness": 1.0e6, "normal_force_N": 100.0,
                   **joints},
        "poses": [{"name": "P1", "q": [0.2]}],
    }


@pytest.fixture
def axis_mapping():
    return copy.deepcopy(axis_study())
