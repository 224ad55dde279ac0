"""ISO 9283 figures of measured poses, against hand computations."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

from helpers.measurement_files import write_csv
from tribokin.iso9283.metrics import position_repeatability
from tribokin.measurement import figures
from tribokin.measurement.contract import read_measurements
from tribokin.measurement.figures import bootstrap_bytes, measurement_figures, pose_figures, rp_l_interval
from tribokin.measurement.registration import register_measurements

UM = 1e-6
CENTRE_MM = np.array([500.0, 200.0, 300.0])
#: Direction "+": four cycles 3, 3, 4, 4 µm from their barycentre, which lies 10 µm off the commanded
#: position along x; direction "-": two cycles 2 µm either side of a barycentre 12 µm above the first.
PLUS_UM = np.array([[3, 0, 0], [-3, 0, 0], [0, 4, 0], [0, -4, 0]]) + [10, 0, 0]
MINUS_UM = np.array([[0, 0, 14], [0, 0, 10]]) + [10, 0, 0]


def _cells(values) -> str:
    """Numbers as CSV cells, in full precision."""
    return ",".join(repr(float(v)) for v in values)


def _rows(direction, offsets_um, angles_deg=None):
    rows = []
    for cycle, offset in enumerate(np.asarray(offsets_um, dtype=float), start=1):
        a, c = angles_deg[cycle - 1] if angles_deg is not None else (0.0, 0.0)
        rows.append(f"P1,{direction},{cycle},{_cells(CENTRE_MM + offset * 1e-3)},{a},0,{c},{_cells(CENTRE_MM)}")
    return rows


@pytest.fixture
def hand(tmp_path):
    angles = [(10.000, 179.999), (10.001, -179.999), (9.999, 179.999), (10.000, -179.999)]
    rows = _rows("+", PLUS_UM, angles) + _rows("-", MINUS_UM) + _rows("o", [[10, 0, 40]])
    path = write_csv(tmp_path, "pose,direction,cycle,x_mm,y_mm,z_mm,a_deg,b_deg,c_deg,cx_mm,cy_mm,cz_mm", rows)
    return pose_figures(read_measurements(path).poses[0])


def test_per_direction_figures_equal_the_hand_computation(hand):
    plus, minus, once = hand.directions
    # l_j = 3, 3, 4, 4: l_bar = 3.5, S_l = sqrt(4 * 0.25 / 3)
    assert plus.RP_l_m == pytest.approx((3.5 + 3 * np.sqrt(1 / 3)) * UM, rel=1e-6)
    assert plus.AP_p_m == pytest.approx(10 * UM, rel=1e-6)
    # covariance diag(18/3, 32/3, 0) µm²
    np.testing.assert_allclose(plus.semi_axes_m, np.array([np.sqrt(32 / 3), np.sqrt(6), 0]) * UM, rtol=1e-6, atol=1e-12)
    # a: deviations 0, 1, -1, 0 mdeg; c wraps at ±180°: deviations 0, 2, 0, 2 mdeg
    rp_a, rp_b, rp_c = plus.RP_abc_rad * 180e3 / np.pi
    assert rp_a == pytest.approx(3 * np.sqrt(2 / 3), rel=1e-6)
    assert rp_b == 0 and rp_c == pytest.approx(3 * np.sqrt(4 / 3), rel=1e-6)
    assert minus.RP_l_m == pytest.approx(2 * UM, rel=1e-6) and minus.cycles == 2
    assert once.too_short and once.RP_l_m is None and once.RP_l_ci95_m is None and once.cycles == 1


def test_pose_figures_across_directions_equal_the_hand_computation(hand):
    assert hand.vAP_p_m == pytest.approx(12 * UM, rel=1e-6)  # the one-cycle series gives no barycentre for vAP
    # pooled cloud of all seven cycles: barycentre 64/7 µm above the "+" one
    pooled = np.vstack([PLUS_UM, MINUS_UM, [[10, 0, 40]]]) - [0, 0, 64 / 7] - [10, 0, 0]
    distances = np.linalg.norm(pooled, axis=1)
    assert hand.RP_l_all_directions_m == pytest.approx(
        (distances.mean() + 3 * distances.std(ddof=1)) * UM, rel=1e-6)
    assert hand.commanded_spread_m == 0 and not hand.commanded_corrected and not hand.registered


def test_report_rows_carry_the_names_of_run(hand):
    rows = hand.report_rows()
    assert [r["direction"] for r in rows] == ["+", "-", "o"]
    assert rows[0]["RP_l_um"] == pytest.approx(3.5 + 3 * np.sqrt(1 / 3), rel=1e-6)
    assert rows[0]["AP_p_um"] == pytest.approx(10, rel=1e-6)
    assert rows[0]["RP_a_mdeg"] == pytest.approx(3 * np.sqrt(2 / 3), rel=1e-6)
    assert rows[2]["too_short_for_RP"] and rows[2]["RP_l_um"] is None
    assert all(r["vAP_p_um"] == pytest.approx(12, rel=1e-6) for r in rows)


def test_bootstrap_interval_of_two_cycles_is_zero_to_half_their_distance():
    # each resample draws the same cycle twice (RP_l 0) or both (RP_l d/2), with probability 1/2 each
    points = np.array([[0.0, 0, 0], [8e-6, 0, 0]])
    low, high = rp_l_interval(points, 4000, np.random.default_rng(1))
    assert low == 0 and high == pytest.approx(4e-6)


def test_bootstrap_is_the_same_every_run_and_follows_the_seed(tmp_path):
    rng = np.random.default_rng(5)
    rows = [f"P,+,{k + 1},{x},{y},{z}" for k, (x, y, z) in enumerate(rng.normal(0, 1e-5, (30, 3)))]
    measurements = read_measurements(write_csv(tmp_path, "pose,direction,cycle,x_m,y_m,z_m", rows))
    first = measurement_figures(measurements)[0].directions[0]
    assert measurement_figures(measurements)[0].directions[0].RP_l_ci95_m == first.RP_l_ci95_m
    assert measurement_figures(measurements, seed=6)[0].directions[0].RP_l_ci95_m != first.RP_l_ci95_m
    assert first.RP_l_ci95_m[0] < first.RP_l_m < first.RP_l_ci95_m[1]


def _retaught(tmp_path, rotation_deg=30.0):
    """Three poses in a tracker frame rotated about z and shifted, approached from "+" (cycles 1, 2 of the
    four rows) and "-" (3, 4); pose A's rows commanded up to 0.2 mm apart along x, each reached 1 µm above
    its own commanded position plus ±2 µm along y."""
    angle = np.radians(rotation_deg)
    to_tracker = np.array([[np.cos(angle), np.sin(angle), 0], [-np.sin(angle), np.cos(angle), 0], [0, 0, 1]])
    shift = np.array([0.1, -0.2, 0.05])
    rows = []
    for pose, base in (("A", [0.5, 0.0, 0.3]), ("B", [0.2, 0.4, 0.3]), ("C", [0.3, 0.1, 0.6])):
        for cycle in range(1, 5):
            retaught = [0.0, 2e-4, 1e-4, 0.0][cycle - 1] if pose == "A" else 0.0
            commanded = np.array(base) + [retaught, 0, 0]
            reached = commanded + [0, (-1) ** cycle * 2e-6, 1e-6]
            direction, number = ("+", cycle) if cycle < 3 else ("-", cycle - 2)
            rows.append(f"{pose},{direction},{number},{_cells(to_tracker @ reached + shift)},{_cells(commanded)}")
    return read_measurements(write_csv(tmp_path, "pose,direction,cycle,x_m,y_m,z_m,cx_m,cy_m,cz_m", rows))


def test_retaught_commanded_positions_are_removed_only_under_a_registration(tmp_path):
    measurements = _retaught(tmp_path)
    registration = register_measurements(measurements)
    corrected = pose_figures(measurements.poses[0], registration)
    assert corrected.commanded_corrected and corrected.registered
    assert corrected.commanded_spread_m == pytest.approx(2e-4)
    for direction in corrected.directions:
        assert direction.RP_l_m == pytest.approx(2e-6, rel=1e-6)  # l_j = 2 µm each
        assert direction.AP_p_m < 1e-12  # the common 1 µm lift goes into the registration's shift
    assert corrected.vAP_p_m < 1e-12
    raw = pose_figures(measurements.poses[0])
    assert not raw.commanded_corrected and raw.commanded_spread_m == pytest.approx(2e-4)
    assert raw.directions[0].RP_l_m > 50e-6  # the 0.2 mm of re-teaching left in
    assert raw.report_rows()[0]["commanded_spread_um"] == pytest.approx(200)


def _interval_of_one_draw(positions: np.ndarray, resamples: int, seed) -> tuple[float, float]:
    """The bootstrap interval as one draw of every resample at once (as before it was streamed)."""
    draws = np.random.default_rng(seed).integers(0, len(positions), size=(resamples, len(positions)))
    low, high = np.percentile(position_repeatability(positions[draws])[0], [2.5, 97.5])
    return float(low), float(high)


@pytest.mark.parametrize("block_cycles", [1, 999, 2 ** 19])
def test_streamed_bootstrap_gives_the_bytes_of_one_draw(monkeypatch, block_cycles):
    """Blocks of one resample, of a few, and all at once: the same indices in the same order, the same RP_l."""
    positions = np.random.default_rng(3).normal(scale=5e-6, size=(333, 3)) + [0.5, 0.2, 0.3]
    monkeypatch.setattr(figures, "BOOTSTRAP_BLOCK_CYCLES", block_cycles)
    streamed = rp_l_interval(positions, 2000, np.random.default_rng([9283, 0, 1]))
    assert np.array(streamed).tobytes() == np.array(_interval_of_one_draw(positions, 2000, [9283, 0, 1])).tobytes()


def test_bootstrap_of_a_long_series_holds_one_block_not_every_resample():
    """10^6 cycles: one resample at a time (about 100 MiB) where every resample at once held 40 × 24 MB."""
    cycles, resamples = 10 ** 6, 40
    positions = np.random.default_rng(4).normal(scale=5e-6, size=(cycles, 3))
    tracemalloc.start()
    rp_l_interval(positions, resamples, np.random.default_rng(1))
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak <= bootstrap_bytes(cycles, resamples) < resamples * cycles * 24 / 4
