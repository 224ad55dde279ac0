"""A study with ``[drift]``: each pose's drift figure (``drift_<pose>.png``, :func:`tribokin.viz.figures.drift_figure`)
written, the same bytes from two runs, its axes labelled with their units, and the report's drift section (the
sentence on what the figures rest on, the table of summary.json's figures with their Monte Carlo errors, the figure);
none of it without ``[drift]``."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from conftest import axis_study
from tribokin.output.writers import write_results
from tribokin.run import run_study
from tribokin.viz.canvas import save_png
from tribokin.viz.contents import drift_title, study_figures
from tribokin.viz.figures import drift_figure

#: The axis warming by its own friction (AR(1) 0.9), one cycle every 10 s for 20 minutes, sets of 10 cycles.
WARMING = {"law": "gaussian", "mean": 0.12, "std": 0.006, "ar1": 0.9,
           "thermal": {"time_constant_s": 600.0, "resistance_K_per_W": 2.0, "mu_per_K": -0.005}}


def drift_axis(friction: dict, duration_s: float = 1200.0, set_cycles: int = 10) -> dict:
    study = axis_study(friction=friction, travel_per_cycle=0.5)
    study["study"]["cycle_time_s"] = 10.0
    study["drift"] = {"duration_s": duration_s, "set_cycles": set_cycles}
    return study


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    out = tmp_path_factory.mktemp("drift") / "out"
    result = run_study(drift_axis(WARMING))
    write_results(result, out, report="light")
    return out, result


def test_the_report_shows_the_drift_figures_with_their_errors_and_what_they_rest_on(written):
    out, result = written
    page = (out / "report.html").read_text(encoding="utf-8")
    section = page[page.index("<h2>ISO 9283 drift, simulated</h2>"):page.index("<h2>Inputs</h2>")]
    assert "friction-induced change only" in section and "not on the thermal expansion of links or gears" in section
    assert "over 8000 simulated tests" in section and "sets of 10 cycles" in section
    for header in ("dAP_p [µm]", "dRP_l [µm]", "dRP_a [mdeg]", "dRP_b [mdeg]", "dRP_c [mdeg]"):
        assert header in section
    drift = json.loads((out / "summary.json").read_text())["poses"][0]["directions"]["+"]["drift"]
    for key in ("dAP_p_um", "dRP_l_um", "dRP_a_mdeg"):
        assert f"{drift[key]:.3f} ± {drift[key] * drift['mc_errors'][key]:.3f}" in section
    png = (out / "drift_P1.png").read_bytes()
    assert png.startswith(b"\x89PNG")
    embedded = re.findall(r'<h3>([^<]+)</h3><img alt="[^"]*" src="data:image/png;base64,', page)
    assert embedded == ["drift_P1.png", "field_P1.png"]  # the drift figure in its section, not again below
    assert page.index("<h2>ISO 9283 figures per pose</h2>") < page.index("<h2>ISO 9283 drift, simulated</h2>")


def test_two_runs_draw_the_same_drift_figure_and_report(written, tmp_path):
    out, _ = written
    write_results(run_study(drift_axis(WARMING)), tmp_path / "again", report="light")
    names = sorted(p.name for p in out.iterdir())
    assert names == sorted(p.name for p in (tmp_path / "again").iterdir()) and "drift_P1.png" in names
    for name in names:
        assert (tmp_path / "again" / name).read_bytes() == (out / name).read_bytes(), name


def test_every_axis_is_labelled_with_its_unit(written):
    """µm for AP_p and RP_l, °C for the temperature, minutes for a 20-minute test; the notebook's figures hold it
    after the pose's field."""
    _, result = written
    figure = drift_figure(result.drifts[0])
    ap, rp, heat = figure.axes
    assert "[µm]" in ap.get_ylabel() and "[µm]" in rp.get_ylabel() and "[°C]" in heat.get_ylabel()
    assert heat.get_xlabel().endswith("[min]") and heat.get_xlim() == (0.0, 20.0)
    assert [line.get_label() for line in heat.get_lines()] == ["x"]
    assert list(study_figures(result)) == ["field_P1.png", "drift_P1.png"]


def axes_data(figure) -> list:
    """What each of ``figure``'s axes draws: its lines' points and its bands' outlines."""
    return [([line.get_xydata() for line in axes.get_lines()],
             [path.vertices for band in axes.collections for path in band.get_paths()]) for axes in figure.axes]


def test_a_study_s_notebook_figures_hold_each_pose_s_drift_figure_as_the_command_draws_it(written, tmp_path):
    """StudyResult.figures() (the result that holds the drifts; a PoseResult holds none, its figures() its field)
    gives drift_P1.png: the command's drawing (the same axes data as drift_figure's under the folder's title), saved
    the folder's bytes."""
    out, result = written
    figures = result.figures()
    assert list(figures) == ["field_P1.png", "drift_P1.png"]
    assert list(result.poses[0].figures()) == ["field_P1.png"]
    drawn = drift_figure(result.drifts[0], drift_title(result, result.drifts[0]))
    assert figures["drift_P1.png"]._suptitle.get_text() == drawn._suptitle.get_text() == "axis — P1: ISO 9283 " \
        "drift test, simulated"
    for (lines, bands), (drawn_lines, drawn_bands) in zip(axes_data(figures["drift_P1.png"]), axes_data(drawn),
                                                          strict=True):
        assert len(lines) == len(drawn_lines) > 0 and len(bands) == len(drawn_bands) > 0
        assert all(np.array_equal(a, b) for a, b in zip(lines + bands, drawn_lines + drawn_bands, strict=True))
    save_png(figures["drift_P1.png"], tmp_path / "drift_P1.png")
    assert (tmp_path / "drift_P1.png").read_bytes() == (out / "drift_P1.png").read_bytes()


def test_a_short_test_without_warming_joints_is_drawn_in_seconds_and_says_so():
    result = run_study(drift_axis({"law": "gaussian", "mean": 0.12, "std": 0.006}, duration_s=100.0, set_cycles=5))
    drift = result.drifts[0]
    assert drift.joints == () and drift.temperature_C.shape == (10, 0)
    heat = drift_figure(drift).axes[2]
    assert heat.get_xlabel().endswith("[s]") and "[°C]" in heat.get_ylabel()
    assert "temperatures not modelled" in heat.texts[0].get_text()


def test_no_drift_section_or_figure_without_drift(tmp_path):
    study = drift_axis(WARMING)
    del study["drift"]
    result = run_study(study)
    write_results(result, tmp_path / "out", report="light")
    assert result.drifts == () and not list((tmp_path / "out").glob("drift_*"))
    page = (tmp_path / "out" / "report.html").read_text(encoding="utf-8")
    assert "ISO 9283 drift" not in page and "dAP_p" not in page
