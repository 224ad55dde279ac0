"""BLAS threads: work whose bytes must not depend on how many cores the machine has runs single-threaded.

OpenBLAS splits some products over its threads (by default one per core) and sums their parts in an order that
depends on how many there are, so a result can move by rounding from one machine to another. An iterative fit ends
where rounding takes it: the UR5 example's calibration (``studies/ur5-calibrate.toml``) gave a stiffness standard
error of 13 235.56 N·m/rad on two BLAS threads and 13 234.98 on one (``OPENBLAS_NUM_THREADS=1``, which dask's workers
also set in the process that starts them). Such work runs inside :func:`single_threaded_blas`; its matrices are
small (3 × 3 scatter matrices, per-pose Jacobians), so one thread costs nothing measurable.
"""

from __future__ import annotations

from contextlib import contextmanager


@contextmanager
def single_threaded_blas():
    """Run the block (or, as a decorator, the function) with every loaded BLAS library on one thread
    (``threadpoolctl``), restoring their thread counts after."""
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="blas"):
        yield
