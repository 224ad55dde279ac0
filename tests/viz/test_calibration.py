"""Figures of a calibration: measured clouds with predicted ellipses, and the parity plot."""

from __future__ import annotations

import struct

import numpy as np
import pytest

from tribokin.calibration.cross_validation import PredictedFigure
from tribokin.viz import calibration
from tribokin.viz.calibration import (
    RADIUS_95_2D,
    ParityPoint,
    PredictedCloud,
    ellipse_outline,
    save_calibration_clouds,
    save_parity,
)


def png_size(path) -> tuple[int, int]:
    """(width, height) [px] from the IHDR chunk of a PNG file, which must be one."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR"
    return struct.unpack(">II", data[16:24])


def clouds(points_per_direction=(30, 30, 30), names=("+x", "-y", "o")) -> list[PredictedCloud]:
    """Anisotropic clouds of a few µm about a pose 0.5 m from the base, and predictions near them."""
    rng = np.random.default_rng(5)
    pose = np.array([0.6, 0.1, 0.4])
    found = []
    for n, name in zip(points_per_direction, names, strict=True):
        shape = rng.normal(size=(3, 3)) * np.array([3.0, 1.5, 0.7])[:, None] * 1e-6
        covariance = shape @ shape.T
        mean = pose + rng.normal(size=3) * 2e-6
        found.append(PredictedCloud(name, rng.multivariate_normal(mean, covariance, size=n),
                                    mean + rng.normal(size=3) * 0.5e-6, 1.2 * covariance))
    return found


def parity_points(count=15, kinds=("RP_l", "vAP_p"), low_um=1.0, high_um=14.0) -> list[ParityPoint]:
    """``count`` figures between ``low_um`` and ``high_um`` measured, predicted within 20 %, intervals about them."""
    rng = np.random.default_rng(6)
    measured = np.geomspace(low_um, high_um, count) * 1e-6
    predicted = measured * rng.uniform(0.8, 1.2, count)
    return [ParityPoint(f"P{k // 3 + 1}_{k % 3}", kinds[k % len(kinds)],
                        PredictedFigure(float(m), float(p), (float(0.6 * p), float(1.5 * p))))
            for k, (m, p) in enumerate(zip(measured, predicted, strict=True))]


def captured_figures(monkeypatch) -> list:
    """The figures the module draws from now on, kept for inspection."""
    drawn, agg_figure = [], calibration.agg_figure

    def keeping(**options):
        drawn.append(agg_figure(**options))
        return drawn[-1]

    monkeypatch.setattr(calibration, "agg_figure", keeping)
    return drawn


def test_the_95_percent_radius_of_a_2d_gaussian():
    # P(r² ≤ R²) = 1 - exp(-R²/2) for a 2-D standard Gaussian
    assert RADIUS_95_2D == pytest.approx(np.sqrt(-2 * np.log(0.05)), rel=1e-12)
    assert RADIUS_95_2D == pytest.approx(2.4477, abs=1e-4)


@pytest.mark.parametrize("covariance", [[[4.0, 1.5], [1.5, 1.0]], [[0.3, -0.2], [-0.2, 2.5]], [[2.0, 0.0], [0.0, 2.0]]])
def test_ellipse_outline_lies_on_the_mahalanobis_radius_and_encloses_its_area(covariance):
    covariance = np.array(covariance)
    mean = np.array([1.0, -2.0])
    outline = ellipse_outline(mean, covariance, RADIUS_95_2D, points=400)
    assert outline.shape == (400, 2) and np.array_equal(outline[0], outline[-1])
    offsets = outline - mean
    distances = np.einsum("ni,ni->n", offsets, np.linalg.solve(covariance, offsets.T).T)
    np.testing.assert_allclose(distances, RADIUS_95_2D ** 2, rtol=0, atol=1e-12)
    x, y = outline.T
    shoelace = 0.5 * abs(np.dot(x[:-1], y[1:]) - np.dot(x[1:], y[:-1]))
    assert shoelace == pytest.approx(np.pi * RADIUS_95_2D ** 2 * np.sqrt(np.linalg.det(covariance)), rel=1e-3)


def test_ellipse_outline_of_a_singular_covariance_is_a_segment():
    outline = ellipse_outline(np.zeros(2), np.array([[1.0, 1.0], [1.0, 1.0]]), 2.0)
    np.testing.assert_allclose(outline[:, 0], outline[:, 1], atol=1e-12)
    assert np.abs(outline[:, 0]).max() == pytest.approx(2.0, rel=1e-3)  # radius × sqrt(C_xx)


def test_clouds_figure_is_a_png_written_the_same_twice(tmp_path):
    save_calibration_clouds(clouds(), tmp_path / "a.png", "P1")
    save_calibration_clouds(clouds(), tmp_path / "b.png", "P1")
    width, height = png_size(tmp_path / "a.png")
    assert 1000 < width < 2000 and 400 < height < width and (tmp_path / "a.png").stat().st_size > 20_000
    assert (tmp_path / "a.png").read_bytes() == (tmp_path / "b.png").read_bytes()


def test_clouds_figure_with_a_one_point_and_a_two_point_direction(tmp_path, monkeypatch):
    drawn = captured_figures(monkeypatch)
    save_calibration_clouds(clouds((30, 1, 2)), tmp_path / "few.png")
    assert png_size(tmp_path / "few.png")[0] > 1000
    # per panel: 3 predicted ellipses, 1 measured (the 30-cycle direction); markers are lines of one point
    ellipses = [[line for line in panel.lines if len(line.get_xdata()) > 1] for panel in drawn[0].axes]
    assert [len(lines) for lines in ellipses] == [4, 4, 4]
    assert [sum(line.get_linestyle() == "--" for line in lines) for lines in ellipses] == [1, 1, 1]


def test_names_with_dollars_and_underscores_are_shown_as_written(tmp_path, monkeypatch):
    drawn = captured_figures(monkeypatch)
    names = (r"$\nosuchsymbol$", "a_b", "c$d$")  # as math text the first would fail to draw
    save_calibration_clouds(clouds(names=names), tmp_path / "clouds.png", r"pose $\alsonot_1$")
    points = parity_points(kinds=(r"$\kind_x$", "RP_l"))
    points[0] = ParityPoint(r"$\nosuchsymbol$", "RP_l", points[0].figure)
    save_parity(points, tmp_path / "parity.png", r"$\nosuchsymbol$")
    texts = [t.get_text() for figure in drawn for t in figure.findobj(lambda o: hasattr(o, "get_text"))]
    assert {r"$\nosuchsymbol$: 30 cycles", "a_b: 30 cycles", r"pose $\alsonot_1$", r"$\nosuchsymbol$"} <= set(texts)
    assert any(r"$\kind_x$" in text for text in texts)


def test_parity_plot_is_a_png_written_the_same_twice(tmp_path):
    save_parity(parity_points(), tmp_path / "a.png", "calibration")
    save_parity(parity_points(), tmp_path / "b.png", "calibration")
    width, height = png_size(tmp_path / "a.png")
    assert 500 < width < 1200 and 500 < height < 1200 and (tmp_path / "a.png").stat().st_size > 20_000
    assert (tmp_path / "a.png").read_bytes() == (tmp_path / "b.png").read_bytes()


def test_parity_plot_is_linear_from_zero_up_to_a_span_of_20_and_log_log_beyond(tmp_path, monkeypatch):
    drawn = captured_figures(monkeypatch)
    save_parity(parity_points(low_um=1.0, high_um=10.0), tmp_path / "linear.png")
    save_parity(parity_points(low_um=0.1, high_um=10.0), tmp_path / "log.png")
    linear, log = (figure.axes[0] for figure in drawn)
    assert (linear.get_xscale(), linear.get_yscale()) == ("linear", "linear")
    assert linear.get_xlim()[0] == 0 and linear.get_xlim() == linear.get_ylim()
    assert (log.get_xscale(), log.get_yscale()) == ("log", "log") and log.get_xlim() == log.get_ylim()
    assert (linear.get_xlabel(), linear.get_ylabel()) == ("measured [µm]", "predicted [µm]")
    labels = [t.get_text() for t in log.get_xticklabels() + log.get_yticklabels() if t.get_text()]
    assert labels and not any("$" in label for label in labels)  # plain numbers, not 10^n math text


def test_parity_plot_names_its_points_up_to_15(tmp_path, monkeypatch):
    drawn = captured_figures(monkeypatch)
    save_parity(parity_points(15), tmp_path / "named.png")
    save_parity(parity_points(16), tmp_path / "unnamed.png")
    named, unnamed = ([t.get_text() for t in figure.axes[0].texts] for figure in drawn)
    assert named == [p.label for p in parity_points(15)] and unnamed == []
