"""Each map kind knows its grid: targets along each axis, their count, its rows, its chunks and its size key; an
expected map has directional figures unless `map.directional = false`, a placement search's maps none."""

import pytest

from conftest import axis_study
from tribokin.study.map_spec import BoxMap, JointMap, PlaneMap
from tribokin.study.reading import load_study

PLANE = {"kind": "plane", "origin_m": [0.0, 0.0, 0.0], "axis_u": [1.0, 0.0, 0.0], "axis_v": [0.0, 1.0, 0.0],
         "extent_u_m": [0.0, 0.4], "extent_v_m": [0.0, 0.3], "resolution": [25, 40]}
BOX = {"kind": "box", "min_m": [0.2, 0.0, 0.2], "max_m": [0.8, 0.6, 0.7], "resolution": [4, 3, 2]}
JOINT = {"kind": "joint", "joints": ["x"], "ranges": [[0.0, 0.3]], "counts": [7]}


# expected: the values of the helpers of maps/budget.py these replaced (grid_counts, map_target_count, grid_rows,
# chunk_targets, size_key, rows_per_chunk), worked out by hand
@pytest.mark.parametrize("table, kind, counts, targets, rows, chunk, key", [
    (PLANE, PlaneMap, (25, 40), 1000, 40, 250, "map.resolution"),  # MIN_CHUNKS (4) chunks of 10 rows of 25
    (BOX, BoxMap, (4, 3, 2), 24, 6, 8, "map.resolution"),  # 6 rows in 3 chunks of 2 (4 would leave one empty)
    (JOINT, JointMap, (7,), 7, 1, 7, "map.counts"),
    ({**PLANE, "chunk_rows": 3}, PlaneMap, (25, 40), 1000, 40, 75, "map.resolution"),
])
def test_a_map_kind_knows_its_targets_rows_chunks_and_size_key(table, kind, counts, targets, rows, chunk, key):
    spec = load_study({**axis_study(), "map": table}).map
    assert type(spec) is kind and spec.kind == table["kind"]
    assert (spec.counts, spec.target_count, spec.grid_rows, spec.chunk_targets, spec.size_key) == \
        (counts, targets, rows, chunk, key)
    assert spec.rows_per_chunk * counts[0] == chunk


@pytest.mark.parametrize("keys, figure_set", [
    ({}, "directional"),  # an expected map has its directional figures by default
    ({"directional": False}, "expected"),
    ({"directional": True}, "directional"),
    ({"statistic": "one-test"}, "one-test"),  # a one-test map has none, and is not refused for the default
])
def test_an_expected_map_has_directional_figures_unless_turned_off(keys, figure_set):
    spec = load_study({**axis_study(), "map": {**PLANE, **keys}}).map
    assert spec.figure_set == figure_set
    assert spec.directional == (figure_set == "directional")


def test_a_placement_search_maps_its_candidates_without_directional_figures():
    from tribokin.placement.search import placed_study
    from tribokin.study.placement_spec import Candidate

    study = load_study({**axis_study(), "map": PLANE})
    assert study.map.figure_set == "directional"
    placed = placed_study(study, Candidate(index=0, base_xyz_m=(0.1, 0.0, 0.0), yaw_deg=0.0))
    assert placed.map.figure_set == "expected" and placed.placement is None
