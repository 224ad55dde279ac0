"""Each map kind knows its grid: targets along each axis, their count, its rows, its chunks and its size key."""

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
