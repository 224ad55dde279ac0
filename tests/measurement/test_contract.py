"""The measurement file: units honoured, series grouped, every rule of the contract a one-line error."""

from __future__ import annotations

import numpy as np
import pytest

from helpers.measurement_files import write_csv
from tribokin.errors import InputError
from tribokin.measurement.contract import read_measurements, read_stream

HEADER = "pose,direction,cycle,x_mm,y_mm,z_mm"
ROWS = ["P1,+x,1,100.0,200.0,300.0", "P1,+x,2,100.003,200.0,300.0", "P1,-x,1,100.010,200.0,300.0"]


def test_units_in_the_names_are_honoured_and_comments_skipped(tmp_path):
    in_mm = read_measurements(write_csv(tmp_path, HEADER, ROWS, "mm.csv"))
    in_m = read_measurements(write_csv(tmp_path, "pose,direction,cycle,x_m,y_m,z_m",
                                       ["P1,+x,1,0.1,0.2,0.3", "P1,+x,2,0.100003,0.2,0.3", "P1,-x,1,0.10001,0.2,0.3"],
                                       "m.csv", comments=("# a", "# b")))
    for mm, m in zip(in_mm.poses[0].series, in_m.poses[0].series, strict=True):
        np.testing.assert_allclose(mm.positions_m, m.positions_m, rtol=1e-12)
    assert in_mm.poses[0].series[0].positions_m[1, 0] == pytest.approx(0.100003)
    assert in_mm.poses[0].series[0].lines.tolist() == [3, 4]  # line numbers of the file, comments counted


def test_the_columns_found_are_kept_in_file_order(tmp_path):
    assert read_measurements(write_csv(tmp_path, HEADER, ROWS)).columns == tuple(HEADER.split(","))


def test_series_grouped_by_direction_in_cycle_order_and_optional_columns_converted(tmp_path):
    header = "pose,direction,cycle,x_m,y_m,z_m,a_deg,b_deg,c_deg,cx_mm,cy_mm,cz_mm,sx_mm,sy_mm,sz_mm,t_s"
    rows = ["P1,-,2,1,2,3,90,0,0,1000,2000,3000,0.01,0.01,0.02,4",
            "P1,+,1,1,2,3,90,0,0,1000,2000,3000,0.01,0.01,0.02,1",
            "P1,-,1,1,2,3,90,0,0,1000,2000,3000,0.01,0.01,0.02,3",
            "P1,+,2,1,2,3,90,0,0,1000,2000,3000,0.01,0.01,0.02,2"]
    pose = read_measurements(write_csv(tmp_path, header, rows)).poses[0]
    assert [s.direction for s in pose.series] == ["-", "+"]
    minus = pose.series[0]
    assert minus.cycles.tolist() == [1, 2] and minus.times_s.tolist() == [3.0, 4.0]
    np.testing.assert_allclose(minus.angles_rad[0], [np.pi / 2, 0, 0])
    np.testing.assert_allclose(minus.commanded_m[0], [1.0, 2.0, 3.0])
    np.testing.assert_allclose(minus.std_m[0], [1e-5, 1e-5, 2e-5])
    with pytest.raises(ValueError):
        minus.positions_m[0, 0] = 5.0  # read-only


def test_a_byte_order_mark_before_the_header_is_not_part_of_a_name(tmp_path):
    path = tmp_path / "excel.csv"
    path.write_bytes("pose,cycle,x_m,y_m,z_m\nA,1,0,0,0\nA,2,0,0,0\n".encode("utf-8-sig"))
    assert read_measurements(path).poses[0].name == "A"


def test_direction_defaults_to_plus(tmp_path):
    measurements = read_measurements(write_csv(tmp_path, "pose,cycle,x_m,y_m,z_m", ["A,1,0,0,0", "A,2,0,0,1e-6"]))
    assert [s.direction for s in measurements.poses[0].series] == ["+"]


def test_one_cycle_series_beside_a_longer_one_is_kept_and_marked_too_short(tmp_path):
    pose = read_measurements(write_csv(tmp_path, HEADER, ROWS)).poses[0]
    assert [(s.direction, s.too_short) for s in pose.series] == [("+x", False), ("-x", True)]
    assert pose.pooled("positions_m").shape == (3, 3)


@pytest.mark.parametrize("header, rows, key, words", [
    ("pose,cycle,x_m,y_m", ["P,1,0,0", "P,2,0,0"], "z_m", "missing column"),
    ("cycle,x_m,y_m,z_m", ["1,0,0,0"], "pose", "missing column"),
    ("pose,x_m,y_m,z_m", ["P,0,0,0"], "cycle", "missing column"),
    ("pose,cycle,a_deg", ["P,1,0"], "x_m", "missing column"),
    ("pose,cycle,x_m,y_mm,z_m", ["P,1,0,0,0", "P,2,0,0,0"], "x_m", "mixed units"),
    ("pose,cycle,x_m,y_m,z_m,x_mm", ["P,1,0,0,0,0"], "x_mm", "two units"),
    ("pose,cycle,x_m,y_m,z_m,cx_m,cy_mm,cz_m", ["P,1,0,0,0,0,0,0"], "cx_m", "mixed units"),
    ("pose,cycle,x_m,y_m,z_m", ["P,1,0,0,0", "P,2,0,abc,0"], "y_m", "line 4, column 4: expected a finite number"),
    ("pose,cycle,x_m,y_m,z_m", ["P,1,0,0,0", "P,2,0,nan,0"], "y_m", "line 4"),
    ("pose,cycle,x_m,y_m,z_m,t_s", ["P,1,0,0,0,", "P,2,0,0,0,1"], "t_s", "line 3 is empty"),
    ("pose,cycle,x_m,y_m,z_m", ["P,1,0,0,0", "P,1.5,0,0,0"], "cycle", "whole numbers"),
    ("pose,cycle,x_m,y_m,z_m", ["P,1,0,0,0", "P,2,0,0,0", "P,1,0,0,1"], "cycle", "lines 3 and 5"),
    ("pose,cycle,x_m,y_m,z_m", ["P,1,0,0,0", "P,2,0,0,0", "Q,1,1,0,0"], "pose", "pose 'Q'"),
    ("pose,cycle,x_m,y_m,z_m,x_cm", ["P,1,0,0,0,0"], None, "line 2, column 6: unknown column (did you mean"),
    ("pose,cycle,x_m,y_m,z_m,x_m", ["P,1,0,0,0,0"], None, "line 2: columns 3 and 6 have the same name"),
    ("pose,cycle,x_m,y_m,z_m", ["P,1,0,0,0", "P,2,0,0,0,5"], None, "line 4 has 6 cells, the header 5"),
    ("pose;cycle;x_m;y_m;z_m", ["P;1;0,5;0;0"], None, "separated by ';'"),
])
def test_each_rule_of_the_contract_is_a_one_line_error(tmp_path, header, rows, key, words):
    path = write_csv(tmp_path, header, rows)
    with pytest.raises(InputError) as caught:
        read_measurements(path)
    assert caught.value.source == str(path) and caught.value.key == key
    assert words in caught.value.message and "\n" not in caught.value.one_line()


def test_duplicate_cycle_counts_per_direction_only(tmp_path):
    rows = ["P,+,1,0,0,0", "P,+,2,0,0,0", "P,-,1,0,0,0", "P,-,2,0,0,0"]
    pose = read_measurements(write_csv(tmp_path, "pose,direction,cycle,x_m,y_m,z_m", rows)).poses[0]
    assert len(pose.series) == 2


def test_joint_spread_above_the_limit_is_refused_naming_the_pose(tmp_path):
    header = "pose,cycle,x_m,y_m,z_m,q_shoulder,q_slide"
    fine = write_csv(tmp_path, header, ["A,1,0,0,0,0.5,0.1", "A,2,0,0,0,0.509,0.1009"], "fine.csv")
    pose = read_measurements(fine, prismatic=("slide",)).poses[0]
    np.testing.assert_allclose(pose.q, [0.5045, 0.10045])
    assert pose.q_spread == pytest.approx(0.009)
    wide = write_csv(tmp_path, header, ["A,1,0,0,0,0.5,0.1", "B,1,1,0,0,0.0,0.1", "B,2,1,0,0,0.02,0.1",
                                        "A,2,0,0,0,0.5,0.1"], "wide.csv")
    with pytest.raises(InputError) as caught:
        read_measurements(wide)
    assert caught.value.key == "q_shoulder" and "pose 'B'" in caught.value.message
    slid = write_csv(tmp_path, header, ["A,1,0,0,0,0.5,0.1", "A,2,0,0,0,0.5,0.1012"], "slid.csv")
    with pytest.raises(InputError, match="q_slide.*0.0012 m"):
        read_measurements(slid, prismatic=("slide",))
    assert read_measurements(slid).poses[0].q_spread == pytest.approx(0.0012)  # taken as an angle: within 0.01 rad


def test_continuous_joint_takes_a_circular_mean_across_pi(tmp_path):
    path = write_csv(tmp_path, "pose,cycle,x_m,y_m,z_m,q_wrist",
                     [f"A,1,0,0,0,{np.pi - 0.001}", f"A,2,0,0,0,{-np.pi + 0.001}"])
    with pytest.raises(InputError, match="q_wrist"):
        read_measurements(path)
    pose = read_measurements(path, continuous=("wrist",)).poses[0]
    assert abs(pose.q[0]) == pytest.approx(np.pi) and pose.q_spread == pytest.approx(0.002)


def test_raw_stream_needs_increasing_times(tmp_path):
    stream = read_stream(write_csv(tmp_path, "t_s,x_mm,y_mm,z_mm", ["0,1,2,3", "0.1,1,2,3"]))
    np.testing.assert_allclose(stream.positions_m[0], [1e-3, 2e-3, 3e-3])
    assert stream.lines.tolist() == [3, 4]
    with pytest.raises(InputError, match="line 4: times must increase"):
        read_stream(write_csv(tmp_path, "t_s,x_m,y_m,z_m", ["0,1,2,3", "0,1,2,3"], "back.csv"))
    with pytest.raises(InputError) as caught:
        read_stream(write_csv(tmp_path, "x_m,y_m,z_m", ["1,2,3"], "untimed.csv"))
    assert caught.value.key == "t_s"
    assert read_stream(tmp_path / "untimed.csv", require_time=False).times_s is None


@pytest.mark.parametrize("header, row, key, message", [
    ("pose,direction,cycle,x_mm,y_mm,z_mm", "P1,+x,2,2e6,200.0,300.0", "x_mm", "outside [-1000, 1000] m"),
    ("pose,direction,cycle,x_m,y_m,z_m", "P1,+x,2,1e300,0.2,0.3", "x_m", "a kilometre away"),
    ("pose,direction,cycle,x_mm,y_mm,z_mm,a_deg,b_deg,c_deg", "P1,+x,2,100,200,300,0,400,0", "b_deg", "one turn"),
    ("pose,direction,cycle,x_mm,y_mm,z_mm,sx_mm,sy_mm,sz_mm", "P1,+x,2,100,200,300,0,-1e-3,0", "sy_mm",
     "outside [0, 1] m"),
    ("pose,direction,cycle,x_mm,y_mm,z_mm,q_j1", "P1,+x,2,100,200,300,1e5", "q_j1", "160 times"),
])
def test_values_outside_their_physical_range_are_one_line_errors(tmp_path, header, row, key, message):
    """Numeric extremes (1e300, a unit slip of mm for m) are refused before any figure overflows."""
    extra = ",0,0,0" if "a_deg" in header or "sx_mm" in header else (",0" if "q_j1" in header else "")
    first = "P1,+x,1,100,200,300" + extra
    with pytest.raises(InputError) as error:
        read_measurements(write_csv(tmp_path, header, [first, row]))
    assert error.value.key == key and message in error.value.message
