"""A one-test map agrees with what tribokin wrote before expected maps, the batched IK and the batched kinematics
(``tests/data/one-test-reference-map.csv``, from commit 4c66137): to 1e-6 relative at every target whose
configuration agrees to 1e-9 rad (rounding-level differences of the IK and kinematics; seen: 1.5e-11)."""

import csv

import numpy as np

from conftest import ROOT
from tribokin import run_study
from tribokin.output.writers import write_map_table

REFERENCE = ROOT / "tests" / "data" / "one-test-reference-map.csv"
STUDY = {
    "study": {"name": "one-test-reference", "cycles": 20, "seed": 9283},
    "robot": {"name": "ur5", "payload_kg": 3.0},
    "joints": {"friction": {"preset": "42CD4-raw"}, "stiffness": 1.0e5, "friction_radius_m": 0.02,
               "bearing_span_m": 0.08},
    "map": {"kind": "plane", "origin_m": [0.0, -0.55, 0.1], "axis_u": [1, 0, 0], "axis_v": [0, 1, 0],
            "extent_u_m": [-0.6, 0.6], "extent_v_m": [-0.35, 0.35], "resolution": [25, 15], "rpy_deg": [180, 0, 90],
            "statistic": "one-test"},
}
FIGURES = ("RP_l_um", "AP_p_um", "RP_a_mdeg", "RP_b_mdeg", "RP_c_mdeg", "largest_semi_axis_um", "dominant_share")


def read_rows(path) -> list[dict]:
    with open(path, newline="") as handle:
        return list(csv.DictReader(line for line in handle if not line.startswith("#")))


def test_one_test_figures_agree_with_the_engine_before_expected_maps(tmp_path):
    result = run_study(STUDY)
    write_map_table(result.map, result.map.reference, tmp_path / "map.csv")
    before, now = read_rows(REFERENCE), read_rows(tmp_path / "map.csv")
    assert len(before) == len(now) == 375
    assert [row["reachable"] for row in before] == [row["reachable"] for row in now]
    joints = [name for name in before[0] if name.startswith("q_")]
    compared = moved = 0
    for old, new in zip(before, now):
        if old["reachable"] != "true":
            continue
        if max(abs(float(old[q]) - float(new[q])) for q in joints) > 1e-9:
            moved += 1
            continue
        compared += 1
        assert old["dominant_joint"] == new["dominant_joint"]
        np.testing.assert_allclose([float(new[f]) for f in FIGURES], [float(old[f]) for f in FIGURES], rtol=1e-6)
    assert compared > 300 and moved <= 2
