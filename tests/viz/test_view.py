"""`tribokin view DIR`: a live meshcat server listening on 127.0.0.1 only, serving the scene of a pose, map or
mixed folder, and stopped however the viewer ends (Ctrl-C, SIGTERM, SIGHUP, even SIGKILL)."""

import contextlib
import copy
import http.client
import os
import re
import shutil
import signal
import socket
import struct
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest

from conftest import AXIS_STUDY_TOML, AXIS_URDF, GANTRY_MAP_TOML
from helpers.command import in_process
from helpers.viz_layers import CUBE, UNIFORM_AXIS, grid_layers
from tribokin.cli import main
from tribokin.errors import InputError
from tribokin.output.writers import write_results
from tribokin.run import run_study
from tribokin.viz.live import start_server
from tribokin.viz.scene_file import load_scene_inputs

SMALL_MAP_TOML = GANTRY_MAP_TOML.replace("cycles = 400", "cycles = 20").replace("resolution = [25, 40]",
                                                                                 "resolution = [3, 3]")
STUDY_TEXTS = {"pose": AXIS_STUDY_TOML, "map": SMALL_MAP_TOML,
               "mixed": SMALL_MAP_TOML + '\n[[poses]]\nname = "P1"\nq = [0.3, 0.2, 0.1]\n'}


@pytest.fixture(scope="module")
def folders(tmp_path_factory) -> dict[str, Path]:
    """Output folders written by `tribokin run --report light`: a pose study, a map study, and both; without their
    PNG figures, which the viewer never reads (it serves scene.npz, summary.json says what the folder holds)."""
    import tribokin.viz.contents as contents
    import tribokin.viz.maps as maps

    assert "resolution = [3, 3]" in SMALL_MAP_TOML
    root = tmp_path_factory.mktemp("view")
    with pytest.MonkeyPatch.context() as patch:  # in the views' process too (and its helpers): forked with the patch
        patch.setattr(contents, "save_repeatability_field", lambda pose, path, title="": None)
        for module in (contents, maps):
            patch.setattr(module, "save_map_figures", lambda workspace_map, folder, study_name, names=None: [])
        for kind, text in STUDY_TEXTS.items():
            (root / f"{kind}.toml").write_text(text)
            assert main(["run", root / f"{kind}.toml", "--out", root / kind, "--report", "light"]) == 0
    assert not list(root.glob("*/*.png")) and all((root / kind / "scene.npz").is_file() for kind in STUDY_TEXTS)
    return {kind: root / kind for kind in STUDY_TEXTS}


def read_line_matching(stream, pattern: str, seen: list[str] | None = None) -> re.Match:
    """The first line of ``stream`` matching ``pattern``; the lines read are appended to ``seen``."""
    seen = [] if seen is None else seen
    for line in stream:
        seen.append(line)
        match = re.search(pattern, line)
        if match:
            return match
    raise AssertionError(f"no line matching {pattern!r}; got {seen!r}")


@contextlib.contextmanager
def running_view(folder, printed: list[str] | None = None):
    """Start `tribokin view folder`; yield the viewer process, the URL and the server pid it printed (its lines up to
    then appended to ``printed``)."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    # Ctrl-C as in a terminal: a shell's background job inherits SIGINT ignored, and so would the viewer
    viewer = subprocess.Popen([sys.executable, "-u", "-m", "tribokin", "view", str(folder)], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True, env=env,
                              preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    server_pid = None
    try:
        match = read_line_matching(viewer.stdout, r"scene at (http://127\.0\.0\.1:\d+/static/) \(\S+ pid (\d+)",
                                   printed)
        server_pid = int(match.group(2))
        yield viewer, match.group(1), server_pid
    finally:
        for pid in (viewer.pid, server_pid):
            if pid is not None and is_running(pid):
                os.kill(pid, signal.SIGKILL)
        viewer.wait()


def is_running(pid: int) -> bool:
    """Whether ``pid`` exists and is not a zombie (a zombie holds no socket)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except FileNotFoundError:
        return False
    return stat.rpartition(")")[2].split()[0] != "Z"


def wait_until_gone(pid: int, timeout_s: float = 10.0) -> bool:
    deadline = time.monotonic() + timeout_s
    while is_running(pid) and time.monotonic() < deadline:
        time.sleep(0.05)
    return not is_running(pid)


def with_descendants(pid: int) -> set[int]:
    """``pid`` and every process below it, from the parent pids in /proc/*/stat."""
    parents = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        with contextlib.suppress(OSError):
            parents[int(stat.parent.name)] = int(stat.read_text().rpartition(")")[2].split()[2])
    found = {pid}
    while new := {child for child, parent in parents.items() if parent in found} - found:
        found |= new
    return found


def listening_addresses(pids: set[int]) -> set[tuple[str, int]]:
    """(address, port) of every listening TCP socket (IPv4 and IPv6) held by ``pids``, from /proc."""
    inodes = set()
    for pid in pids:
        for fd in Path(f"/proc/{pid}/fd").iterdir():
            with contextlib.suppress(OSError):
                inodes |= set(re.findall(r"^socket:\[(\d+)\]$", os.readlink(fd)))
    addresses = set()
    for table, family in (("tcp", socket.AF_INET), ("tcp6", socket.AF_INET6)):
        for line in Path(f"/proc/net/{table}").read_text().splitlines()[1:]:  # this network namespace
            fields = line.split()
            local, state, inode = fields[1], fields[3], fields[9]
            if state == "0A" and inode in inodes:  # TCP_LISTEN
                address, port = local.split(":")
                words = [int(address[i:i + 8], 16) for i in range(0, len(address), 8)]  # host-order 32-bit words
                addresses.add((socket.inet_ntop(family, struct.pack(f"={len(words)}I", *words)), int(port, 16)))
    return addresses


def assert_stopped(server_pid: int) -> None:
    """The server has exited, and its listening sockets closed with it. (Its port is not probed: once freed, any other
    program on the machine may take it, as another job's server did on CI.)"""
    assert wait_until_gone(server_pid)


def test_view_serves_the_scene_and_stops_on_ctrl_c(tmp_path):
    out = tmp_path / "out"
    write_results(run_study(copy.deepcopy(UNIFORM_AXIS)), out, map_layers=grid_layers(), cube=CUBE)
    with running_view(out) as (viewer, url, server_pid):
        with urllib.request.urlopen(url, timeout=10) as response:
            assert response.status == 200 and b"meshcat" in response.read().lower()
        viewer.send_signal(signal.SIGINT)
        assert viewer.wait(timeout=20) == 0, viewer.stderr.read()
    assert not Path(f"/proc/{server_pid}").exists()  # the server was stopped and reaped
    assert_stopped(server_pid)


def test_view_draws_the_skeleton_of_a_robot_whose_meshes_are_missing(tmp_path):
    """Before, `tribokin run` refused such a robot unless --report none, which writes no scene: nothing to view."""
    urdf = tmp_path / "share" / "pkg" / "axis.urdf"
    urdf.parent.mkdir(parents=True)
    urdf.write_text(AXIS_URDF.read_text().replace('<box size="0.70 0.12 0.05"/>',
                                                  '<mesh filename="package://pkg/meshes/slide.stl"/>'))
    study = copy.deepcopy(UNIFORM_AXIS)
    study["robot"]["urdf"] = str(urdf)
    write_results(run_study(study), tmp_path / "out", report="light")
    printed = []
    with running_view(tmp_path / "out", printed) as (viewer, url, server_pid):
        viewer.send_signal(signal.SIGINT)
        assert viewer.wait(timeout=20) == 0, viewer.stderr.read()
    assert ("note: robot drawn as a skeleton (links as segments, joints as cylinders on their axes): its meshes were "
            "not found in its package folders (pkg/meshes/slide.stl)\n") in printed
    assert_stopped(server_pid)


@pytest.mark.parametrize("kind", ["pose", "map", "mixed"])
def test_view_shows_pose_map_and_mixed_folders(folders, kind):
    inputs = load_scene_inputs(folders[kind])
    assert [pose.name for pose in inputs.poses] == ([] if kind == "map" else ["P1"])
    map_layers = ["gantry-resume", "gantry-resume vAP_p", "gantry-resume RP_l_multi"]  # directional figures: default
    assert list(inputs.map_layers) == ([] if kind == "pose" else map_layers)
    with running_view(folders[kind]) as (viewer, url, server_pid):
        with urllib.request.urlopen(url, timeout=10) as response:
            assert response.status == 200
        viewer.send_signal(signal.SIGINT)
        assert viewer.wait(timeout=20) == 0, viewer.stderr.read()
    assert_stopped(server_pid)


def test_view_listens_on_127_0_0_1_only(folders):
    with running_view(folders["pose"]) as (viewer, url, server_pid):
        addresses = listening_addresses(with_descendants(server_pid) | {viewer.pid})
        web_port = int(re.search(r":(\d+)/", url).group(1))
        assert ("127.0.0.1", web_port) in addresses and len(addresses) == 2, addresses  # the web and zmq ports
        assert {host for host, _ in addresses} == {"127.0.0.1"}, addresses
        page = http.client.HTTPConnection("127.0.0.1", web_port, timeout=10)
        page.request("GET", "/static/../../../../../../../../etc/passwd")
        assert page.getresponse().status == 403  # only meshcat's own viewer files are served


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGHUP], ids=["SIGTERM", "SIGHUP"])
def test_view_stops_its_server_on(folders, signum):
    with running_view(folders["pose"]) as (viewer, url, server_pid):
        viewer.send_signal(signum)
        out, err = viewer.communicate(timeout=20)
        assert viewer.returncode == 0 and out.strip().endswith("viewer stopped"), err
    assert_stopped(server_pid)


def test_view_server_dies_with_a_killed_viewer(folders):
    with running_view(folders["pose"]) as (viewer, url, server_pid):
        viewer.kill()
        viewer.wait()
        assert_stopped(server_pid)


def test_view_of_a_folder_without_scene_is_one_line_exit_2(tmp_path):
    done = in_process("view", tmp_path)  # refused before any server starts: no process of its own to watch
    assert done.returncode == 2 and len(done.stderr.strip().splitlines()) == 1
    assert "summary.json" in done.stderr and "tribokin run" in done.stderr


def test_a_server_that_does_not_start_is_one_error(monkeypatch):
    monkeypatch.setattr(sys, "executable", shutil.which("false"))  # exits at once with status 1, printing nothing
    with pytest.raises(InputError, match="meshcat server did not start: exit status 1"):
        start_server()
