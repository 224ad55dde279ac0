"""Where chunks of work run: in this process, in local worker processes, or on a dask cluster.

A chunk is a call ``function(*arguments)`` whose result depends on its arguments only, so
where it runs changes nothing but the time taken. Results come back as chunks finish. Local
workers end with the process that started them, however it ends (Linux).
"""

from __future__ import annotations

import ctypes
import multiprocessing
import os
import signal
import socket
import sys
import threading
from collections.abc import Callable, Iterator
from concurrent.futures import ProcessPoolExecutor, as_completed

from tribokin.checks import positive_int
from tribokin.errors import InputError

#: How long to try reaching a dask scheduler [s].
SCHEDULER_TIMEOUT_S = 10.0
#: How long the check before any work waits for a dask scheduler to accept a connection [s].
SCHEDULER_CHECK_S = 2.0
#: ``prctl`` option: the signal this process gets when its parent ends (Linux).
_PR_SET_PDEATHSIG = 1


def check_executor(workers: int, scheduler: str | None) -> None:
    """An :class:`InputError` for a bad ``--workers`` count, ``--workers`` with ``--scheduler``, or a
    scheduler address that is not ``scheme://host:port`` or accepts no connection within
    ``SCHEDULER_CHECK_S`` (one attempt)."""
    positive_int(workers, "command line", "--workers")
    if scheduler is None:
        return
    if workers != 1:
        raise InputError("give --workers (local processes) or --scheduler (a dask cluster), not both",
                         "command line", "--scheduler")
    from distributed.comm import get_address_host_port, parse_address

    try:
        if parse_address(scheduler)[0] == "inproc":
            return  # a scheduler in this process
        host, port = get_address_host_port(scheduler)
    except ValueError as error:
        raise InputError(f"'{scheduler}' is not a scheduler address ({error}); give it as tcp://host:port",
                         "command line", "--scheduler") from None
    try:
        socket.create_connection((host, port), timeout=SCHEDULER_CHECK_S).close()
    except (OSError, OverflowError) as error:
        reason = getattr(error, "strerror", None) or str(error)
        raise InputError(f"cannot reach the dask scheduler at '{scheduler}' ({reason}); start it or correct the "
                         "address", "command line", "--scheduler") from None


def _end_with(parent: int) -> None:
    """Worker initializer: have the kernel kill this process when its parent ends (Linux), and end now if
    the parent already has (between the fork and this call)."""
    if sys.platform == "linux":
        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)
    if os.getppid() != parent:
        os._exit(1)


def run_chunks(function: Callable, chunks: dict, workers: int = 1, scheduler: str | None = None) -> Iterator:
    """Yield ``(key, function(*arguments))`` for every ``key: arguments`` of ``chunks``, as they finish.

    Local worker processes start here, before the first result is asked for: forked from this
    process when it runs no other thread (fast, and they inherit what it has loaded), else
    spawned clean (forking a process with threads can deadlock). They end when this process
    ends, even if it is killed. ``workers`` and ``scheduler`` are those :func:`check_executor` accepted.

    Args:
        workers: local processes (1: run here, in key order).
        scheduler: address of a dask.distributed scheduler (``"tcp://host:8786"``); its workers
            must be able to import tribokin.
    """
    if scheduler is not None:
        return _run_on_dask(function, chunks, scheduler)
    if workers == 1:
        return ((key, function(*arguments)) for key, arguments in chunks.items())
    start = "fork" if "fork" in multiprocessing.get_all_start_methods() and threading.active_count() == 1 else "spawn"
    pool = ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context(start), initializer=_end_with,
                               initargs=(os.getpid(),))
    futures = {pool.submit(function, *arguments): key for key, arguments in chunks.items()}
    return _as_finished(pool, futures)


def _as_finished(pool: ProcessPoolExecutor, futures: dict) -> Iterator:
    try:
        for future in as_completed(futures):
            yield futures[future], future.result()
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _run_on_dask(function: Callable, chunks: dict, scheduler: str) -> Iterator:
    from dask.distributed import Client
    from dask.distributed import as_completed as dask_completed

    try:
        client = Client(scheduler, timeout=SCHEDULER_TIMEOUT_S, set_as_default=False)
    except (OSError, TimeoutError, ValueError) as error:
        raise InputError(f"cannot reach the dask scheduler at '{scheduler}' ({error})", "command line",
                         "--scheduler") from None
    try:
        futures = {client.submit(function, *arguments, pure=False): key for key, arguments in chunks.items()}
        for future in dask_completed(futures, loop=client.loop):
            yield futures[future], future.result()
            future.release()
    finally:
        client.close()
