"""Maps give the same bytes whatever the chunk size, the workers, the executor, or an interruption."""

import json
import shutil
import signal
import subprocess
import sys
import time
from contextlib import suppress
from pathlib import Path

import numpy as np
import pytest

from conftest import GANTRY_MAP_TOML, GANTRY_SAMPLED_MAP_TOML
from helpers.command import in_process
from helpers.dask_cluster import local_cluster
from tribokin import InputError, run_study
from tribokin.cli import main
from tribokin.compiled import kernels_used
from tribokin.execution import executor_for
from tribokin.maps.expected_figures import ANALYTIC, SAMPLED
from tribokin.maps.store import ChunkStore
from tribokin.output.writers import map_table_name, write_map_table, write_results, write_summary

UR5_MAP = {
    "study": {"name": "ur5-map", "cycles": 60, "seed": 5},
    "robot": {"name": "ur5", "payload_kg": 2.0},
    "joints": {"friction": {"preset": "42CD4-raw"}, "stiffness": 1.0e5, "bearing_span_m": 0.08},
    # reaches out of the workspace at large u: some targets are unreachable
    "map": {"kind": "plane", "origin_m": [0.0, -0.5, 0.1], "axis_u": [0, -1, 0], "axis_v": [0, 0, 1],
            "extent_u_m": [-0.2, 0.45], "extent_v_m": [0.0, 0.3], "resolution": [7, 5], "chunk_rows": 1},
    "scenarios": [{"name": "raw"}, {"name": "treated-shoulder",
                                    "joints": {"shoulder_lift_joint": {"friction": {"preset": "42CD4-treated"}}}}],
}
#: Scenarios measured with robots of their own: another robot, and the study's moved and turned on its table.
#: The UR10's figures sampled (the raw steel's uniform law), the others' in closed form (:data:`VARIANTS`).
OTHER_ROBOTS = [{"name": "ur10", "robot": {"name": "ur10"}, "joints": {"friction": {"preset": "42CD4-raw"}}},
                {"name": "moved", "robot": {"base_xyz_m": [0.05, -0.1, 0.0], "base_rpy_deg": [0.0, 0.0, 20.0]}}]


def written(result, folder):
    """The map tables and summary.json as write_results writes them (figures left out, for speed)."""
    folder.mkdir()
    write_summary(result, folder)
    names = ["summary.json"]
    for scenario in result.map.scenarios.values():
        names.append(map_table_name(result.map, scenario))
        write_map_table(result.map, scenario, folder / names[-1])
    return {name: (folder / name).read_bytes() for name in names}


#: The raw steel as a time series that runs in and warms up (issue 38), and the joints' motion it needs.
TIME_KEYS = {"ar1": 0.9, "run_in": {"start": 0.3, "tau_cycles": 40}, "steady_mean_std": 0.005,
             "thermal": {"mu_per_K": -0.005}}
MOTION = {"study": {"cycle_time_s": 6.0}, "joints": {"travel_per_cycle": 1.0}}
#: The map's figure sets: one simulated test per target; expected figures sampled by common random numbers (the
#: raw steel's uniform law) with the directional ones; in closed form (the treated steel's Gaussian law everywhere);
#: and with scenarios of other robots (:data:`OTHER_ROBOTS`), each solving its own IK, sampled on one of them and in
#: closed form on the others.
VARIANTS = {"one-test": ({"statistic": "one-test"}, "42CD4-raw", []),
            "directional": ({"directional": True}, "42CD4-raw", []),
            "expected-closed-form": ({}, "42CD4-treated", []), "other-robots": ({}, "42CD4-treated", OTHER_ROBOTS)}
#: UR5_MAP without scenarios, its friction with time keys, from one state compared with another: 3 x 3 targets (the
#: far column unreachable) in 3 chunks, tests of 10 cycles (sampled whole), the directional figures too.
TIME_KEYS_MAP = {**UR5_MAP, "scenarios": [], "study": {**UR5_MAP["study"], "cycles": 10, **MOTION["study"]},
                 "joints": {**UR5_MAP["joints"], "friction": {"preset": "42CD4-raw", **TIME_KEYS}, **MOTION["joints"]},
                 "map": {**UR5_MAP["map"], "resolution": [3, 3],
                         "state": {"age_cycles": 0, "after_s": 600},
                         "compare": {"age_cycles": 5000, "after_s": "warm"}}}


def variant_study(name: str) -> dict:
    """UR5_MAP with one of the :data:`VARIANTS`."""
    keys, preset, scenarios = VARIANTS[name]
    return {**UR5_MAP, "joints": {**UR5_MAP["joints"], "friction": {"preset": preset}},
            "map": {**UR5_MAP["map"], **keys}, "scenarios": UR5_MAP["scenarios"] + scenarios}


@pytest.fixture(scope="module")
def references(tmp_path_factory):
    """The tables and summary of each of the :data:`VARIANTS` run in this process, each computed at its first use."""
    cache = {}

    def reference(name: str) -> dict[str, bytes]:
        if name not in cache:
            cache[name] = written(run_study(variant_study(name)), tmp_path_factory.mktemp("reference") / "out")
        return cache[name]

    return reference


@pytest.fixture(scope="module", params=list(VARIANTS))
def variant_name(request):
    return request.param


@pytest.fixture(scope="module")
def variant(variant_name):
    """UR5_MAP with one of the figure sets (:data:`VARIANTS`)."""
    return variant_study(variant_name)


@pytest.fixture(scope="module")
def reference(variant_name, references):
    return references(variant_name)


def with_chunk_rows(study, rows):
    return {**study, "map": {**study["map"], "chunk_rows": rows}}


def test_reference_map_has_unreachable_targets_and_all_scenarios(variant, reference):
    summary = json.loads(reference["summary.json"])["map"]
    assert 0 < summary["unreachable"] < summary["count"] == 35
    assert [s["name"] for s in summary["scenarios"]] == [s["name"] for s in variant["scenarios"]]
    assert sum(summary["wins"].values()) + summary["ties"] == summary.get("reached_by_any", summary["reachable"])
    if "reached_by_any" in summary:  # the UR10, and the UR5 moved nearer, reach the far edge, beyond the UR5
        for scenario in summary["scenarios"][2:]:
            assert scenario["reached_only_by_this"] > 0 and scenario["reached_only_by_reference"] == 0


@pytest.mark.parametrize("rows", [2, 5])
def test_chunk_size_changes_nothing(variant, reference, tmp_path, rows):
    assert written(run_study(with_chunk_rows(variant, rows)), tmp_path / "out") == reference


def test_reading_results_in_small_blocks_changes_nothing(variant, reference, tmp_path, monkeypatch):
    """Tables and summary (exact medians) are built block by block from the store: the block size is invisible."""
    result = run_study(variant)
    monkeypatch.setattr("tribokin.maps.streaming.BLOCK_TARGETS", 4)
    monkeypatch.setattr("tribokin.maps.streaming.BINS", 3)
    monkeypatch.setattr("tribokin.maps.streaming.GATHER_VALUES", 4)
    assert written(result, tmp_path / "out") == reference
    rp = result.map.reference.figure("RP_l_um")
    assert json.loads(reference["summary.json"])["map"]["RP_l_um"]["median"] == np.nanmedian(rp)
    if len(result.map.scenarios) == 4:  # other robots: the UR10's figures sampled, the others' in closed form
        methods = {name: set(s.read("method")[s.read_robot("reachable")]) for name, s in result.map.scenarios.items()}
        assert methods == {"raw": {ANALYTIC}, "treated-shoulder": {ANALYTIC}, "ur10": {SAMPLED}, "moved": {ANALYTIC}}


def test_two_local_workers_change_nothing(variant, reference, tmp_path, monkeypatch):
    import multiprocessing
    import threading

    alone = threading.active_count() == 1  # the whole suite runs in one thread unless a test left one behind
    started = []
    real_context = multiprocessing.get_context
    monkeypatch.setattr(multiprocessing, "get_context", lambda method=None: started.append(method) or
                        real_context(method))
    with executor_for(workers=2) as executor:
        assert written(run_study(with_chunk_rows(variant, 2), executor=executor), tmp_path / "out") == reference
    assert started == ["fork" if alone else "spawn"]  # forked when this process runs no other thread


def test_workers_are_spawned_when_another_thread_runs(references, tmp_path, monkeypatch):
    """Forking a process that runs threads can deadlock: the workers start clean instead. The figure set of scenarios
    with robots of their own (each spawned worker loads them, and the sampled figures' laws, from nothing); every
    figure set runs in forked workers in test_two_local_workers_change_nothing, and on spawned dask workers in
    test_a_dask_cluster_changes_nothing."""
    import multiprocessing
    import threading

    started = []
    real_context = multiprocessing.get_context
    monkeypatch.setattr(multiprocessing, "get_context", lambda method=None: started.append(method) or
                        real_context(method))
    stop = threading.Event()
    other = threading.Thread(target=stop.wait)
    other.start()
    try:
        with executor_for(workers=2) as executor:
            result = run_study(with_chunk_rows(variant_study("other-robots"), 2), executor=executor)
    finally:
        stop.set()
        other.join()
    assert started == ["spawn"]
    assert written(result, tmp_path / "out") == references("other-robots")


@pytest.fixture(scope="module")
def time_keys_reference(tmp_path_factory):
    """:data:`TIME_KEYS_MAP`'s tables and summary, run here in one go."""
    return written(run_study(TIME_KEYS_MAP), tmp_path_factory.mktemp("time-keys") / "out")


def test_a_map_with_time_keys_has_its_changes_and_their_errors(time_keys_reference):
    summary = json.loads(time_keys_reference["summary.json"])["map"]
    assert 0 < summary["unreachable"] < summary["count"] == 9
    assert summary["state"] == {"age_cycles": 0, "after_s": 600} and summary["compare"]["after_s"] == "warm"
    assert summary["RP_l_change_um"]["max"] < 0 and summary["AP_p_change_um"]["max"] < 0  # run in and warm: less
    header = time_keys_reference["map.csv"].split(b"\n", 1)[0].decode().split(",")
    changes = ["RP_l_change_mc_error_um", "AP_p_change_mc_error_um", "RP_l_change_engine_bound_um",
               "AP_p_change_engine_bound_um"]  # after the relative Monte Carlo errors, in this order
    assert header[header.index("RP_l_change_mc_error_um"):][:4] == changes and "RP_l_change_um" in header
    computed = next(iter(summary["computed"].values()))
    for name in ("RP_l_change", "AP_p_change"):  # the first-order model's bounds: small, not 0
        assert 0 < computed[f"{name}_max_engine_bound_um"] < computed[f"{name}_max_mc_error_um"]


def test_a_map_with_time_keys_gives_the_same_bytes_chunked_on_two_workers(time_keys_reference, tmp_path):
    with executor_for(workers=2) as executor:
        result = run_study(with_chunk_rows(TIME_KEYS_MAP, 2), executor=executor)
    assert written(result, tmp_path / "out") == time_keys_reference


def test_a_dask_cluster_changes_nothing(references, time_keys_reference, tmp_path):
    """Every figure set, and the map with time keys, on one cluster (starting its spawned workers costs as much as
    a map)."""
    with local_cluster() as scheduler, executor_for(scheduler=scheduler) as executor:
        results = {name: run_study(variant_study(name), executor=executor) for name in VARIANTS}
        time_keys = run_study(TIME_KEYS_MAP, executor=executor)
    for name, result in results.items():
        assert written(result, tmp_path / name) == references(name), name
    assert written(time_keys, tmp_path / "time-keys") == time_keys_reference


def test_a_map_with_time_keys_interrupted_resumes_to_the_same_bytes(time_keys_reference, tmp_path, monkeypatch):
    folder = tmp_path / "chunks"
    with monkeypatch.context() as patch:
        interrupted_at(patch, "save", 2)
        with pytest.raises(KeyboardInterrupt):
            run_study(TIME_KEYS_MAP, checkpoint=folder)
    assert finished(folder) == 1
    assert written(run_study(TIME_KEYS_MAP, checkpoint=folder, resume=True), tmp_path / "out") == time_keys_reference


def test_unreachable_scheduler_is_refused_before_any_work(tmp_path, monkeypatch):
    monkeypatch.setattr("dask.distributed.Client", lambda *args, **options: pytest.fail("a client was made"))
    with pytest.raises(InputError, match="cannot reach") as error:
        with executor_for(scheduler="tcp://127.0.0.1:9"):
            pytest.fail("an executor was made")
    assert error.value.key == "--scheduler"


def test_finished_chunks_are_reused_on_resume_others_recomputed_and_settings_checked(tmp_path, monkeypatch):
    study = tmp_path / "study.toml"
    study.write_text(GANTRY_SAMPLED_MAP_TOML.replace("cycles = 400", "cycles = 5").replace("[25, 40]", "[5, 8]"))
    folder = tmp_path / "chunks"
    first = run_study(study, checkpoint=folder)
    rp_first = first.map.reference.figure("RP_l_um")
    column = folder / "scenario0_figures.npy"
    figures = np.load(column)
    row_3, row_5 = slice(3 * 5, 4 * 5), slice(5 * 5, 6 * 5)
    figures[row_3, 0] = figures[row_5, 0] = 42.0
    np.save(column, figures)
    (folder / "done" / "5").unlink()  # chunk 5 (one row each) as if the run died while writing it
    resumed = run_study(study, checkpoint=folder, resume=True)
    rp_resumed = resumed.map.reference.figure("RP_l_um")
    assert np.all(rp_resumed[row_3] == 42.0)  # taken from the finished chunk, not recomputed
    np.testing.assert_array_equal(np.delete(rp_resumed, row_3), np.delete(rp_first, row_3))  # row 5 recomputed
    with pytest.raises(InputError, match="other settings"):
        run_study(study, seed=9, checkpoint=folder, resume=True)
    with monkeypatch.context() as patch, pytest.raises(InputError, match="other settings"):
        patch.setenv("TRIBOKIN_KERNELS", "compiled" if kernels_used() == "numpy" else "numpy")  # no mixed paths
        run_study(study, checkpoint=folder, resume=True)
    with pytest.raises(InputError, match="--resume"):
        run_study(study, checkpoint=folder)


def interrupted_at(monkeypatch, method: str, call: int):
    """Make ``ChunkStore.<method>`` raise KeyboardInterrupt at its ``call``-th call (as a Ctrl-C would)."""
    real, calls = getattr(ChunkStore, method), iter(range(1, 10 ** 6))

    def interrupting(*args, **options):
        if next(calls) == call:
            raise KeyboardInterrupt
        return real(*args, **options)

    monkeypatch.setattr(ChunkStore, method, interrupting)


def test_a_map_of_several_robots_interrupted_in_its_chunks_and_in_its_holes_resumes_to_the_same_bytes(
        references, tmp_path, monkeypatch):
    study, folder = variant_study("other-robots"), tmp_path / "chunks"
    with monkeypatch.context() as patch:
        interrupted_at(patch, "save", 3)
        with pytest.raises(KeyboardInterrupt):
            run_study(study, checkpoint=folder)
    assert finished(folder) == 2
    with monkeypatch.context() as patch:  # the study robot's holes filled and recorded, the next robot's not
        interrupted_at(patch, "save_record", 2)
        with pytest.raises(KeyboardInterrupt):
            run_study(study, checkpoint=folder, resume=True)
    assert finished(folder) == 5 and (folder / "filled.npz").is_file() and not (folder / "robot1_filled.npz").exists()
    assert written(run_study(study, checkpoint=folder, resume=True), tmp_path / "out") == references("other-robots")


def finished(chunks) -> int:
    """Chunks a run has marked finished in its store."""
    return len(list((chunks / "done").glob("*"))) if (chunks / "done").is_dir() else 0


def killed_after(command, chunks, count: int) -> int:
    """Start ``command``, SIGKILL it once the store ``chunks`` has ``count`` finished chunks; the number finished
    then."""
    run = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 60
    while finished(chunks) < count and run.poll() is None and time.monotonic() < deadline:
        time.sleep(0.005)
    run.send_signal(signal.SIGKILL)
    run.wait()
    assert run.returncode == -signal.SIGKILL  # killed, not finished
    return finished(chunks)


def children(pid: int) -> list[int]:
    """The processes whose parent is ``pid``."""
    found = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        with suppress(OSError):
            if int(stat.read_text().rsplit(")", 1)[1].split()[1]) == pid:
                found.append(int(stat.parent.name))
    return found


def alive(pid: int) -> bool:
    """Whether process ``pid`` runs (a zombie has ended: only its exit status waits to be collected)."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except FileNotFoundError:
        return False


def test_workers_end_with_a_killed_run_and_leave_its_lock_free(tmp_path):
    """The treated steel's Gaussian law: expected figures in closed form (the raw steel's are sampled: 5x the time)."""
    study = tmp_path / "study.toml"
    study.write_text(GANTRY_MAP_TOML)
    command = [sys.executable, "-m", "tribokin", "run", study, "--out", tmp_path / "out", "--workers", "2",
               "--report", "none"]
    run = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 60
    while finished(tmp_path / "out.chunks") < 2 and run.poll() is None and time.monotonic() < deadline:
        time.sleep(0.005)
    workers = children(run.pid)
    run.send_signal(signal.SIGKILL)
    run.wait()
    assert run.returncode == -signal.SIGKILL and len(workers) >= 2
    deadline = time.monotonic() + 10  # the kernel kills them at once; this only bounds a failing test
    while any(alive(worker) for worker in workers) and time.monotonic() < deadline:
        time.sleep(0.01)
    assert not any(alive(worker) for worker in workers)
    resumed = in_process(*command[3:], "--resume")  # its workers forked from this process
    assert resumed.returncode == 0, resumed.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out", "study.toml"]


def without_command(summary: bytes) -> dict:
    """summary.json without the command line it records (which says --resume, and names the folder)."""
    summary = json.loads(summary)
    assert summary["reproduce"].pop("command") is not None
    return summary


@pytest.mark.parametrize("statistic", ["expected", "one-test"])
def test_run_killed_at_random_points_resumes_to_the_same_bytes(tmp_path, statistic):
    """Expected: the closed form (the treated steel's Gaussian law; the sampled expected figures resume in
    test_finished_chunks_are_reused_on_resume_others_recomputed_and_settings_checked)."""
    study = tmp_path / "study.toml"
    text = GANTRY_MAP_TOML.replace("[map]", f'[map]\nstatistic = "{statistic}"')
    study.write_text(text.replace("resolution = [25, 40]", "resolution = [5, 40]"))  # still 40 chunks of one row
    out, chunks = tmp_path / "out", tmp_path / "out.chunks"
    command = [sys.executable, "-m", "tribokin", "run", study, "--out", out]
    saved = 0
    for kill, steps in enumerate(np.random.default_rng(9283).integers(2, 9, size=3)):  # 3 kill points, 40 chunks
        before = saved
        saved = killed_after(command + (["--resume"] if kill else []), chunks, saved + steps)
        assert before + steps <= saved < 40 and not out.exists()
        if not kill:
            refused = in_process(*command[3:])
            assert refused.returncode == 2 and "--resume" in refused.stderr
    assert (tmp_path / "out.lock").exists()  # left by the killed run; it locks nothing
    resumed = in_process(*command[3:], "--resume")
    assert resumed.returncode == 0, resumed.stderr
    assert "200 of 200 targets reachable" in resumed.stdout
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out", "study.toml"]  # no chunks, lock or partial folder

    write_results(run_study(study), tmp_path / "uninterrupted")
    names = sorted(p.name for p in out.iterdir())
    assert names == sorted(p.name for p in (tmp_path / "uninterrupted").iterdir()) and "report.html" in names
    for name in set(names) - {"summary.json"}:  # every file, the report included
        assert (out / name).read_bytes() == (tmp_path / "uninterrupted" / name).read_bytes(), name
    uninterrupted = json.loads((tmp_path / "uninterrupted" / "summary.json").read_bytes())
    assert uninterrupted["reproduce"].pop("command") is None
    assert without_command((out / "summary.json").read_bytes()) == uninterrupted


#: The gantry map of 1 000 targets in 40 chunks, cheap (closed form, no directional figures): for refusals.
SMALL_MAP = GANTRY_MAP_TOML.replace("cycles = 400", "cycles = 5").replace("[map]", "[map]\ndirectional = false")


def test_chunk_folder_deleted_during_a_run_ends_in_one_line(tmp_path, monkeypatch, capsys):
    study = tmp_path / "study.toml"
    study.write_text(SMALL_MAP)
    real = ChunkStore.save

    def save_then_lose_the_folder(store, chunk, first, arrays):
        real(store, chunk, first, arrays)
        if chunk == 2:
            shutil.rmtree(store.folder)

    monkeypatch.setattr(ChunkStore, "save", save_then_lose_the_folder)
    status = main(["run", str(study), "--out", str(tmp_path / "out"), "--report", "none"])
    error = capsys.readouterr().err
    last = error.splitlines()[-1]  # after the progress bar
    assert status == 2 and "Traceback" not in error and last.startswith("tribokin: error: "), error
    assert last.startswith(f"tribokin: error: {tmp_path / 'out.chunks'}: ") and "deleted or damaged" in last
    assert sorted(p.name for p in tmp_path.iterdir()) == ["study.toml"]


def test_a_refusal_after_the_map_ran_removes_only_the_chunks_of_this_run(tmp_path, monkeypatch, capsys):
    """Chunks this run created hold nothing a later run needs; chunks an interrupted run left are kept for --resume."""
    study = tmp_path / "study.toml"
    study.write_text(SMALL_MAP)
    command = ["run", str(study), "--out", str(tmp_path / "out"), "--report", "none"]
    answers = iter([InputError("refused", "a file"), KeyboardInterrupt(), InputError("refused", "a file")])

    def refuses(*args, **options):
        raise next(answers)

    monkeypatch.setattr("tribokin.output.writers.write_results", refuses)
    assert main(command) == 2  # refused after the map ran: its chunks go
    assert sorted(p.name for p in tmp_path.iterdir()) == ["study.toml"]
    assert main(command) == 130  # interrupted: its chunks stay for --resume
    assert main([*command, "--resume"]) == 2  # refused while resuming: the interrupted run's chunks stay
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.chunks", "study.toml"]
    assert len(list((tmp_path / "out.chunks" / "done").iterdir())) == 40
    assert "refused" in capsys.readouterr().err
