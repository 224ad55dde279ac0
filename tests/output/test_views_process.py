"""The views' process: it draws the same files and computes the same summary as the writing process would, in a
process of its own; its errors come back as the command's; a lost one is replaced; it ends with the command."""

import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from conftest import AXIS_URDF, GANTRY_MAP_TOML, STUDIES
from helpers.command import in_process
from tribokin import InputError, run_study
from tribokin.output.views_process import RemoteTraceback, ViewsProcess
from tribokin.output.writers import write_results

#: A small map with unreachable targets and a pose, drawn with a light report.
STUDY = GANTRY_MAP_TOML.replace("cycles = 400", "cycles = 20").replace("resolution = [25, 40]", "resolution = [6, 5]") \
    + '\n[[poses]]\nname = "P1"\nq = [0.2, 0.2, 0.2]\n'


@pytest.fixture(scope="module")
def study_file(tmp_path_factory) -> Path:
    """The study's file, which no test changes."""
    path = tmp_path_factory.mktemp("study") / "study.toml"
    path.write_text(STUDY)
    return path


@pytest.fixture
def study(study_file, monkeypatch):
    """The study's file; and the views' process forked though an earlier test of this process may have left an idle
    thread behind (dask's offload thread, waiting on its queue: it holds no lock the forked process needs)."""
    monkeypatch.setattr(threading, "active_count", lambda: 1)
    return study_file


@pytest.fixture(scope="module")
def drawn_here(study_file, tmp_path_factory) -> dict[str, bytes]:
    """The study's folder as the writing process writes it without a views' process, drawn by this process: what
    every views' process, and every writing process that replaces one, must draw (written once for the tests that
    compare with it)."""
    root = tmp_path_factory.mktemp("drawn-here")
    with pytest.MonkeyPatch.context() as patch:
        record_drawing_pid(patch, root)
        write_results(run_study(study_file), root / "here", report="light")
    assert drawn_by(root) == [os.getpid()]
    return files(root / "here")


def files(folder) -> dict[str, bytes]:
    return {path.name: path.read_bytes() for path in sorted(folder.iterdir())}


def record_drawing_pid(monkeypatch, tmp_path, raises: BaseException | None = None):
    """write_views records the process that draws (in a file: the views' process is forked after this patch), and
    raises ``raises`` if given."""
    import tribokin.viz.contents as contents

    real = contents.write_views

    def write_views(*arguments, **options):
        (tmp_path / f"drawn-by-{os.getpid()}").touch()
        if raises is not None:
            raise raises
        return real(*arguments, **options)

    monkeypatch.setattr(contents, "write_views", write_views)


def drawn_by(tmp_path) -> list[int]:
    return [int(path.name.rsplit("-", 1)[1]) for path in tmp_path.glob("drawn-by-*")]


def test_the_views_process_draws_the_same_files_and_summary_as_the_writing_process(study, drawn_here, tmp_path,
                                                                                   monkeypatch):
    record_drawing_pid(monkeypatch, tmp_path)
    views = ViewsProcess.start(study, None, None, "light")
    assert views is not None
    result = run_study(study)
    write_results(result, tmp_path / "there", report="light", views=views)
    assert len(drawn_by(tmp_path)) == 1 and os.getpid() not in drawn_by(tmp_path)  # drawn in another process
    assert not views._process.is_alive()  # closed by write_results
    there = files(tmp_path / "there")
    assert there == drawn_here and {"report.html", "map_RP_l.png", "field_P1.png"} <= set(there)
    assert result.map.summary() == json.loads(there["summary.json"])["map"]  # the summary it sent back


def record_map_figure_drawers(monkeypatch, tmp_path, fails_in_helpers: str | None = None) -> None:
    """Each process that draws map figures records which (a file per process and call: the views' process and its
    helpers are forked after this patch); a helper (a process whose parent is not this one) ``"raises"`` or is
    ``"killed"`` when it would draw, if asked."""
    import tribokin.viz.contents as contents
    import tribokin.viz.maps as maps

    real, here = maps.save_map_figures, os.getpid()

    def save_map_figures(workspace_map, folder, study_name, names=None):
        drawn = real(workspace_map, folder, study_name, names)
        helper = os.getpid() != here and os.getppid() != here
        if helper and fails_in_helpers == "raises":
            raise OSError("a helper's error")
        if helper and fails_in_helpers == "killed":
            os.kill(os.getpid(), signal.SIGKILL)
        (tmp_path / f"{'helper' if helper else 'views'}-{os.getpid()}-{time.monotonic_ns()}").write_text(
            json.dumps([path.name for path in drawn]))
        return drawn

    for module in (contents, maps):
        monkeypatch.setattr(module, "save_map_figures", save_map_figures)


def map_figure_drawers(tmp_path) -> dict[str, dict[int, list[str]]]:
    """``"helper"`` and ``"views"``: each process's pid -> the map figures it drew, in the order drawn
    (:func:`record_map_figure_drawers`)."""
    drawers = {"helper": {}, "views": {}}
    for path in sorted(tmp_path.glob("*-*-*"), key=lambda path: int(path.name.split("-")[2])):  # in time order
        kind, pid, _ = path.name.split("-")
        drawers[kind].setdefault(int(pid), []).extend(json.loads(path.read_text()))
    return drawers


@pytest.mark.parametrize("helper", ["draws", "raises", "killed"])
def test_a_helper_of_the_views_process_draws_a_share_of_the_map_figures(study, drawn_here, tmp_path, monkeypatch,
                                                                       helper):
    """On two cores the views' process forks a helper for every second map figure (the same bytes); a helper that
    fails, or is killed, leaves its figures to the views' process, which draws them. No helper outlives the run."""
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0, 1})
    record_map_figure_drawers(monkeypatch, tmp_path, None if helper == "draws" else helper)
    from tribokin.viz.maps import map_figure_names

    views = ViewsProcess.start(study, None, None, "light")
    result = run_study(study)
    write_results(result, tmp_path / "there", report="light", views=views)
    assert files(tmp_path / "there") == drawn_here
    names = map_figure_names(result.map)
    drawers = map_figure_drawers(tmp_path)
    (views_pid, drawn), = drawers["views"].items()
    assert views_pid != os.getpid() and len(names) == 5
    if helper == "draws":
        (helper_pid, share), = drawers["helper"].items()
        assert drawn == names[0::2] and share == names[1::2]
        assert not Path(f"/proc/{helper_pid}").exists()
    else:  # drawn again by the views' process
        assert not drawers["helper"] and drawn == names[0::2] + names[1::2]


def test_where_no_helper_can_be_forked_the_views_process_draws_every_figure(study, drawn_here, tmp_path,
                                                                           monkeypatch):
    """A fork refused in the views' process (a process limit): its figures are drawn there, the same files."""
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0, 1})
    record_map_figure_drawers(monkeypatch, tmp_path)
    real, here = os.fork, os.getpid()

    def fork():
        if os.getpid() != here:  # the views' process, forking its helper
            raise BlockingIOError(11, "Resource temporarily unavailable")
        return real()

    monkeypatch.setattr(os, "fork", fork)
    views = ViewsProcess.start(study, None, None, "light")
    write_results(run_study(study), tmp_path / "there", report="light", views=views)
    assert files(tmp_path / "there") == drawn_here
    drawers = map_figure_drawers(tmp_path)
    assert not drawers["helper"] and len(next(iter(drawers["views"].values()))) == 5


def test_an_error_in_the_views_process_ends_its_helpers(study, tmp_path, monkeypatch):
    """The views' process fails while its helper still draws: the helper is ended, the error raised, nothing kept."""
    import tribokin.viz.maps as maps

    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0, 1})
    real, here = maps.save_map_figures, os.getpid()

    def save_map_figures(workspace_map, folder, study_name, names=None):
        if os.getppid() == here:  # the views' process
            raise OSError(28, "No space left on device")
        (tmp_path / f"helper-{os.getpid()}").touch()
        time.sleep(60)  # still drawing
        return real(workspace_map, folder, study_name, names)

    monkeypatch.setattr(maps, "save_map_figures", save_map_figures)
    record_drawing_pid(monkeypatch, tmp_path)
    monkeypatch.setattr(
        "tribokin.viz.contents.save_map_figures",
        lambda workspace_map, folder, study_name, names=None: save_map_figures(workspace_map, folder, study_name))
    views = ViewsProcess.start(study, None, None, "light")
    started = time.monotonic()
    with pytest.raises(InputError, match="disk"):
        write_results(run_study(study), tmp_path / "out", report="light", views=views)
    assert time.monotonic() - started < 30 and not (tmp_path / "out").exists()
    helper, = (int(path.name.split("-")[1]) for path in tmp_path.glob("helper-*"))
    assert not Path(f"/proc/{helper}").exists()


#: The axis warming by its own friction, with a drift test of 12 cycles in sets of 4.
DRIFT_STUDY = f"""
[study]
cycles = 10
cycle_time_s = 10.0
[robot]
urdf = "{AXIS_URDF}"
tool_frame = "tool"
[joints]
stiffness = 1.0e6
normal_force_N = 100.0
travel_per_cycle = 0.5
friction = {{ law = "gaussian", mean = 0.12, std = 0.006, thermal = {{ mu_per_K = -0.005 }} }}
[[poses]]
name = "P1"
q = [0.2]
[drift]
duration_s = 120.0
set_cycles = 4
"""


def test_the_views_process_draws_the_drift_figures_as_the_writing_process(tmp_path, monkeypatch):
    """A study with [drift]: its poses' drift along their span travel to the views' process, which draws the same
    drift_<pose>.png and report."""
    path = tmp_path / "drift.toml"
    path.write_text(DRIFT_STUDY)
    monkeypatch.setattr(threading, "active_count", lambda: 1)
    write_results(run_study(path), tmp_path / "here", report="light")
    views = ViewsProcess.start(path, None, None, "light")
    assert views is not None
    write_results(run_study(path), tmp_path / "there", report="light", views=views)
    there = files(tmp_path / "there")
    assert there == files(tmp_path / "here") and "drift_P1.png" in there


def test_an_error_while_drawing_is_raised_by_the_command_and_nothing_is_written(study, tmp_path, monkeypatch):
    record_drawing_pid(monkeypatch, tmp_path, raises=InputError("cannot read this mesh", "robot.stl"))
    views = ViewsProcess.start(study, None, None, "light")
    with pytest.raises(InputError) as raised:
        write_results(run_study(study), tmp_path / "out", report="light", views=views)
    assert raised.value.one_line() == "robot.stl: cannot read this mesh"
    assert drawn_by(tmp_path) != [os.getpid()] and not (tmp_path / "out").exists()
    assert not views._process.is_alive()


def test_an_unexpected_error_comes_back_with_the_views_process_traceback(study, tmp_path, monkeypatch):
    record_drawing_pid(monkeypatch, tmp_path, raises=ZeroDivisionError("a bug"))
    views = ViewsProcess.start(study, None, None, "none")
    with pytest.raises(ZeroDivisionError, match="a bug") as raised:
        write_results(run_study(study), tmp_path / "out", report="none", views=views)
    assert isinstance(raised.value.__cause__, RemoteTraceback)
    assert "in write_views" in str(raised.value.__cause__) and "ZeroDivisionError: a bug" in str(raised.value.__cause__)
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("when", ["killed before it is sent the results", "killed while it draws",
                                  "the study file changed after it read it"])
def test_a_lost_or_declining_views_process_is_replaced_by_the_writing_process(study, drawn_here, tmp_path, monkeypatch,
                                                                              when):
    if when == "killed while it draws":
        import tribokin.viz.contents as contents

        monkeypatch.setattr(contents, "write_views", lambda *arguments, **options: os.kill(os.getpid(), signal.SIGKILL))
    views = ViewsProcess.start(study, None, None, "light")
    if when == "killed before it is sent the results":
        views._process.kill()
        views._process.join()
    elif when == "killed while it draws":
        monkeypatch.undo()  # the views' process has the patch: it is killed while it draws; here, drawn as ever
    else:  # as if the file was edited between its reading and the command's: another file, read here
        study = tmp_path / "edited.toml"
        study.write_text(STUDY.replace("seed = 8", "seed = 9"))
    record_drawing_pid(monkeypatch, tmp_path)
    write_results(run_study(study), tmp_path / "there", report="light", views=views)
    assert os.getpid() in drawn_by(tmp_path)  # drawn here
    if when == "the study file changed after it read it":
        write_results(run_study(study), tmp_path / "here", report="light")
        drawn_here = files(tmp_path / "here")
    assert files(tmp_path / "there") == drawn_here


def test_results_with_large_pose_samples_are_drawn_by_the_writing_process(study, tmp_path, monkeypatch):
    """Sending them would take their memory twice again: the writing process draws, as it did before."""
    import tribokin.output.views_process as views_process

    record_drawing_pid(monkeypatch, tmp_path)
    views = ViewsProcess.start(study, None, None, "none")
    result = run_study(study)
    samples = sum(values.nbytes for values in result.poses[0].samples().values())
    monkeypatch.setattr(views_process, "SENT_POSE_BYTES", samples - 1)
    write_results(result, tmp_path / "out", report="none", views=views)
    assert drawn_by(tmp_path) == [os.getpid()] and (tmp_path / "out" / "field_P1.png").exists()
    assert not views._process.is_alive()


def test_none_is_started_on_one_core_or_beside_another_thread(study, monkeypatch):
    monkeypatch.undo()  # the thread count as it is
    stop = threading.Event()
    other = threading.Thread(target=stop.wait)
    other.start()
    try:
        assert ViewsProcess.start(study, None, None, "light") is None  # forking beside a thread can deadlock
    finally:
        stop.set()
        other.join()
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0})
    assert ViewsProcess.start(study, None, None, "light") is None


def test_the_command_interrupted_says_one_line_and_leaves_no_process(tmp_path):
    """Ctrl-C reaches every process of the command: the workers end at once and silently (before, each printed its
    KeyboardInterrupt's traceback), the views' process ignores it and is ended by the command."""
    path = tmp_path / "study.toml"
    path.write_text(GANTRY_MAP_TOML)
    def as_in_a_terminal():  # its own process group; SIGINT not ignored (as a shell's background job inherits it)
        os.setsid()
        signal.signal(signal.SIGINT, signal.SIG_DFL)

    run = subprocess.Popen([sys.executable, "-m", "tribokin", "run", path, "--out", tmp_path / "out", "--workers",
                            "2"], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                           preexec_fn=as_in_a_terminal)
    deadline = time.monotonic() + 60
    while not any((tmp_path / "out.chunks" / "done").glob("*")) and run.poll() is None and time.monotonic() < deadline:
        time.sleep(0.005)
    children = [int(pid) for pid in Path(f"/proc/{run.pid}/task/{run.pid}/children").read_text().split()]
    assert len(children) >= 3, children  # two workers and the views' process
    os.killpg(run.pid, signal.SIGINT)  # as a terminal sends it: to the whole process group
    error = run.communicate(timeout=60)[1]
    assert run.returncode == 130 and error.splitlines()[-1] == "tribokin: interrupted; nothing was written", error
    assert "Traceback" not in error, error  # the workers end at once and silently, the views' process ignores it
    deadline = time.monotonic() + 10
    while any(Path(f"/proc/{pid}").exists() for pid in children) and time.monotonic() < deadline:
        time.sleep(0.01)
    assert not any(Path(f"/proc/{pid}").exists() for pid in children)
    assert not (tmp_path / "out").exists()


def test_a_shipped_study_through_the_command_draws_what_the_api_draws(tmp_path, monkeypatch):
    """The command (views' process, two workers) against the Python API (drawn in one process): every file. The
    command runs its main in this process (its views' process and workers forked from it, as the `study` fixture
    allows), which draws as a fresh one does: the same code, the same inputs. The shipped Panda plane on 8 x 10 of
    its 29 x 37 targets: whether the two write the same files does not depend on the map's size."""
    text = (STUDIES / "panda-map-vertical.toml").read_text(encoding="utf-8")
    assert "resolution = [29, 37]" in text
    study = tmp_path / "panda-map-vertical.toml"
    study.write_text(text.replace("resolution = [29, 37]", "resolution = [8, 10]"), encoding="utf-8")
    monkeypatch.setattr(threading, "active_count", lambda: 1)
    started, start = [], ViewsProcess.start

    def recorded(*arguments):
        started.append(start(*arguments))
        return started[-1]

    monkeypatch.setattr(ViewsProcess, "start", recorded)
    done = in_process("run", study, "--out", tmp_path / "command", "--workers", "2", "--cycles", "30", "--report",
                      "light")
    assert done.returncode == 0, done.stderr
    assert len(started) == 1 and started[0] is not None  # drawn by the views' process
    write_results(run_study(study, cycles=30), tmp_path / "api", report="light")
    command, api = files(tmp_path / "command"), files(tmp_path / "api")
    assert command.keys() == api.keys() and "report.html" in command
    for name in set(command) - {"summary.json"}:
        assert command[name] == api[name], name
    summaries = [json.loads(folder["summary.json"]) for folder in (command, api)]
    assert summaries[0]["reproduce"].pop("command") is not None and summaries[1]["reproduce"].pop("command") is None
    assert summaries[0] == summaries[1]
