"""Column statistics read block by block equal numpy's on the whole column."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tribokin.maps.streaming import blocks, order_statistic, spread


def reader(values):
    return lambda part: values[part]


@pytest.fixture
def small_blocks(monkeypatch):
    """Blocks and bins small enough for the narrowing passes to run on a few hundred values."""
    monkeypatch.setattr("tribokin.maps.streaming.BLOCK_TARGETS", 16)
    monkeypatch.setattr("tribokin.maps.streaming.BINS", 8)


def test_blocks_cover_the_range_once():
    assert [(b.start, b.stop) for b in blocks(10, 4)] == [(0, 4), (4, 8), (8, 10)]
    assert list(blocks(0, 4)) == []


@pytest.mark.parametrize("count", [3, 12, 999, 1000])
def test_spread_equals_numpy_on_the_finite_values(small_blocks, count):
    values = np.random.default_rng(count).lognormal(size=count)
    values[::7] = np.nan
    values[1::11] = np.inf
    finite = values[np.isfinite(values)]
    assert spread(reader(values), count) == {"min": finite.min(), "median": np.median(finite), "max": finite.max()}


def test_every_rank_is_found_with_ties_and_near_equal_values(small_blocks):
    values = np.concatenate([np.full(300, 1.0), 1.0 + np.arange(1, 40) * np.spacing(1.0), np.arange(50.0)])
    np.random.default_rng(0).shuffle(values)
    ordered = np.sort(values)
    for rank in range(0, len(values), 7):
        assert order_statistic(reader(values), len(values), rank) == ordered[rank]


def test_no_finite_values_give_none():
    assert spread(reader(np.full(5, np.nan)), 5) == {"min": None, "median": None, "max": None}


@given(st.lists(st.floats(allow_nan=True, allow_infinity=True, width=64), min_size=1, max_size=200))
def test_median_is_numpys_for_any_column(values):
    import tribokin.maps.streaming as streaming

    values = np.array(values)
    finite = values[np.isfinite(values)]
    saved = streaming.BLOCK_TARGETS, streaming.BINS
    streaming.BLOCK_TARGETS, streaming.BINS = 8, 4  # (hypothesis runs the test many times: no fixture)
    try:
        median = spread(reader(values), len(values))["median"]
    finally:
        streaming.BLOCK_TARGETS, streaming.BINS = saved
    with np.errstate(over="ignore"):  # the mean of two huge middle values may overflow, in numpy too
        assert median == (np.median(finite) if finite.size else None)
