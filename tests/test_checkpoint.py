"""The map store: columns written by chunks and read back by blocks, finished chunks marked, records atomic."""

import numpy as np
import pytest

from tribokin import InputError
from tribokin.checkpoint import ChunkStore

COLUMNS = {"q": ((2,), "f8"), "reachable": ((), "?")}


def test_columns_written_by_chunk_read_back_by_block_and_index(tmp_path):
    store = ChunkStore(tmp_path / "store", "key", COLUMNS, size=10)
    assert store.finished() == []
    store.save(1, 4, {"q": np.arange(12.0).reshape(6, 2), "reachable": np.ones(6, dtype=bool)})
    store.save(0, 0, {"q": np.full((4, 2), -1.0), "reachable": np.zeros(4, dtype=bool)})
    assert store.finished() == [0, 1]
    np.testing.assert_array_equal(store.read("q", slice(3, 6)), [[-1, -1], [0, 1], [2, 3]])
    np.testing.assert_array_equal(store.read("reachable", [0, 9]), [False, True])
    store.write(np.array([0, 9]), {"q": np.zeros((2, 2))})
    np.testing.assert_array_equal(store.read("q")[[0, 9]], np.zeros((2, 2)))
    assert store.read("q").shape == (10, 2) and not isinstance(store.read("q"), np.memmap)


def test_a_store_is_resumed_only_with_the_same_key_and_when_asked(tmp_path):
    folder = tmp_path / "store"
    ChunkStore(folder, "key", COLUMNS, size=3).save(0, 0, {"q": np.ones((3, 2)), "reachable": np.ones(3, bool)})
    with pytest.raises(InputError, match="--resume"):
        ChunkStore(folder, "key", COLUMNS, size=3)
    with pytest.raises(InputError, match="other settings"):
        ChunkStore(folder, "other", COLUMNS, size=3, resume=True)
    resumed = ChunkStore(folder, "key", COLUMNS, size=3, resume=True)
    assert resumed.finished() == [0]
    np.testing.assert_array_equal(resumed.read("q"), np.ones((3, 2)))


def test_records_are_kept_whole(tmp_path):
    store = ChunkStore(tmp_path / "store", "key", COLUMNS, size=3)
    assert store.load_record("filled") is None
    store.save_record("filled", {"index": np.array([2])})
    assert store.load_record("filled")["index"].tolist() == [2]
    assert sorted(p.name for p in (tmp_path / "store").glob("*filled*")) == ["filled.npz"]


def test_scattered_reads_in_file_pieces_return_values_in_the_order_asked(tmp_path, monkeypatch):
    monkeypatch.setattr("tribokin.checkpoint.READ_ROWS", 3)
    store = ChunkStore(tmp_path / "store", "key", COLUMNS, size=10)
    q = np.arange(20.0).reshape(10, 2)
    store.save(0, 0, {"q": q, "reachable": np.arange(10) % 3 == 0})
    for index in ([9, 0, 4, 4, 8, 1], [7], [], np.arange(10)[::-1]):
        np.testing.assert_array_equal(store.read("q", index), q[index])
    np.testing.assert_array_equal(store.read("reachable", [3, 1, 0]), [True, False, True])
    assert store.read("q", []).shape == (0, 2)
