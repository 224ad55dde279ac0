"""`tribokin measure`: a measurement file -> ISO 9283 figures in run's folder shape (bad input: one line, exit 2)."""

from __future__ import annotations

import csv
import json
import tracemalloc

import numpy as np
import pytest

from helpers.command import in_process, tribokin
from tribokin.cli import main
from tribokin.maps import budget
from tribokin.measured import iso_figures
from tribokin.measurement.contract import file_size
from tribokin.measurement.figures import bootstrap_bytes

CENTRE_MM = np.array([500.0, 200.0, 300.0])
#: Commanded 10 µm below the measured barycentre of P1 "+" along x.
COMMANDED_MM = CENTRE_MM - [0.010, 0.0, 0.0]
#: P1 "+": l = 3, 3, 4, 4 µm about the barycentre CENTRE; "-": l = 2, 2 about CENTRE + 12 µm z.
#: P2 "+": l = 5, 5, 0 about CENTRE; "o": one cycle (too short for RP).
CYCLES_UM = {("P1", "+"): [[3, 0, 0], [-3, 0, 0], [0, 4, 0], [0, -4, 0]],
             ("P1", "-"): [[0, 0, 14], [0, 0, 10]],
             ("P2", "+"): [[5, 0, 0], [-5, 0, 0], [0, 0, 0]],
             ("P2", "o"): [[0, 30, 0]]}
#: RP_l = l_bar + 3 S_l (S_l with n - 1), by hand:
#: P1 "+": 3.5 + 3 sqrt(4 (0.5)^2 / 3) = 3.5 + sqrt(3); P1 "-": 2 + 0;
#: P2 "+": 10/3 + 3 sqrt(150/9 / 2) = 10/3 + 5 sqrt(3).
RP_L_UM = {("P1", "+"): 3.5 + np.sqrt(3), ("P1", "-"): 2.0, ("P2", "+"): 10 / 3 + 5 * np.sqrt(3)}
#: P1 pooled: barycentre 4 µm up z; l = 5, 5, sqrt(32), sqrt(32), 10, 6.
P1_POOLED_L = np.array([5, 5, np.sqrt(32), np.sqrt(32), 10, 6])


def measurement_file(folder, unit: str = "mm", times: bool = False, name: str = "tracker.csv", drop=None):
    """The known points as a measurement file in ``unit`` (``m`` or ``mm``), with ``t_s`` if ``times``."""
    scale = 1.0 if unit == "mm" else 1e-3
    header = ["pose", "direction", "cycle", f"x_{unit}", f"y_{unit}", f"z_{unit}", f"cx_{unit}", f"cy_{unit}",
              f"cz_{unit}"] + (["t_s"] if times else [])
    lines = [",".join(header)]
    t = 0.0
    for (pose, direction), offsets in CYCLES_UM.items():
        for cycle, offset in enumerate(offsets, start=1):
            t += 10.0
            measured_mm = CENTRE_MM + np.array(offset) * 1e-3
            cells = [pose, direction, str(cycle), *(repr(float(v * scale)) for v in (*measured_mm, *COMMANDED_MM))]
            cells += [repr(t)] if times else []
            lines.append(",".join(cells))
    path = folder / name
    path.write_text("# known points\n" + "\n".join(lines) + "\n", encoding="utf-8")
    return path


def read_rows(path):
    with open(path, newline="", encoding="utf-8") as handle:
        return list(csv.DictReader(handle))


@pytest.fixture(scope="module")
def measured(tmp_path_factory):
    folder = tmp_path_factory.mktemp("measure")
    done = tribokin("measure", measurement_file(folder, "m", times=True), "--out", folder / "out")
    assert done.returncode == 0, done.stderr
    return folder / "out", done.stdout


def test_known_points_give_the_hand_computed_figures(measured):
    out, stdout = measured
    summary = json.loads((out / "summary.json").read_text())
    poses = {p["name"]: p for p in summary["poses"]}
    for (pose, direction), rp_l in RP_L_UM.items():
        assert poses[pose]["directions"][direction]["RP_l_um"] == pytest.approx(rp_l, rel=1e-6)
    assert poses["P1"]["directions"]["+"]["AP_p_um"] == pytest.approx(10.0, rel=1e-6)
    assert poses["P1"]["directions"]["-"]["AP_p_um"] == pytest.approx(np.hypot(10, 12), rel=1e-6)
    assert poses["P1"]["vAP_p_um"] == pytest.approx(12.0, rel=1e-6)
    assert poses["P1"]["RP_l_all_directions_um"] == pytest.approx(
        P1_POOLED_L.mean() + 3 * P1_POOLED_L.std(ddof=1), rel=1e-6)
    low, high = poses["P1"]["directions"]["+"]["RP_l_95_um"]
    assert 0 < low < RP_L_UM[("P1", "+")] < high
    assert summary["settings"]["registration"]["made"] is False  # two poses cannot register a frame
    assert summary["settings"]["commanded_correction"]["made"] is False
    rows = read_rows(out / "poses.csv")
    assert [(r["name"], r["direction"]) for r in rows] == list(CYCLES_UM)
    assert float(rows[0]["RP_l_um"]) == pytest.approx(RP_L_UM[("P1", "+")], rel=1e-6)
    assert float(rows[1]["vAP_p_um"]) == pytest.approx(12.0, rel=1e-6)
    assert {"RP_l_95_low_um", "RP_l_95_high_um", "ellipsoid_semi_axis_1_um", "barycenter_x_m",
            "RP_l_all_directions_um"} <= set(rows[0])
    assert "P1" in stdout and "registration (auto): the measuring frame is not registered" in stdout


def test_one_cycle_series_is_reported_too_short_not_refused(measured):
    out, stdout = measured
    direction = json.loads((out / "summary.json").read_text())["poses"][1]["directions"]["o"]
    assert direction["too_short_for_RP"] is True and direction["RP_l_um"] is None
    row = read_rows(out / "poses.csv")[3]
    assert (row["direction"], row["too_short_for_RP"], row["RP_l_um"]) == ("o", "True", "")
    assert "too short" in stdout


def test_times_give_drift_and_its_plot(measured):
    out, stdout = measured
    drift = json.loads((out / "summary.json").read_text())["poses"][0]["drift"]
    # P1 "+" in sets of 2: RP_l of cycles 1, 2 is 3 µm, of cycles 3, 4 is 4 µm
    assert [d["direction"] for d in drift] == ["+"] and drift[0]["dRP_l_um"] == pytest.approx(1.0, rel=1e-6)
    assert {p.name for p in out.iterdir()} == {"summary.json", "poses.csv", "field_P1.png", "field_P2.png",
                                              "drift.png", "report.html"}
    assert "field_P1.png" in (out / "report.html").read_text()
    assert f"results in {out}/ (summary.json, poses.csv, field_*.png, drift.png, report.html)\n" in stdout


def test_units_in_column_names_are_honoured(measured, tmp_path):
    out_m, _ = measured
    done = in_process("measure", measurement_file(tmp_path, "mm"), "--out", tmp_path / "mm", "--report", "none")
    assert done.returncode == 0 and done.stdout.endswith(f"results in {tmp_path / 'mm'}/ (summary.json, poses.csv, "
                                                         "field_*.png)\n")  # no times: no drift figure
    in_mm = read_rows(tmp_path / "mm" / "poses.csv")
    in_m = read_rows(out_m / "poses.csv")
    for a, b in zip(in_mm, in_m, strict=True):
        for key in ("RP_l_um", "AP_p_um", "vAP_p_um", "RP_l_all_directions_um", "barycenter_x_m"):
            assert (a[key] == b[key] == "") or float(a[key]) == pytest.approx(float(b[key]), rel=1e-9)
    assert not (tmp_path / "mm" / "report.html").exists()


def test_same_bytes_on_two_runs(tmp_path):
    path = measurement_file(tmp_path, "mm", times=True)
    for out in ("a", "b"):
        assert main(["measure", path, "--out", tmp_path / out, "--seed", 4]) == 0
    files = sorted(p.name for p in (tmp_path / "a").iterdir())
    assert files == sorted(p.name for p in (tmp_path / "b").iterdir())
    for name in files:
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes(), name


def test_seed_moves_only_the_bootstrap(tmp_path):
    offsets = np.random.default_rng(1).normal(0, 5e-3, (12, 3))  # 12 cycles [mm]
    path = tmp_path / "many.csv"
    path.write_text("pose,cycle,x_mm,y_mm,z_mm\n" + "".join(
        f"P1,{k + 1},{','.join(repr(float(v)) for v in CENTRE_MM + d)}\n" for k, d in enumerate(offsets)))
    for out, seed in (("a", 1), ("b", 2)):
        assert main(["measure", path, "--out", tmp_path / out, "--seed", seed, "--report", "none"]) == 0
    a, b = (json.loads((tmp_path / out / "summary.json").read_text())["poses"][0]["directions"]["+"]
            for out in "ab")
    assert a["RP_l_95_um"] != b["RP_l_95_um"] and a["RP_l_um"] == b["RP_l_um"]


def test_noise_floor_flags_figures_within_twice_its_spread(tmp_path, capsys):
    still = tmp_path / "still.csv"
    # l = 1.5 µm for every reading: the floor's RP_l is 1.5 µm; P1 "-" (RP_l 2 µm) is within 2x, P1 "+" is not
    still.write_text("x_mm,y_mm,z_mm\n" + "".join(f"{500 + dx * 1e-3!r},200.0,300.0\n"
                                                  for dx in (1.5, -1.5, 1.5, -1.5)))
    assert main(["measure", measurement_file(tmp_path), "--out", tmp_path / "out", "--noise-floor", still,
                 "--report", "none"]) == 0
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["settings"]["noise_floor"]["RP_l_um"] == pytest.approx(1.5, rel=1e-6)
    directions = summary["poses"][0]["directions"]
    assert "RP_l_um" in directions["-"]["noise_flags"] and "RP_l_um" not in directions["+"]["noise_flags"]
    assert "RP_l_um" in read_rows(tmp_path / "out" / "poses.csv")[1]["noise_flags"].split()
    assert "P1 - RP_l_um" in capsys.readouterr().out


def stream_file(folder):
    """A raw stream at 10 Hz: home (once), then A, B, A, B, each held 2 s, moved between in 1 s."""
    stops = {"home": [0.0, 0.0, 0.5], "A": [0.4, 0.1, 0.3], "B": [0.4, -0.1, 0.3]}
    order = ["home", "A", "B", "A", "B"]
    rng = np.random.default_rng(0)
    times, points = [], []
    t = 0.0
    for k, stop in enumerate(order):
        for _ in range(20):
            times.append(t)
            points.append(np.array(stops[stop]) + rng.normal(0, 5e-6, 3))
            t += 0.1
        if k + 1 < len(order):
            for s in np.linspace(0, 1, 12)[1:-1]:
                times.append(t)
                points.append((1 - s) * np.array(stops[stop]) + s * np.array(stops[order[k + 1]]))
                t += 0.1
    path = folder / "stream.csv"
    path.write_text("t_s,x_m,y_m,z_m\n" + "".join(f"{ti!r},{float(p[0])!r},{float(p[1])!r},{float(p[2])!r}\n"
                                                   for ti, p in zip(times, points, strict=True)))
    return path


def test_segment_finds_dwells_labels_them_and_reports_the_unmatched(tmp_path, capsys):
    assert main(["measure", stream_file(tmp_path), "--segment", "--out", tmp_path / "out", "--report", "none"]) == 0
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    segmentation = summary["settings"]["segmentation"]
    assert segmentation["dwells"] == 5 and len(segmentation["unmatched"]) == 1
    assert segmentation["unmatched"][0]["position_m"] == pytest.approx([0.0, 0.0, 0.5], abs=1e-4)
    assert [(p["name"], p["directions"]["+"]["cycles"]) for p in summary["poses"]] == [("P1", 2), ("P2", 2)]
    printed = capsys.readouterr().out
    assert "dwells: radius 0.0001 m for 1 s" in printed and "unmatched dwell" in printed


@pytest.mark.parametrize("edit, key", [
    (lambda text: "".join(line.rsplit(",", 1)[0] + "\n" for line in text.splitlines()), "cz_m"),  # missing column
    (lambda text: text.replace("pose,direction,cycle,x_mm,y_mm,z_mm", "pose,direction,cycle,x_mm,y_m,z_mm"),
     "x_mm"),                                                                          # mixed units
    (lambda text: text.replace("P1,+,2,", "P1,+,2,abc", 1).replace(",abc500.0", ",abc", 1), "x_mm"),  # not a number
    (lambda text: text.replace("P1,+,2,", "P1,+,1,", 1), "cycle"),                     # duplicate row
    (lambda text: text + "P3,+,1,1.0,2.0,3.0,1.0,2.0,3.0\n", "pose"),                  # no series of two cycles
    (lambda text: text.replace("P2,", "p1,"), "pose 'p1'"),          # P1 and p1: one field_P1.png on macOS, Windows
])
def test_contract_errors_are_one_line_exit_2_nothing_written(tmp_path, capsys, edit, key):
    path = measurement_file(tmp_path)
    path.write_text(edit(path.read_text()))
    assert main(["measure", path, "--out", tmp_path / "out"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"tribokin: error: {path}: ") and f": {key}: " in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["tracker.csv"]


def test_an_existing_output_folder_is_kept_without_force(measured):
    out, _ = measured
    before = (out / "summary.json").read_bytes()
    done = in_process("measure", out.parent / "tracker.csv", "--out", out)
    assert done.returncode == 2 and "--out: output folder exists" in done.stderr
    assert (out / "summary.json").read_bytes() == before


@pytest.mark.parametrize("options, key", [
    (["--dwell-radius-m", "1e-3"], "--dwell-radius-m"),
    (["--segment", "--dwell-min-s", "0"], "--dwell-min-s"),
])
def test_segment_options_are_checked(tmp_path, capsys, options, key):
    assert main(["measure", stream_file(tmp_path), "--out", tmp_path / "out", *options]) == 2
    assert f"command line: {key}: " in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["stream.csv"]


def _long_series(folder, cycles: int):
    """One pose, one direction, ``cycles`` cycles about CENTRE_MM (scatter of 5 µm)."""
    points = CENTRE_MM + np.random.default_rng(2).normal(scale=5e-3, size=(cycles, 3))
    lines = ["pose,cycle,x_mm,y_mm,z_mm"] + [f"P1,{i + 1},{x!r},{y!r},{z!r}" for i, (x, y, z) in
                                            enumerate(points.tolist())]
    path = folder / "long.csv"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def test_a_file_beyond_the_memory_is_refused_before_it_is_read(tmp_path, capsys, monkeypatch):
    path = _long_series(tmp_path, 1000)
    size = file_size(path)
    monkeypatch.setattr(budget, "available_bytes", lambda: size.reading_bytes // 2)  # a machine of little memory
    monkeypatch.setattr(iso_figures, "read_measurements", None)  # never reached
    assert main(["measure", path, "--out", tmp_path / "out"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"tribokin: error: {path}: rows: measuring this file needs about")
    assert "of memory (mostly" in err and "is available: split it into several files" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["long.csv"]


def test_measuring_takes_no_more_memory_than_the_estimate(tmp_path):
    """A series of 5 000 cycles: what measure allocates (tracemalloc, NumPy's arrays included) stays within the
    estimate it checks, which is below the 2000 resamples' positions held at once before (240 MB)."""
    path = _long_series(tmp_path, 5_000)
    tracemalloc.start()
    iso_figures.measure(path).write(tmp_path / "out", report="none")
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    size = file_size(path)
    estimate = size.reading_bytes + bootstrap_bytes(size.lines) + iso_figures.DRAWN_BYTES_PER_ROW * size.lines
    assert peak <= estimate < 2000 * 5_000 * 24
