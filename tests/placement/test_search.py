"""The placement search: the gantry's known answer (statics and an independent Monte Carlo), the ranking rule, the
same bytes on one or two workers and after a kill and resume, best.toml, and bad [placement] keys refused."""

import json

import numpy as np
import pytest
import tomllib

from conftest import ROOT, killed_after
from helpers.dask_cluster import local_cluster
from tribokin import InputError, run_study
from tribokin.cli import main
from tribokin.compiled import kernels_used
from tribokin.execution import executor_for
from tribokin.kinematics.loads import BearingLoads
from tribokin.output.writers import write_results
from tribokin.placement.search import open_store
from tribokin.study.assembly import load_robot
from tribokin.study.reading import load_study, read_study_file
from tribokin.viz.canvas import save_png

MU_MEAN, MU_STD, STIFFNESS = 0.1375, 0.0075, 2.0e7  # the 42CD4-treated preset [-], its σ, k [N/m]
PAYLOAD_KG, SPAN_M, CYCLES = 5.0, 0.2, 30
#: The task region: a 3 x 3 plane at z = 0.4 m, world x 0.4-0.6 m, y 0-0.2 m.
TASK = {"kind": "plane", "origin_m": [0.4, 0.0, 0.4], "axis_u": [1, 0, 0], "axis_v": [0, 1, 0],
        "extent_u_m": [0.0, 0.2], "extent_v_m": [0.0, 0.2], "resolution": [3, 3]}
#: Base positions, each tried at yaw 0 and 180°: the gantry (tool = base + R(yaw)·(0.2 + q_x, q_y, 0.2 + q_z)) placed
#: so that the task lies at large local y (0.4-0.6 m: the first two, facing each other), at small local y (0-0.2 m:
#: the next two, the mirror images of the first), and half outside the y travel (local y -0.1-0.1 m: the last).
BASES = [[0.0, -0.4, 0.0], [1.0, 0.6, 0.0], [1.0, 0.2, 0.0], [0.0, 0.0, 0.0], [0.0, 0.1, 0.0]]
YAWS = [0.0, 180.0]
FAR, NEAR, PARTIAL = (0, 3), (5, 6), 8  # candidate indices (position × 2 + yaw): far, near and partial placements


def gantry_study(task: dict | None = TASK, **placement) -> str:
    """A study file's text: the gantry, the ``task`` region (``None``: no [map]), a [placement] of BASES × YAWS
    updated by ``placement`` (a key set to ``None`` left out)."""
    keys = {"candidates": BASES, "yaw_deg": YAWS, **placement}
    lines = "\n".join(f"{key} = {json.dumps(value)}" for key, value in keys.items() if value is not None)
    task = "" if task is None else "[map]\n" + "\n".join(f"{key} = {json.dumps(value)}" for key, value in task.items())
    return f"""# the gantry placed to serve a small plane
[study]
name = "gantry-placement-test"
cycles = {CYCLES}
seed = 4

[robot]
urdf = "{ROOT / 'urdf' / 'cartesian_xyz.urdf'}"
tool_frame = "tool"
payload_kg = {PAYLOAD_KG}

[joints]
friction = {{ preset = "42CD4-treated" }}
stiffness = {STIFFNESS}
bearing_span_m = {SPAN_M}

{task}

[placement]   # where to put it
{lines}
"""


@pytest.fixture(scope="module")
def study_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("study") / "study.toml"
    path.write_text(gantry_study())
    return path


@pytest.fixture(scope="module")
def result(study_file):
    return run_study(study_file, meshes=False)


def task_targets_m() -> np.ndarray:
    """(9, 3) the task's targets in the world [m]."""
    u, v = np.meshgrid(np.linspace(0.0, 0.2, 3), np.linspace(0.0, 0.2, 3))
    return np.column_stack([0.4 + u.ravel(), v.ravel(), np.full(9, 0.4)])


def local_configurations(base_m, yaw_deg: float) -> np.ndarray:
    """(9, 3) the gantry's joint values at the task's targets with its base at ``base_m``, turned by ``yaw_deg``."""
    c, s = np.cos(np.radians(yaw_deg)), np.sin(np.radians(yaw_deg))
    local = (task_targets_m() - base_m) @ np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])  # R(yaw)ᵀ·(world - base)
    return local - [0.2, 0.0, 0.2]


def monte_carlo_rp_l_um(loads_N: np.ndarray, tests: int = 4000) -> np.ndarray:
    """Expected RP_l [µm] of 30-cycle unidirectional tests at each configuration of ``loads_N`` (k, 3), by direct
    simulation: each prismatic axis of the gantry moves the tool along its own direction by μ·N/k (Gaussian μ; its
    truncation at 0 lies 18σ away); RP_l = l̄ + 3·S_l of the distances from the test's barycentre."""
    rng = np.random.default_rng(2024)
    mu = rng.normal(MU_MEAN, MU_STD, size=(tests, CYCLES, 3))
    figures = []
    for loads in loads_N:
        positions = mu * loads / STIFFNESS  # (tests, cycles, 3) [m]
        distances = np.linalg.norm(positions - positions.mean(axis=1, keepdims=True), axis=2)
        figures.append(np.mean(distances.mean(axis=1) + 3 * distances.std(axis=1, ddof=1)) * 1e6)
    return np.array(figures)


def test_the_best_of_mirrored_placements_is_the_one_statics_predict(result):
    placement = result.placement
    gantry = load_robot(read_study_file(ROOT / "studies" / "gantry-map.toml"), meshes=False)  # base at the origin
    loads = BearingLoads(gantry, PAYLOAD_KG, [SPAN_M] * 3)
    predicted_p95 = {}
    for index in FAR + NEAR:
        candidate = placement.candidates[index]
        q = local_configurations(candidate.base_xyz_m, candidate.yaw_deg)
        assert np.all((q >= -1e-12) & (q <= [0.6 + 1e-12, 0.6 + 1e-12, 0.5 + 1e-12]))  # every target within travel
        n = loads(q)
        predicted_p95[index] = np.percentile(monte_carlo_rp_l_um(n), 95)
        if index in NEAR:  # the X guide carries the carriage's reach: 0.4 m more of it at every far target
            far = loads(local_configurations(placement.candidates[FAR[0]].base_xyz_m, 0.0))
            assert np.all(n[:, 0] < far[:, 0] - 1.0) and np.allclose(n[:, 1:], far[:, 1:])
        assert placement.reachable[index] == 9
        assert placement.objective_um[index] == pytest.approx(predicted_p95[index], rel=0.01)
    assert max(predicted_p95[i] for i in NEAR) < 0.9 * min(predicted_p95[i] for i in FAR)
    assert placement.best.index in NEAR and placement.ranks[list(NEAR)].max() == 2
    near = placement.objective_um[list(NEAR)]
    assert near[0] == pytest.approx(near[1], rel=1e-9)  # turning the base about the vertical changes no load
    assert placement.best.index == NEAR[0]  # a tie to 9 digits: the lower index
    assert placement.reachable[[1, 2, 4, 7, 9]].tolist() == [0] * 5  # facing away: nothing reached


def test_a_candidate_reaching_fewer_targets_ranks_after_all_that_reach_every_one(result, study_file, tmp_path):
    placement = result.placement
    assert placement.reachable[PARTIAL] == 6  # local y -0.1 m lies outside the travel: a row of three lost
    reaching = np.flatnonzero(placement.reachable == 9)
    assert placement.objective_um[PARTIAL] < placement.objective_um[reaching].min()  # more precise where it reaches
    assert placement.ranks[PARTIAL] == len(reaching) + 1
    assert sorted(placement.ranks[reaching]) == list(range(1, len(reaching) + 1))
    relaxed = tmp_path / "relaxed.toml"
    relaxed.write_text(gantry_study(min_reachable=0.6))
    assert run_study(relaxed, meshes=False).placement.best.index == PARTIAL  # 6 of 9 is enough now


def test_objectives_are_statistics_of_the_task_map_at_each_base(result, study_file):
    """Each candidate's figures are those of the task map run on its own, with the base set in the study."""
    placement = result.placement
    for index in (NEAR[1], PARTIAL):
        candidate = placement.candidates[index]
        mapping = tomllib.loads(study_file.read_text())
        del mapping["placement"]
        mapping["robot"].update(base_xyz_m=list(candidate.base_xyz_m), base_rpy_deg=[0.0, 0.0, candidate.yaw_deg])
        alone = run_study(mapping, meshes=False).map.reference.figure("RP_l_um")
        reached = alone[np.isfinite(alone)]
        assert len(reached) == placement.reachable[index]
        expected = [reached.mean(), np.percentile(reached, 95), reached.max()]
        np.testing.assert_allclose(placement.RP_l_um[index], expected, rtol=1e-12)


def without_command(summary: bytes) -> dict:
    summary = json.loads(summary)
    assert summary["reproduce"].pop("command") is not None
    return summary


PLACEMENT_FILES = ("placement.csv", "best.toml", "placement.png")


def test_a_resume_on_the_other_kernel_path_is_refused(study_file, tmp_path, monkeypatch):
    """The candidates' results differ by rounding between the kernel paths (TRIBOKIN_KERNELS): not mixed."""
    study = load_study(study_file)
    open_store(study, 4, tmp_path / "chunks", resume=False)
    open_store(study, 4, tmp_path / "chunks", resume=True)
    monkeypatch.setenv("TRIBOKIN_KERNELS", "compiled" if kernels_used() == "numpy" else "numpy")
    with pytest.raises(InputError, match="other settings"):
        open_store(study, 4, tmp_path / "chunks", resume=True)


def test_one_or_two_workers_and_a_resume_write_the_same_bytes(study_file, tmp_path):
    outputs = {}
    for name, options in (("one", []), ("two", ["--workers", "2"])):
        assert main(["run", study_file, "--out", tmp_path / name, "--report", "none", *options]) == 0
        outputs[name] = tmp_path / name
    out, chunks = tmp_path / "resumed", tmp_path / "resumed.chunks"
    command = ["run", study_file, "--out", out, "--report", "none"]
    assert killed_after(3, ("tribokin.placement.search.evaluate_candidate",), lambda: main(command))
    assert not out.exists() and len(list((chunks / "done").iterdir())) == 2  # killed before saving the third
    assert main(command + ["--resume"]) == 0
    assert not chunks.exists()
    for folder in (outputs["two"], out):
        for name in PLACEMENT_FILES:
            assert (folder / name).read_bytes() == (outputs["one"] / name).read_bytes(), (folder, name)
        assert without_command((folder / "summary.json").read_bytes()) == \
            without_command((outputs["one"] / "summary.json").read_bytes())


def test_a_dask_cluster_writes_the_same_bytes(result, study_file, tmp_path):
    with local_cluster() as scheduler, executor_for(scheduler=scheduler) as executor:
        clustered = run_study(study_file, executor=executor, meshes=False)
    for name, run in (("here", result), ("dask", clustered)):
        write_results(run, tmp_path / name, report="none")
    for name in PLACEMENT_FILES + ("summary.json",):
        assert (tmp_path / "dask" / name).read_bytes() == (tmp_path / "here" / name).read_bytes(), name


def test_the_run_writes_the_table_the_summary_and_the_best_study(result, study_file, tmp_path, capsys):
    out = tmp_path / "out"
    write_results(result, out, report="none")
    assert sorted(p.name for p in out.iterdir()) == ["best.toml", "placement.csv", "placement.png", "summary.json"]
    (name, figure), = result.figures().items()  # the heat map as a matplotlib Figure: the same PNG saved
    save_png(figure, tmp_path / name)
    assert (tmp_path / name).read_bytes() == (out / "placement.png").read_bytes()
    lines = (out / "placement.csv").read_text().splitlines()
    assert lines[0] == ("candidate,base_x_m,base_y_m,base_z_m,yaw_deg,reachable_fraction,reachable_targets,"
                        "RP_l_p95_um,RP_l_mean_um,RP_l_max_um,meets_min_reachable,rank")
    assert lines[1].startswith(f"{NEAR[0]},1.0,0.2,0.0,180.0,1.0,9,") and lines[1].endswith(",true,1")
    assert len(lines) == 11 and lines[-1].endswith(",,,,false,10")  # nothing reached: last, no figures
    summary = json.loads((out / "summary.json").read_text())["placement"]
    assert summary["best"]["base_rpy_deg"] == [0.0, 0.0, 180.0]
    assert summary["meeting_min_reachable"] == result.placement.meeting_min_reachable == 4
    best = (out / "best.toml").read_text()
    assert "# the gantry placed to serve a small plane" in best and "# where to put it" not in best
    placed = load_study(read_study_file(out / "best.toml"))
    assert placed.placement is None and placed.map is not None
    assert placed.robot.base_xyz_m == (1.0, 0.2, 0.0) and placed.robot.base_rpy_deg == (0.0, 0.0, 180.0)
    again = run_study(out / "best.toml", meshes=False).map.reference.figure("RP_l_um")
    assert np.percentile(again, 95) == pytest.approx(result.placement.objective_um[NEAR[0]], rel=1e-12)


@pytest.mark.parametrize(("placement", "key", "message"), [
    ({"objective": "median"}, "placement.objective", "p95"),
    ({"min_reachable": 1.5}, "placement.min_reachable", "between 0 and 1"),
    ({"yaw_deg": [0, 0]}, "placement.yaw_deg[1]", "twice"),
    ({"yaw_deg": [400]}, "placement.yaw_deg[0]", "360"),
    ({"candidates": [[0, 0]]}, "placement.candidates[0]", "3 numbers"),
    ({"base_xyz_m_min": [0, 0, 0]}, "placement.base_xyz_m_min", "not both"),
    ({"candidates": None, "base_xyz_m_min": [0, 0, 0], "base_xyz_m_max": [1, 1, 0]}, "placement.resolution",
     "missing"),
    ({"candidates": None, "base_xyz_m_min": [0, 1, 0], "base_xyz_m_max": [1, 0, 0], "resolution": [2, 2, 1]},
     "placement.base_xyz_m_max[1]", "swap"),
    ({"candidates": None, "base_xyz_m_min": [0, 0, 0], "base_xyz_m_max": [1, 1, 0], "resolution": [200, 200, 1]},
     "placement.resolution", "candidates"),
    ({"yaws": [0]}, "placement.yaws", "valid keys: candidates"),
])
def test_bad_placement_keys_are_refused_in_one_line_before_any_work(tmp_path, capsys, monkeypatch, placement, key,
                                                                    message):
    monkeypatch.setattr("tribokin.placement.search.evaluate_candidate", lambda *a: pytest.fail("work started"))
    study = tmp_path / "bad.toml"
    study.write_text(gantry_study(**placement))
    assert main(["run", study, "--out", tmp_path / "out"]) == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and f"{study}: {key}:" in error and message in error, error
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml"]


JOINT_MAP = {"kind": "joint", "joints": ["x"], "ranges": [[0.0, 0.5]], "counts": [3]}


@pytest.mark.parametrize(("text", "key", "message"), [
    (gantry_study(task=None), "placement", "[map]"),
    (gantry_study(task=JOINT_MAP), "map.kind", '"joint"'),
    (gantry_study() + '\n[[scenarios]]\nname = "a"\n', "scenarios", "[[scenarios]]"),
])
def test_a_placement_needs_a_world_task_map_and_no_scenarios(tmp_path, text, key, message):
    study = tmp_path / "bad.toml"
    study.write_text(text)
    with pytest.raises(InputError) as error:
        read_study_file(study)
    assert error.value.key == key and message in error.value.message, error.value.one_line()


def test_poses_run_at_the_study_base_beside_the_search_and_progress_counts_targets(tmp_path):
    study = tmp_path / "study.toml"
    study.write_text(gantry_study(candidates=[[0.0, 0.0, 0.0], [0.0, -0.4, 0.0]], yaw_deg=[0.0]) +
                     '\n[[poses]]\nname = "home"\nq = [0.1, 0.1, 0.1]\n')
    calls = []
    result = run_study(study, progress=lambda done, total: calls.append((done, total)))
    assert [pose.name for pose in result.poses] == ["home"] and result.map is None
    assert result.poses[0].report_row()["commanded_position_m"] == pytest.approx([0.3, 0.1, 0.3])  # base at origin
    assert calls == [(0, 18), (9, 18), (18, 18)]
    write_results(result, tmp_path / "out", report="light")
    assert {"poses.csv", "placement.csv", "best.toml"} <= {p.name for p in (tmp_path / "out").iterdir()}
    assert "map" not in json.loads((tmp_path / "out" / "summary.json").read_text())
    report = (tmp_path / "out" / "report.html").read_text()
    assert "Where to put the robot" in report and '<img alt="placement"' in report
    assert "candidate 0: base at (0, 0, 0) m" in report and "2 (base positions × yaw_deg (0)°)" in report
