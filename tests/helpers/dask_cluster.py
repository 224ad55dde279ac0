"""A dask cluster for one test that leaves no thread behind it in the test's process."""

from __future__ import annotations

import threading
from collections.abc import Iterator
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager


@contextmanager
def local_cluster() -> Iterator[str]:
    """The scheduler address of a ``LocalCluster`` of two worker processes of two threads, closed after the block.

    distributed keeps one thread of its own for good once a client has run (``distributed.utils._offload_executor``,
    "Dask-Offload"). A process with a second thread spawns its local workers rather than forking them
    (``tribokin.execution.executor_for``) and draws its views itself: every later test of this xdist worker would
    pay each spawned worker's imports (about 2 CPU s) and test another path than a fresh process takes. The pool
    is replaced by an unstarted one (its thread begins at its first task) and its thread ended; the cluster's own
    threads end with it.
    """
    from dask.distributed import LocalCluster
    from distributed import utils

    with LocalCluster(n_workers=2, threads_per_worker=2, processes=True,
                      dashboard_address=None) as cluster:
        yield cluster.scheduler_address
    used, utils._offload_executor = utils._offload_executor, ThreadPoolExecutor(1, thread_name_prefix="Dask-Offload")
    used.shutdown(wait=True)
    for thread in threading.enumerate():  # and the threads that watch the workers' processes end with them
        if thread is not threading.main_thread():
            thread.join(timeout=60)
    assert threading.active_count() == 1, [thread.name for thread in threading.enumerate()]
