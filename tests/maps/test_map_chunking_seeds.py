"""Maps: the same seed gives the same numbers whatever the chunking (rows per chunk)."""

import copy

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import ROOT
from tribokin import run_study

MAP = {
    "study": {"cycles": 8, "seed": 4},
    "robot": {"urdf": str(ROOT / "urdf" / "cartesian_xyz.urdf"), "tool_frame": "tool", "payload_kg": 3.0},
    "joints": {"friction": {"law": "uniform", "low": 0.09, "high": 0.16}, "stiffness": 2e7},
    # reaches past the x travel: some targets are unreachable
    "map": {"kind": "plane", "origin_m": [0.2, 0.0, 0.4], "axis_u": [1, 0, 0], "axis_v": [0, 1, 0],
            "extent_u_m": [0.0, 0.9], "extent_v_m": [0.0, 0.6], "resolution": [4, 5]},
}


@pytest.fixture(scope="module")
def one_chunk():
    return run_study(MAP).map


@settings(max_examples=5)
@given(st.integers(1, 5))
def test_chunking_changes_no_number(one_chunk, rows):
    study = copy.deepcopy(MAP)
    study["map"]["chunk_rows"] = rows
    chunked = run_study(study).map
    assert 0 < chunked.reachable.sum() < 20
    np.testing.assert_array_equal(chunked.reachable, one_chunk.reachable)
    np.testing.assert_array_equal(chunked.q, one_chunk.q)
    np.testing.assert_array_equal(chunked.reference.figures, one_chunk.reference.figures)
    np.testing.assert_array_equal(chunked.reference.normal_forces_N, one_chunk.reference.normal_forces_N)
