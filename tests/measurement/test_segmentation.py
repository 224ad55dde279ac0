"""Dwells of a raw stream found, labelled in order, and the unmatched ones reported."""

from __future__ import annotations

import numpy as np
import pytest

from tribokin.errors import InputError
from tribokin.measurement.contract import Stream
from tribokin.measurement.segmentation import dwell_measurements, find_dwells, label_dwells

RATE_HZ = 100.0
DWELL_S, MOVE_S = 2.0, 1.0
PLACES_M = {"home": [0.0, 0.0, 0.8], "A": [0.5, 0.0, 0.3], "B": [0.5, 0.05, 0.3], "C": [0.45, 0.05, 0.35],
            "pause": [0.4, 0.2, 0.4]}
VISITS = ["home", "A", "B", "C", "A", "B", "C", "A", "B", "C", "pause"]


def _stream(visits=VISITS, noise_m=5e-6):
    """Dwells of DWELL_S at each visit, straight moves of MOVE_S between, 5 µm instrument noise."""
    times, positions, truth = [], [], []
    t = 0.0
    for k, place in enumerate(visits):
        here = np.array(PLACES_M[place])
        if k:
            previous = np.array(PLACES_M[visits[k - 1]])
            steps = np.arange(1, int(MOVE_S * RATE_HZ)) / (MOVE_S * RATE_HZ)
            times.append(t + steps * MOVE_S)
            positions.append(previous + steps[:, None] * (here - previous))
            t += MOVE_S
        steps = np.arange(int(DWELL_S * RATE_HZ)) / RATE_HZ
        truth.append((t, t + steps[-1], here))
        times.append(t + steps)
        positions.append(np.tile(here, (len(steps), 1)))
        t += DWELL_S
    positions = np.vstack(positions) + np.random.default_rng(4).normal(0, noise_m, (sum(map(len, times)), 3))
    times = np.concatenate(times)
    return Stream("stream.csv", np.arange(len(times)) + 2, times, positions), truth


def test_dwells_are_found_where_the_stream_settles():
    stream, truth = _stream()
    dwells = find_dwells(stream.times_s, stream.positions_m)
    assert len(dwells) == len(truth)
    for dwell, (start, end, place) in zip(dwells, truth, strict=True):
        assert dwell.start_s == pytest.approx(start, abs=0.03) and dwell.end_s == pytest.approx(end, abs=0.03)
        np.testing.assert_allclose(dwell.position_m, place, atol=3e-6)


def test_dwells_are_labelled_in_order_and_the_unmatched_reported():
    stream, _ = _stream()
    dwells = label_dwells(find_dwells(stream.times_s, stream.positions_m))
    assert [(d.pose, d.cycle) for d in dwells] == [
        (None, None), ("P1", 1), ("P2", 1), ("P3", 1), ("P1", 2), ("P2", 2), ("P3", 2),
        ("P1", 3), ("P2", 3), ("P3", 3), (None, None)]
    measurements = dwell_measurements(stream, dwells)
    assert [p.name for p in measurements.poses] == ["P1", "P2", "P3"]
    series = measurements.poses[0].series[0]
    assert series.cycles.tolist() == [1, 2, 3] and series.direction == "+"
    np.testing.assert_allclose(series.positions_m, np.tile(PLACES_M["A"], (3, 1)), atol=3e-6)
    assert series.times_s[0] == pytest.approx(3 + DWELL_S / 2, abs=0.05)
    assert series.lines[0] == stream.lines[dwells[1].first]


def test_a_tighter_radius_than_the_noise_finds_no_dwell_and_a_stream_without_repeats_is_refused():
    stream, _ = _stream()
    assert find_dwells(stream.times_s, stream.positions_m, radius_m=5e-6) == ()
    once, _ = _stream(["A", "B", "C"])
    with pytest.raises(InputError, match="3 settled dwells found, no pose among them visited twice"):
        dwell_measurements(once, label_dwells(find_dwells(once.times_s, once.positions_m)))
