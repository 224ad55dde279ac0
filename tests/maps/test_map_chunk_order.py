"""Map runs: the order chunks are computed in, the progress they report, and what runs while they compute
(results: test_map_execution.py)."""

from conftest import GANTRY_MAP_TOML
from tribokin import run_study
from tribokin.execution import executor_for
from tribokin.maps.mapping import chunk_order
from tribokin.maps.store import ChunkStore

#: 1000 targets in 40 chunks of one row, cheap (closed form, no directional figures).
SMALL_MAP = GANTRY_MAP_TOML.replace("cycles = 400", "cycles = 5").replace("[map]", "[map]\ndirectional = false")


def test_chunks_run_spread_over_the_grid_so_the_first_are_a_fair_sample():
    assert chunk_order(16) == [0, 8, 4, 12, 2, 10, 6, 14, 1, 9, 5, 13, 3, 11, 7, 15]
    for count in (1, 2, 13, 34):
        order = chunk_order(count)
        assert sorted(order) == list(range(count))
        assert max(order[:4]) >= count * 3 // 4 or count < 4  # the first four reach the far quarter of the grid


def test_progress_reports_the_targets_done_before_and_as_each_chunk_finishes_resumed_ones_included(tmp_path):
    study = tmp_path / "study.toml"
    study.write_text(SMALL_MAP)
    calls = []
    run_study(study, checkpoint=tmp_path / "chunks", progress=lambda done, total: calls.append((done, total)))
    assert calls == [(25 * k, 1000) for k in range(41)]
    (tmp_path / "chunks" / "done" / "7").unlink()
    (tmp_path / "chunks" / "done" / "30").unlink()
    calls.clear()
    run_study(study, checkpoint=tmp_path / "chunks", resume=True, progress=lambda *call: calls.append(call))
    assert calls == [(950, 1000), (975, 1000), (1000, 1000)]


def test_a_map_of_one_chunk_reports_no_progress(tmp_path):
    study = tmp_path / "study.toml"
    study.write_text(SMALL_MAP.replace("chunk_rows = 1", "chunk_rows = 40"))
    calls = []
    assert run_study(study, progress=lambda *call: calls.append(call)).map.grid.size == 1000
    assert calls == []


def test_meanwhile_runs_once_after_the_chunks_are_handed_to_the_workers_and_before_a_result_is_read(tmp_path,
                                                                                                      monkeypatch):
    study = tmp_path / "study.toml"
    study.write_text(SMALL_MAP)
    events = []
    save = ChunkStore.save
    monkeypatch.setattr(ChunkStore, "save", lambda store, *args: events.append("saved") or save(store, *args))
    with executor_for(workers=2) as executor:
        run_study(study, executor=executor, checkpoint=tmp_path / "chunks",
                  progress=lambda *call: events.append("progress"), meanwhile=lambda: events.append("meanwhile"))
    assert events[:2] == ["progress", "meanwhile"] and events.count("meanwhile") == 1
    assert events.count("progress") == 41  # every chunk's result read after it
    assert "saved" not in events  # each saved in the store by its worker: no values came back through a pipe
    assert len(list((tmp_path / "chunks" / "done").iterdir())) == 40
