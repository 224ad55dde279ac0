"""Map runs: the progress bar's ETA and the order chunks are computed in (results: test_map_execution.py)."""

import io

from tqdm import std as tqdm_std

from tribokin.maps.run import ETA_SAMPLES, ProgressBar, chunk_order


def test_eta_counts_only_the_chunks_after_each_workers_first(monkeypatch):
    now = [0.0]
    monkeypatch.setattr(tqdm_std, "time", lambda: now[0])  # the bar's clock
    bar = ProgressBar(total=1000, warm_up=2, file=io.StringIO(), mininterval=0)

    def chunk_done_at(time_s: float) -> str:
        now[0] = time_s
        bar.update(100)
        return tqdm_std.tqdm.format_meter(**bar.format_dict)

    assert "<?" in chunk_done_at(10.0)  # each worker's first chunk paid 10 s of start-up
    assert "<?" in chunk_done_at(10.5)  # the clock starts here
    for k in range(1, ETA_SAMPLES):
        assert "<?" in chunk_done_at(10.5 + k)
    shown = chunk_done_at(10.5 + ETA_SAMPLES)  # 100 targets/s since the start-up
    done, interval = 200 + 100 * ETA_SAMPLES, tqdm_std.tqdm.format_interval
    assert f"{done}/1000 [{interval(10.5 + ETA_SAMPLES)}<{interval((1000 - done) / 100)}, 100.00it/s]" in shown
    bar.close()


def test_chunks_run_spread_over_the_grid_so_the_first_are_a_fair_sample():
    assert chunk_order(16) == [0, 8, 4, 12, 2, 10, 6, 14, 1, 9, 5, 13, 3, 11, 7, 15]
    for count in (1, 2, 13, 34):
        order = chunk_order(count)
        assert sorted(order) == list(range(count))
        assert max(order[:4]) >= count * 3 // 4 or count < 4  # the first four reach the far quarter of the grid
