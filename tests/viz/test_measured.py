"""Figures and report page of measured data."""

from __future__ import annotations

import numpy as np

from tribokin.measurement.contract import Rows, assemble
from tribokin.measurement.figures import measurement_figures, pose_clouds
from tribokin.viz.measured import measurement_report_html, save_measured_field


def test_field_of_a_pose_with_a_one_cycle_series(tmp_path):
    rows = Rows(lines=np.arange(2, 6), poses=("P<1>",) * 4, directions=("+", "+", "+", "o"),
                cycles=np.array([1, 2, 3, 1]), positions_m=np.array([[0, 0, 0], [3e-6, 0, 0], [0, 2e-6, 0],
                                                                      [0, 0, 5e-6]], dtype=float))
    pose = assemble("stream", rows).poses[0]
    figures = measurement_figures(assemble("stream", rows))[0]
    save_measured_field(figures, pose_clouds(pose, None).positions_m, tmp_path / "field.png", "a $title$")
    assert (tmp_path / "field.png").read_bytes()[:4] == b"\x89PNG"


def test_report_page_escapes_names_and_shows_the_interval(tmp_path):
    settings = {"file": "t<x>.csv", "sha256": "ab", "columns": ["pose"], "segmentation": None,
                "registration": {"made": False, "why": "no commanded positions"},
                "commanded_correction": {"made": False, "why": "no commanded positions", "largest_spread_um": None},
                "bootstrap": {"seed": 1}, "noise_floor": None}
    row = {"name": "P<1>", "direction": "+", "cycles": 4, "RP_l_um": 5.0, "RP_l_95_um": [2.5, 9.0],
           "AP_p_um": None, "vAP_p_um": None, "RP_l_all_directions_um": 5.0, "RP_a_mdeg": None,
           "RP_b_mdeg": None, "RP_c_mdeg": None, "noise_flags": ""}
    page = measurement_report_html({"settings": settings}, [row], tmp_path, [])
    assert "P&lt;1&gt;" in page and "t&lt;x&gt;.csv" in page and "P<1>" not in page
    assert "2.500–9.000" in page and "RP_l 95 % interval [µm]" in page
