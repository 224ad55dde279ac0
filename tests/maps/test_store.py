"""The map store: columns written by chunks and read back by blocks, finished chunks marked, records atomic."""

import errno
import gc
import os
import shutil
import signal
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest

from conftest import killed_after
from tribokin import InputError
from tribokin.maps.store import ChunkStore, discard, remove_stale_stores, temporary_store

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


@pytest.mark.parametrize("pread_targets", [0, 64])
def test_scattered_reads_in_file_pieces_return_values_in_the_order_asked(tmp_path, monkeypatch, pread_targets):
    """Memory-mapped in pieces of READ_ROWS rows, or one pread per target."""
    monkeypatch.setattr("tribokin.maps.store.READ_ROWS", 3)
    monkeypatch.setattr("tribokin.maps.store.PREAD_TARGETS", pread_targets)
    store = ChunkStore(tmp_path / "store", "key", COLUMNS, size=10)
    q = np.arange(20.0).reshape(10, 2)
    store.save(0, 0, {"q": q, "reachable": np.arange(10) % 3 == 0})
    for index in ([9, 0, 4, 4, 8, 1], [7], [], np.arange(10)[::-1]):
        np.testing.assert_array_equal(store.read("q", index), q[index])
    np.testing.assert_array_equal(store.read("reachable", [3, 1, 0]), [True, False, True])
    assert store.read("q", []).shape == (0, 2)
    np.testing.assert_array_equal(store.read("q", 7), q[7])
    assert store.read("reachable", np.int64(3)).shape == () and store.read("reachable", 3)
    np.testing.assert_array_equal(store.read("q", [-1, -10]), q[[-1, -10]])
    for index in ([9, 0, 4, 4, 8, 1], [7], [], slice(2, 9), 7, [-1, -10]):  # one element of each target's value
        np.testing.assert_array_equal(store.read("q", index, item=1), q[index, 1])
    for outside in ([10], [-11], 10):
        with pytest.raises(IndexError):
            store.read("q", outside)


def _saved_store(folder):
    store = ChunkStore(folder, "key", COLUMNS, size=3)
    store.save(0, 0, {"q": np.ones((3, 2)), "reachable": np.ones(3, bool)})
    return store


def test_a_store_killed_while_created_is_absent_and_resume_starts_afresh(tmp_path):
    """Killed after its first column, before manifest.json: the next --resume must not see "other settings"."""
    folder = tmp_path / "store"
    assert killed_after(1, ("tribokin.maps.store.open_memmap",), lambda: ChunkStore(folder, "key", COLUMNS, 3))
    assert not folder.exists()  # only a temporary folder beside it
    assert ChunkStore(folder, "key", COLUMNS, size=3, resume=True).finished() == []
    assert sorted(tmp_path.iterdir()) == [folder]  # the killed run's temporary folder is cleared


def test_a_store_killed_while_deleted_is_whole_or_gone(tmp_path):
    """Killed half-way through deleting it (after its first file): resuming it must not meet missing files."""
    folder = tmp_path / "store"
    _saved_store(folder)
    assert killed_after(1, ("os.unlink",), lambda: discard(folder))
    assert not folder.exists()
    assert ChunkStore(folder, "key", COLUMNS, size=3, resume=True).finished() == []
    assert sorted(tmp_path.iterdir()) == [folder]


@pytest.mark.parametrize("lost", ["manifest.json", "q.npy", "done"])
def test_a_damaged_store_is_refused_on_resume_with_a_way_on(tmp_path, lost):
    folder = tmp_path / "store"
    _saved_store(folder)
    path = folder / lost
    shutil.rmtree(path) if path.is_dir() else path.unlink()
    with pytest.raises(InputError, match=f"lacks {lost} .*--force without --resume"):
        ChunkStore(folder, "key", COLUMNS, size=3, resume=True)


def test_a_store_deleted_while_in_use_is_an_input_error(tmp_path):
    folder = tmp_path / "store"
    store = _saved_store(folder)
    shutil.rmtree(folder)
    for use in (store.finished, lambda: store.read("q"), lambda: store.save_record("filled", {"i": np.ones(1)}),
                lambda: store.save(0, 0, {"q": np.ones((3, 2))})):
        with pytest.raises(InputError, match="deleted or damaged"):
            use()


def test_a_store_reserves_its_disk_space_and_a_full_disk_is_refused_before_writing(tmp_path, monkeypatch):
    """Writing through a memory map onto a full disk kills the process (SIGBUS): the space is taken up front."""
    store = ChunkStore(tmp_path / "store", "key", {"q": ((1000,), "f8")}, size=100)
    column = os.stat(store.folder / "q.npy")
    assert column.st_blocks * 512 >= column.st_size > 800_000  # allocated, not sparse

    def full(fd, offset, length):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "posix_fallocate", full)
    with pytest.raises(InputError, match="disk is full .* needed about 0.76 MiB for the map's store"):
        ChunkStore(tmp_path / "other", "key", {"q": ((1000,), "f8")}, size=100)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["store"]


def test_a_temporary_store_lives_under_tmpdir_and_is_deleted_with_the_store(tmp_path, monkeypatch):
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    store = temporary_store("key", {"q": ((2,), "f8")}, 3)
    store.save(0, 0, {"q": np.ones((3, 2))})
    assert store.folder.parent.parent == tmp_path and store.read("q").sum() == 6
    del store
    gc.collect()
    assert list(tmp_path.iterdir()) == []


#: A map run (``run_study``, no checkpoint: a temporary store) that prints its store's folder once its first chunk is
#: saved, then waits there: killed, it leaves that folder behind.
MID_MAP = """
import sys, time
from tribokin.maps import store
from tribokin.run import run_study
saved = store.ChunkStore.save
def save(self, *args):
    saved(self, *args)
    print(self.folder.parent, flush=True)
    time.sleep(600)
store.ChunkStore.save = save
run_study(sys.argv[1], meshes=False)
"""


def test_the_next_temporary_store_removes_a_killed_run_s_and_never_a_live_one(tmp_path, monkeypatch):
    """Two map runs stopped mid-map, one SIGKILLed: the next temporary store removes the killed run's folder, keeps
    the live run's (locked by it, its process id inside), a folder without an owner file and a symbolic link."""
    from conftest import GANTRY_MAP_TOML

    temporary = tmp_path / "tmp"
    (temporary / "tribokin-map-older").mkdir(parents=True)  # no owner file: an earlier tribokin's, or being made
    (tmp_path / "elsewhere").mkdir()
    (tmp_path / "elsewhere" / "owner.lock").write_text("1\n")
    (temporary / "tribokin-map-link").symlink_to(tmp_path / "elsewhere")
    study = tmp_path / "map.toml"
    study.write_text(GANTRY_MAP_TOML.replace("cycles = 400", "cycles = 5").replace("[25, 40]", "[3, 2]"))
    runs = [subprocess.Popen([sys.executable, "-c", MID_MAP, str(study)], stdout=subprocess.PIPE, text=True,
                             env={**os.environ, "TMPDIR": str(temporary)}) for _ in range(2)]
    try:
        killed, live = (Path(run.stdout.readline().strip()) for run in runs)
        assert killed.parent == temporary and live.parent == temporary
        runs[0].send_signal(signal.SIGKILL)
        runs[0].wait()
        assert (killed / "store" / "manifest.json").is_file()  # left behind
        monkeypatch.setattr(tempfile, "tempdir", str(temporary))
        store = temporary_store("key", {"q": ((2,), "f8")}, 3)
        assert not killed.exists()
        assert (live / "store" / "manifest.json").is_file() and (live / "owner.lock").read_text() == f"{runs[1].pid}\n"
        assert sorted(p.name for p in temporary.iterdir()) == sorted(
            ["tribokin-map-older", "tribokin-map-link", live.name, store.folder.parent.name])
        assert (tmp_path / "elsewhere" / "owner.lock").is_file()
        runs[1].send_signal(signal.SIGKILL)
        runs[1].wait()
        assert remove_stale_stores(temporary) == [live]  # not this process's own store
        assert store.folder.is_dir()
    finally:
        for run in runs:
            run.kill()
            run.wait()
