"""The map's progress bar, and the notice that numba compiles the kernels first."""

from __future__ import annotations

import sys
from contextlib import contextmanager

from tqdm import tqdm

#: Chunks finished after the warm-up before the progress bar shows a rate and an ETA.
ETA_SAMPLES = 4


class ProgressBar(tqdm):
    """tqdm whose rate, hence ETA, is the average since its first ``warm_up`` updates (the chunks that paid for
    start-up: worker processes, first calls), shown once ``samples`` more are in (``?`` until then); and without
    tqdm's monitor thread, which would outlive the bar and keep later runs from forking workers."""

    monitor_interval = 0

    def __init__(self, *args, warm_up: int = 1, samples: int = ETA_SAMPLES, **kwargs):
        self.warm_up, self.samples, self.updates = warm_up, samples, 0
        self.clock_start: tuple[float, float] | None = None  # (time [s], count) at the end of the warm-up
        super().__init__(*args, **kwargs)

    def update(self, n=1):
        self.updates += 1
        super().update(n)
        if self.updates == self.warm_up and not self.disable:
            self.clock_start = (self._time(), self.n)

    @property
    def format_dict(self) -> dict:
        shown = super().format_dict
        shown["rate"] = 0.0  # tqdm shows "?"
        if self.clock_start is not None and self.updates >= self.warm_up + self.samples:
            start_s, start_n = self.clock_start
            shown["rate"] = (self.n - start_n) / max(self._time() - start_s, 1e-9)
        elif self.total is not None and self.n >= self.total and self.n > self.initial:
            # done before the ETA's samples were in (a small map): the rate of the whole run, start-up included
            shown["rate"] = (self.n - self.initial) / max(self._time() - self.start_t, 1e-9)
        return shown


#: What the map's progress says first when numba compiles the kernels before its chunks run (:func:`map_progress`).
COMPILING = ("map: numba compiles tribokin's kernels first, once after installing or changing tribokin "
             "(TRIBOKIN_KERNELS=numpy runs without them)")


def kernels_to_compile() -> bool:
    """Whether a run compiles its kernels: on the compiled path (:func:`~tribokin.compiled.use_compiled`), with none
    of tribokin's kernels (its modules ``*_kernels``) in numba's cache (:func:`~tribokin.compiled.cache_is_empty`)."""
    from tribokin.compiled import cache_is_empty, use_compiled

    if not use_compiled():
        return False
    import importlib
    import pkgutil

    import tribokin

    names = [module.name for module in pkgutil.walk_packages(tribokin.__path__, "tribokin.")
             if module.name.endswith("_kernels")]
    return cache_is_empty([importlib.import_module(name) for name in names])


@contextmanager
def map_progress(warm_up: int, compiling: bool = False):
    """A ``progress(done_targets, total_targets)`` callback drawing the map's :class:`ProgressBar`, made at
    its first call (after the run's checks, before its chunks), and when ``compiling`` (:func:`kernels_to_compile`,
    asked before the run) first saying so on stderr; the bar is closed when the block ends."""
    bar = None

    def report(done: int, total: int) -> None:
        nonlocal bar
        if bar is None:
            if compiling:
                print(COMPILING, file=sys.stderr, flush=True)
            bar = ProgressBar(total=total, initial=done, unit="target", desc="map", warm_up=warm_up)
        else:
            bar.update(done - bar.n)

    try:
        yield report
    finally:
        if bar is not None:
            bar.close()
