"""A study that needs more memory than the machine has is refused up front, with the estimate."""

import time
import tracemalloc

import numpy as np
import pytest

from conftest import ROOT, axis_study
from tribokin import InputError, load_study, run_study
from tribokin.cli import main
from tribokin.maps.budget import available_bytes, estimate
from tribokin.units import gib

GANTRY_MAP = {
    "study": {"cycles": 5},
    "robot": {"urdf": str(ROOT / "urdf" / "cartesian_xyz.urdf"), "tool_frame": "tool"},
    "joints": {"friction": {"preset": "42CD4-raw"}, "stiffness": 2e7, "normal_force_N": 100.0},
    "map": {"kind": "box", "min_m": [0.2, 0.0, 0.2], "max_m": [0.8, 0.6, 0.7], "resolution": [4, 3, 2]},
}


def test_available_memory_is_known_and_plausible():
    available = available_bytes()
    assert available is not None and 10 * 2 ** 20 < available < 2 ** 50


def test_estimate_counts_every_cycle_of_every_pose_and_every_map_target():
    study = load_study(axis_study())
    (size, key, what), = estimate(study, 1, [1])
    assert key == "study.cycles" and "30 cycles × 1 pose × 1 joint" in what
    bigger = load_study(axis_study(), cycles=3000)
    (size_3000, _, _), = estimate(bigger, 1, [1])
    assert size_3000 == 100 * size  # linear in cycles
    (two_poses, _, _), = estimate(bigger, 1, [1, 1])
    assert size_3000 < two_poses < 2 * size_3000  # the second pose's samples are kept; the computing is not doubled
    (two_directions, _, _), = estimate(bigger, 1, [2])
    assert two_directions == 2 * size_3000  # every direction's cycles are kept and computed at once
    gantry = load_study(GANTRY_MAP)
    assert gantry.map.target_count == 24
    parts = {key: size for size, key, _ in estimate(gantry, 3, [])}
    assert set(parts) == {"map.resolution", "study.cycles"}
    # the map's results are on disk: memory holds a chunk and a warm start per grid row, whatever the row length
    longer_rows = load_study({**GANTRY_MAP, "map": {**GANTRY_MAP["map"], "resolution": [40, 3, 2], "chunk_rows": 1}})
    more_rows = load_study({**GANTRY_MAP, "map": {**GANTRY_MAP["map"], "resolution": [40, 300, 200], "chunk_rows": 1}})
    held = [{key: size for size, key, _ in estimate(s, 3, [])}["map.resolution"] for s in (longer_rows, more_rows)]
    assert held[1] - held[0] == 3 * 8 * 3 * (300 * 200 - 3 * 2)  # 3 copies of 3 joint values per extra row


def test_a_map_whose_results_would_not_fit_on_disk_is_refused(tmp_path, monkeypatch):
    from collections import namedtuple

    from tribokin.maps.budget import check_disk
    from tribokin.maps.schema import MapLayout

    gantry = load_study(GANTRY_MAP)
    needed = 24 * MapLayout.shared(3, 1, gantry.map.figure_set).bytes_per_target
    usage = namedtuple("usage", "total used free")
    monkeypatch.setattr("shutil.disk_usage", lambda path: usage(needed, 0, needed))
    check_disk(gantry, 3, tmp_path / "not" / "yet" / "made")
    monkeypatch.setattr("shutil.disk_usage", lambda path: usage(needed, 1, needed - 1))
    with pytest.raises(InputError) as error:
        check_disk(gantry, 3, tmp_path / "not" / "yet" / "made")
    assert error.value.key == "map.resolution" and "24 map targets" in error.value.message
    assert str(tmp_path) in error.value.message  # the folder whose disk is full


@pytest.mark.parametrize("size, text", [(48 * 2 ** 30, "48 GiB"), (310 * 2 ** 20, "310 MiB"), (3 * 2 ** 40, "3 TiB"),
                                        (1030 * 2 ** 40, "1030 TiB"), (1000, "0.00095 MiB")])
def test_sizes_read_in_binary_units(size, text):
    assert gib(size) == text


def _refused_fast(mapping, key, tmp_path, capsys, *options):
    """Run ``mapping`` (as a study file) through the command line: refused in well under a second of work,
    allocating next to nothing, one line naming ``key`` and the estimate."""
    study = tmp_path / "huge.toml"
    study.write_text(_toml(mapping))
    tracemalloc.start()
    start = time.perf_counter()
    status = main(["run", str(study), "--out", str(tmp_path / "out"), *options])
    elapsed = time.perf_counter() - start
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    err = capsys.readouterr().err
    assert status == 2 and len(err.splitlines()) == 1, err
    assert key in err and "needs about" in err and "available" in err
    assert elapsed < 10 and peak < 100 * 2 ** 20
    assert sorted(p.name for p in tmp_path.iterdir()) == ["huge.toml"]
    return err


def _toml(mapping: dict) -> str:
    """A (flat enough) mapping as TOML: tables of scalars, lists and inline tables."""
    def value(v):
        if isinstance(v, dict):
            return "{ " + ", ".join(f"{k} = {value(x)}" for k, x in v.items()) + " }"
        if isinstance(v, list):
            return "[" + ", ".join(value(x) for x in v) + "]"
        return f'"{v}"' if isinstance(v, str) else repr(v)
    lines = []
    for section, table in mapping.items():
        for entry in table if isinstance(table, list) else [table]:
            lines.append(f"[[{section}]]" if isinstance(table, list) else f"[{section}]")
            lines += [f"{k} = {value(v)}" for k, v in entry.items()]
    return "\n".join(lines) + "\n"


def test_huge_cycles_are_refused_up_front(tmp_path, capsys):
    mapping = axis_study()
    mapping["study"]["cycles"] = 10 ** 12
    err = _refused_fast(mapping, "study.cycles", tmp_path, capsys)
    assert "1,000,000,000,000 cycles × 1 pose × 1 joint" in err and "TiB" in err
    assert str(tmp_path / "huge.toml") in err


def test_huge_cycles_from_the_command_line_name_the_option(tmp_path, capsys):
    err = _refused_fast(axis_study(), "--cycles", tmp_path, capsys, "--cycles", str(10 ** 12))
    assert "command line: --cycles" in err


def test_huge_map_resolution_is_refused_up_front(tmp_path, capsys):
    mapping = {**GANTRY_MAP, "map": {**GANTRY_MAP["map"], "resolution": [100_000, 100_000, 100]}}
    err = _refused_fast(mapping, "map.resolution", tmp_path, capsys)
    assert "1,000,000,000,000 map targets" in err


def test_a_study_that_fits_runs_and_one_that_does_not_is_refused(monkeypatch):
    study = axis_study()
    study["study"]["cycles"] = 1000
    (needed, _, _), = estimate(load_study(study), 1, [1])
    monkeypatch.setattr("tribokin.maps.budget.available_bytes", lambda: needed)
    assert run_study(study).poses[0].cycles == 1000
    monkeypatch.setattr("tribokin.maps.budget.available_bytes", lambda: needed - 1)
    with pytest.raises(InputError) as error:
        run_study(study)
    assert error.value.key == "study.cycles" and "lower study.cycles" in error.value.message


def test_a_map_with_friction_time_keys_counts_its_whole_sampled_tests():
    """Where a joint's friction is a time series, an expected map's worker holds its sampled tests whole: the estimate
    counts them (twice with ``compare``), and they hold more than what tracemalloc measures of a scenario's setup and
    a block of targets' figures drawn from them (the gantry, 10 cycles: 2 000 tests, the band's at most 16 times)."""
    from tribokin.maps.budget import series_bytes
    from tribokin.maps.expected_figures import ExpectedSetup, expected_targets
    from tribokin.maps.mapping import series_runner
    from tribokin.propagation.exact import tool_frames
    from tribokin.study.assembly import joint_models, load_robot, study_runner

    friction = {"preset": "42CD4-raw", "ar1": 0.9, "run_in": {"start": 0.3, "tau_cycles": 40.0}}
    mapping = {**GANTRY_MAP, "study": {**GANTRY_MAP["study"], "cycles": 10},
               "joints": {**GANTRY_MAP["joints"], "friction": friction},
               "map": {**GANTRY_MAP["map"], "directional": False, "state": "cold"}}
    plain = {key: size for size, key, _ in estimate(load_study({**mapping, "joints": GANTRY_MAP["joints"],
                                                                "map": GANTRY_MAP["map"]}), 3, [])}
    series = load_study(mapping)
    parts = [size for size, _, what in estimate(series, 3, []) if "friction series" in what]
    assert parts == [series_bytes(10, 3, False)] and series_bytes(10, 3, True) > parts[0]
    assert sum(plain.values()) < sum(size for size, _, _ in estimate(series, 3, []))
    robot = load_robot(series)
    runner = series_runner(study_runner(series, robot, joint_models(series, robot)), None, np.zeros((1, 3)))
    qs = np.array([[0.2, 0.2, 0.1], [0.3, 0.1, 0.2]])
    twists, translations = tool_frames(robot, qs)
    tracemalloc.start()
    setup = ExpectedSetup.build(runner, None, "expected")
    expected_targets(runner, setup, qs, runner.normal_forces_at(qs), twists, translations)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert setup.series and peak < parts[0], (peak, parts[0])
