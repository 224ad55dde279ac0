"""Where chunks of work run: one :class:`concurrent.futures.Executor` (local processes, a dask cluster's
client), or ``None`` for this process.

A chunk is a call ``function(*arguments)`` whose result depends on its arguments only, so
where it runs changes nothing but the time taken. Results come back as chunks finish. Local
workers end with the process that started them, however it ends (Linux).
"""

from __future__ import annotations

import ctypes
import gc
import multiprocessing
import os
import signal
import socket
import sys
import threading
from collections.abc import Callable, Iterator
from concurrent.futures import Executor, ProcessPoolExecutor, ThreadPoolExecutor, as_completed
from contextlib import contextmanager

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


def end_with_parent(parent: int) -> None:
    """In a process forked from ``parent``: freeze what this process holds now (:func:`gc.freeze`: its inheritance,
    which no collection here then walks, nor copies the pages of), have the kernel kill this process when its parent
    ends (Linux), and end now if the parent already has (between the fork and this call)."""
    gc.freeze()
    if sys.platform == "linux":
        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)
    if os.getppid() != parent:
        os._exit(1)


def _start_worker(parent: int) -> None:
    """A local worker's initializer: it ends with its parent (:func:`end_with_parent`), and at once and silently on
    Ctrl-C (SIGINT's own action, not Python's KeyboardInterrupt and its traceback: a terminal sends it to every process
    of the command, whose own process says it was interrupted; a chunk not finished is computed on ``--resume``)."""
    end_with_parent(parent)
    signal.signal(signal.SIGINT, signal.SIG_DFL)


@contextmanager
def executor_for(workers: int = 1, scheduler: str | None = None) -> Iterator[Executor | None]:
    """Where a run's chunks run, checked (:func:`check_executor`) and built once, shut down when the block ends.

    Yields ``None`` (here, in key order) for one worker and no scheduler; else a
    :class:`~concurrent.futures.ProcessPoolExecutor` of ``workers`` local processes: forked from this
    process if it runs no other thread now (fast, and they inherit what it has loaded when the first
    chunk is submitted, frozen there: :func:`_start_worker`), else spawned clean (forking a process with threads can
    deadlock); they end when this process ends, even if it is killed. What :func:`run_chunks` froze here is unfrozen
    when the block ends. With ``scheduler``, the address of a
    dask.distributed scheduler (``"tcp://host:8786"``, its workers able to import tribokin), its
    client's executor.
    """
    check_executor(workers, scheduler)
    if scheduler is not None:
        from dask.distributed import Client

        try:
            client = Client(scheduler, timeout=SCHEDULER_TIMEOUT_S, set_as_default=False)
        except (OSError, TimeoutError, ValueError) as error:
            raise InputError(f"cannot reach the dask scheduler at '{scheduler}' ({error})", "command line",
                             "--scheduler") from None
        with client:
            yield client.get_executor(pure=False)
        return
    if workers == 1:
        yield None
        return
    start = "fork" if "fork" in multiprocessing.get_all_start_methods() and threading.active_count() == 1 else "spawn"
    pool = ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context(start), initializer=_start_worker,
                               initargs=(os.getpid(),))
    try:
        yield pool
    finally:
        pool.shutdown(wait=True, cancel_futures=True)
        gc.unfreeze()


def local_workers(executor: Executor | None) -> int:
    """Chunks ``executor`` computes at once in this machine's memory: a pool's workers, else 1 (this
    process, or a cluster's own machines)."""
    pool = local_pool(executor)
    return pool._max_workers if pool is not None else 1  # the pools' size, as their constructor took it


def local_pool(executor: Executor | None) -> Executor | None:
    """``executor`` if it is a pool of this machine's processes or threads (they read and write this machine's
    files), else ``None`` (run here): a cluster's workers may be elsewhere."""
    return executor if isinstance(executor, (ProcessPoolExecutor, ThreadPoolExecutor)) else None


#: How long an interrupted local pool's managing thread is waited for [s] (:func:`run_chunks`).
MANAGER_WAIT_S = 30.0


@contextmanager
def run_chunks(function: Callable, chunks: dict, executor: Executor | None = None) -> Iterator[Iterator]:
    """Within the block, an iterator of ``(key, function(*arguments))`` for every ``key: arguments`` of
    ``chunks``, as they finish.

    Every chunk is submitted to ``executor`` on entering the block, before the first result is asked
    for; those not started when the block ends are cancelled. ``None``: run here, in key order. What this process
    holds when they are submitted is frozen first (:func:`gc.freeze`, as the gc module advises before a fork: a local
    pool forks its workers at its first chunk), so that no collection here walks it while they run.

    A :class:`~concurrent.futures.ProcessPoolExecutor` left with chunks not done (an error, Ctrl-C) is shut down: its
    own thread cancels them. Cancelling them from here races with that thread's handling of a worker that died (Ctrl-C
    ends the workers too): before Python 3.12 it then stops with ``InvalidStateError`` and the process hangs at exit
    (CPython gh-107219). That thread is then waited for (at most ``MANAGER_WAIT_S``), as the interpreter's exit would
    wait for it: otherwise the exit's wake-up of it can write to the pipe it is closing, and print an ignored
    ``OSError`` (Bad file descriptor) after the command's last line.
    """
    if executor is None:
        yield ((key, function(*arguments)) for key, arguments in chunks.items())
        return
    gc.freeze()
    futures = {executor.submit(function, *arguments): key for key, arguments in chunks.items()}
    try:  # a future is let go once its result is out: local memory and a cluster's hold no finished chunk
        yield ((futures.pop(future), future.result()) for future in as_completed(futures))
    finally:
        if futures and isinstance(executor, ProcessPoolExecutor):
            executor.shutdown(wait=False, cancel_futures=True)
            manager = getattr(executor, "_executor_manager_thread", None)  # CPython's, no public handle
            if manager is not None:
                manager.join(MANAGER_WAIT_S)
        else:
            for future in futures:
                future.cancel()
