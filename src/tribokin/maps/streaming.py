"""Statistics of per-target columns read block by block, so a map of any size is summarised in
bounded memory: minimum, exact median and maximum of a column that is never held whole (its finite values at most
``GATHER_VALUES`` at once)."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import asdict, dataclass

import numpy as np

#: Targets read at once.
BLOCK_TARGETS = 1 << 16
#: Bins of a counting pass when narrowing down an order statistic.
BINS = 4096
#: Most values gathered at once to take order statistics from (8 MiB, and as much again to partition them): a column
#: with more finite values is narrowed down by counting passes first.
GATHER_VALUES = 1 << 20


@dataclass(frozen=True)
class Spread:
    """Minimum, median and maximum of a column's finite values (``None`` each when it has none), in its unit."""

    min: float | None
    median: float | None
    max: float | None

    def as_dict(self) -> dict:
        """``{min, median, max}``, as ``summary.json`` gives it."""
        return asdict(self)

    def as_text(self) -> str:
        """``min / median / max`` to three decimals, as the command prints it; ``-`` without values."""
        if self.min is None:
            return "-"
        return f"{self.min:.3f} / {self.median:.3f} / {self.max:.3f}"


def blocks(size: int, block: int | None = None) -> Iterator[slice]:
    """Consecutive slices covering ``range(size)``, ``block`` (default ``BLOCK_TARGETS``) targets each (the last
    may be shorter)."""
    block = block or BLOCK_TARGETS
    return (slice(first, min(first + block, size)) for first in range(0, size, block))


def _finite(read: Callable[[slice], np.ndarray], size: int) -> Iterator[np.ndarray]:
    for part in blocks(size):
        values = np.asarray(read(part), dtype=float)
        yield values[np.isfinite(values)]


def order_statistic(read: Callable[[slice], np.ndarray], size: int, rank: int) -> float:
    """The ``rank``-th smallest finite value (0-based) of a column of ``size`` values that ``read(slice)``
    returns block by block, exactly.

    While more than ``GATHER_VALUES`` candidates remain, a pass counts them in ``BINS`` bins between
    their extremes and keeps the bin holding the rank; the extremes fall in different bins, so every
    pass drops some, and typically all but a ``BINS``-th. The last pass gathers the rest and partitions them.
    """
    low, high, below = -np.inf, np.inf, 0  # candidates: low <= value <= high; ``below`` values under low

    def candidates():
        for values in _finite(read, size):
            yield values[(values >= low) & (values <= high)]

    while True:
        count, low_seen, high_seen = 0, np.inf, -np.inf
        for values in candidates():
            if values.size:
                count = count + values.size
                low_seen, high_seen = min(low_seen, values.min()), max(high_seen, values.max())
        low, high = low_seen, high_seen
        if count <= GATHER_VALUES or low == high:
            break
        edges = np.linspace(low / 2, high / 2, BINS + 1) * 2  # in halves: high - low may exceed the largest float
        edges[0], edges[-1] = low, high
        counts = np.zeros(BINS, dtype=np.int64)
        for values in candidates():
            counts += np.bincount(np.clip(np.searchsorted(edges, values, side="right") - 1, 0, BINS - 1),
                                  minlength=BINS)
        cumulative = below + np.cumsum(counts)
        chosen = int(np.searchsorted(cumulative, rank, side="right"))
        below = int(cumulative[chosen - 1]) if chosen else below
        upper = edges[chosen + 1] if chosen + 1 < BINS else high
        low, high = edges[chosen], np.nextafter(upper, -np.inf) if chosen + 1 < BINS else upper
    if low == high:
        return float(low)
    return float(np.partition(np.concatenate(list(candidates())), rank - below)[rank - below])


def spread(read: Callable[[slice], np.ndarray], size: int) -> Spread:
    """The :class:`Spread` of the finite values of a column read block by block (``None`` each when
    there are none); the median as :func:`numpy.median` gives it (the mean of the middle two of an even count).
    Up to ``GATHER_VALUES`` finite values, in one pass; more, through :func:`order_statistic`."""
    count, low, high, kept = 0, np.inf, -np.inf, []
    for values in _finite(read, size):
        if values.size:
            count, low, high = count + values.size, min(low, values.min()), max(high, values.max())
            if count <= GATHER_VALUES:
                kept.append(values)
            else:
                kept.clear()  # too many: narrowed down by order_statistic
    if not count:
        return Spread(None, None, None)
    ranks = sorted({(count - 1) // 2, count // 2})
    if count <= GATHER_VALUES:
        middle = np.partition(np.concatenate(kept), ranks)[ranks]
    else:
        middle = [order_statistic(read, size, rank) for rank in ranks]
    return Spread(float(low), float(np.mean(middle)), float(high))
