"""Column statistics read block by block equal numpy's on the whole column."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from tribokin.maps.streaming import Spread, blocks, order_statistic, spread


def reader(values):
    return lambda part: values[part]


@pytest.fixture
def small_blocks(monkeypatch):
    """Blocks, bins and gathered values few enough for the narrowing passes to run on a few hundred values."""
    monkeypatch.setattr("tribokin.maps.streaming.BLOCK_TARGETS", 16)
    monkeypatch.setattr("tribokin.maps.streaming.BINS", 8)
    monkeypatch.setattr("tribokin.maps.streaming.GATHER_VALUES", 16)


def test_blocks_cover_the_range_once():
    assert [(b.start, b.stop) for b in blocks(10, 4)] == [(0, 4), (4, 8), (8, 10)]
    assert list(blocks(0, 4)) == []


@pytest.mark.parametrize("narrowed", [True, False])
@pytest.mark.parametrize("count", [3, 12, 999, 1000])
def test_spread_equals_numpy_on_the_finite_values(monkeypatch, count, narrowed):
    """Narrowed down by counting passes (few values gathered at once), or gathered in one pass."""
    monkeypatch.setattr("tribokin.maps.streaming.BLOCK_TARGETS", 16)
    monkeypatch.setattr("tribokin.maps.streaming.BINS", 8)
    monkeypatch.setattr("tribokin.maps.streaming.GATHER_VALUES", 16 if narrowed else 1 << 20)
    values = np.random.default_rng(count).lognormal(size=count)
    values[::7] = np.nan
    values[1::11] = np.inf
    finite = values[np.isfinite(values)]
    assert spread(reader(values), count) == Spread(finite.min(), np.median(finite), finite.max())


def test_every_rank_is_found_with_ties_and_near_equal_values(small_blocks):
    values = np.concatenate([np.full(300, 1.0), 1.0 + np.arange(1, 40) * np.spacing(1.0), np.arange(50.0)])
    np.random.default_rng(0).shuffle(values)
    ordered = np.sort(values)
    for rank in range(0, len(values), 7):
        assert order_statistic(reader(values), len(values), rank) == ordered[rank]


def test_the_widest_columns_are_narrowed_down_without_overflow(small_blocks):
    """Values from -1.8e308 to 1.5e299: their range is beyond the largest float (a hypothesis example)."""
    values = np.array([0.0] * 7 + [1.4752687743193205e299, -1.797693133387047e308, 5e-324, -np.finfo(float).max]
                      + list(np.random.default_rng(1).normal(size=40)))
    ordered = np.sort(values)
    for rank in range(len(values)):
        assert order_statistic(reader(values), len(values), rank) == ordered[rank]
    assert spread(reader(values), len(values)).median == np.median(values)


def test_no_finite_values_give_none():
    assert spread(reader(np.full(5, np.nan)), 5) == Spread(None, None, None)
    assert Spread(None, None, None).as_dict() == {"min": None, "median": None, "max": None}


@given(st.lists(st.floats(allow_nan=True, allow_infinity=True, width=64), min_size=1, max_size=200))
def test_median_is_numpys_for_any_column(values):
    import tribokin.maps.streaming as streaming

    values = np.array(values)
    finite = values[np.isfinite(values)]
    saved = streaming.BLOCK_TARGETS, streaming.BINS, streaming.GATHER_VALUES
    streaming.BLOCK_TARGETS, streaming.BINS, streaming.GATHER_VALUES = 8, 4, 8  # (hypothesis runs it many times)
    try:
        median = spread(reader(values), len(values)).median
    finally:
        streaming.BLOCK_TARGETS, streaming.BINS, streaming.GATHER_VALUES = saved
    with np.errstate(over="ignore"):  # the mean of two huge middle values may overflow, in numpy too
        assert median == (np.median(finite) if finite.size else None)
