"""The command's progress bar: its ETA leaves out the start-up, it follows the map's progress reports, and it says
first when numba compiles the kernels; the command's entry point."""

import gc
import io
import sys
from importlib.metadata import entry_points

from tqdm import std as tqdm_std

from tribokin.cli import COMPILING, ETA_SAMPLES, ProgressBar, entry, map_progress


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


def test_a_map_done_before_the_eta_has_its_samples_ends_on_its_whole_run_s_rate(monkeypatch):
    now = [0.0]
    monkeypatch.setattr(tqdm_std, "time", lambda: now[0])
    bar = ProgressBar(total=300, warm_up=2, file=io.StringIO(), mininterval=0)
    shown = []
    for time_s in (4.0, 5.0, 6.0):  # three chunks: fewer than the warm-up and the ETA's samples
        now[0] = time_s
        bar.update(100)
        shown.append(tqdm_std.tqdm.format_meter(**bar.format_dict))
    assert "?it/s" in shown[0] and "?it/s" in shown[1]
    assert "300/300 [00:06<00:00, 50.00it/s]" in shown[2]  # 300 targets in 6 s, not "?" to the end
    bar.close()


def test_map_progress_starts_the_bar_at_the_resumed_targets_and_moves_it_by_each_report(capsys):
    with map_progress(warm_up=1) as report:
        report(250, 1000)  # a resumed run: a quarter was done
        report(275, 1000)
        report(325, 1000)
    first, *_, last = capsys.readouterr().err.split("\r")[1:]
    assert first.startswith("map:") and "| 250/1000 [" in first
    assert "| 325/1000 [" in last and last.endswith("\n")  # closed with the block


def test_no_report_no_bar(capsys):
    with map_progress(warm_up=2):
        pass
    assert capsys.readouterr().err == ""


def test_a_run_that_compiles_its_kernels_says_so_once_before_the_bar(capsys):
    with map_progress(warm_up=1, compiling=True) as report:
        report(0, 1000)
        report(500, 1000)
    error = capsys.readouterr().err
    assert error.startswith(COMPILING + "\n") and error.count(COMPILING) == 1 and "| 500/1000 [" in error


def test_one_that_does_not_says_nothing_of_it(capsys):
    with map_progress(warm_up=1) as report:
        report(0, 1000)
    assert "numba" not in capsys.readouterr().err


def test_the_command_returns_mains_status_with_what_main_left_frozen(monkeypatch, capsys):
    assert entry_points(group="console_scripts")["tribokin"].value == "tribokin.cli:entry"
    monkeypatch.setattr(sys, "argv", ["tribokin"])  # no command: the help, status 2
    try:
        assert entry() == 2 and gc.get_freeze_count() > 0
    finally:
        gc.unfreeze()
    assert "usage: tribokin" in capsys.readouterr().err
