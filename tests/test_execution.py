"""Where chunks run: one executor, checked and built once, shut down with its block (results: test_map_execution.py)."""

import os
import signal
import subprocess
import sys
import threading
import time
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor, process

import pytest

from tribokin import InputError
from tribokin.execution import executor_for, local_workers, run_chunks


def test_one_worker_runs_here_in_key_order_and_a_pool_is_shut_down_with_its_block():
    with executor_for() as here:
        assert here is None and local_workers(here) == 1
        with run_chunks(pow, {"b": (2, 3), "a": (3, 2)}, here) as results:
            assert list(results) == [("b", 8), ("a", 9)]
    with executor_for(workers=2) as pool:
        assert isinstance(pool, ProcessPoolExecutor) and local_workers(pool) == 2
        with run_chunks(pow, {k: (k, 2) for k in range(5)}, pool) as results:
            assert dict(results) == {k: k * k for k in range(5)}
    with pytest.raises(RuntimeError):
        pool.submit(pow, 2, 2)


#: Run in a fresh interpreter: a pool is forked only from a process without other threads, which a test session's
#: earlier tests may have left.
FROZEN_POOL = """
import gc
from tribokin.execution import executor_for, run_chunks

def frozen(_):
    return gc.get_freeze_count()

if __name__ == "__main__":
    before = gc.get_freeze_count()
    with executor_for(workers=2) as pool:
        start, made = pool._mp_context.get_start_method(), gc.get_freeze_count()
        with run_chunks(frozen, {k: (k,) for k in range(2)}, pool) as results:
            during = gc.get_freeze_count()
            workers = sorted(count for _, count in results)
    print(start, before, made, during, *workers, gc.get_freeze_count())
"""


def test_a_forked_pool_has_what_its_parent_had_frozen_for_its_life(tmp_path):
    """The gc module's advice for workers forked without exec: their collections (and the parent's while they run)
    do not walk what was there when the first chunk was submitted (the fork), frozen then here and there."""
    script = tmp_path / "frozen_pool.py"
    script.write_text(FROZEN_POOL)
    start, before, made, during, *workers, after = subprocess.run(
        [sys.executable, script], capture_output=True, text=True, check=True).stdout.split()
    assert start == "fork" and int(before) == int(made) == 0 and int(during) > 0 and int(after) == 0
    assert all(int(count) > int(during) for count in workers)  # inherited, and what came since frozen there too


def test_workers_are_checked_before_anything_is_built():
    with pytest.raises(InputError, match=">= 1") as error:
        with executor_for(workers=0):
            pytest.fail("an executor was made")
    assert error.value.key == "--workers"


def test_chunks_not_started_when_the_block_ends_are_cancelled():
    started, running, release = [], threading.Event(), threading.Event()

    def chunk(key):
        started.append(key)
        running.set()
        release.wait(timeout=60)  # the timeouts bound a failing test only

    with ThreadPoolExecutor(1) as pool:
        try:
            with run_chunks(chunk, {k: (k,) for k in range(3)}, pool):
                running.wait(timeout=60)
        finally:
            release.set()
    assert started == [0]  # chunks 1 and 2 waited behind it on the pool's one thread


def test_a_pool_whose_worker_dies_after_its_chunks_were_left_ends_cleanly(monkeypatch):
    """Ctrl-C ends the workers while the command leaves the block: the chunks left are not cancelled from here before
    the pool learns that a worker died (on Python 3.11 its thread then stopped on ``InvalidStateError``, and the
    command hung at exit)."""
    errors = []
    monkeypatch.setattr(threading, "excepthook", errors.append)
    with executor_for(workers=2) as pool:
        with pytest.raises(KeyboardInterrupt):
            with run_chunks(time.sleep, {k: (30,) for k in range(10)}, pool):
                queued = 2 + process.EXTRA_QUEUED_CALLS  # the chunks the pool sends its workers' queue at once
                while sum(item.future.running() for item in pool._pending_work_items.values()) < queued:
                    time.sleep(0.01)
                workers, manager = list(pool._processes), pool._executor_manager_thread
                raise KeyboardInterrupt
        for pid in workers:  # after the block: what it left is decided before the pool learns of it
            os.kill(pid, signal.SIGKILL)
        manager.join(timeout=30)  # the pool's thread learns that they died, and ends
        assert not manager.is_alive()
    assert errors == []
