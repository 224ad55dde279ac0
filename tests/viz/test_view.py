"""`tribokin view DIR`: a live meshcat-server on 127.0.0.1, serving the scene, stopped cleanly by Ctrl-C."""

import copy
import os
import re
import signal
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest

from tribokin.output import write_results
from tribokin.study import run_study
from viz_fixtures import CUBE, UNIFORM_AXIS, grid_layers


def read_line_matching(stream, pattern: str, timeout_s: float = 60.0) -> re.Match:
    deadline = time.monotonic() + timeout_s
    seen = []
    while time.monotonic() < deadline:
        line = stream.readline()
        if not line:
            break
        seen.append(line)
        match = re.search(pattern, line)
        if match:
            return match
    raise AssertionError(f"no line matching {pattern!r}; got {seen!r}")


def test_view_serves_the_scene_and_stops_on_ctrl_c(tmp_path):
    out = tmp_path / "out"
    write_results(run_study(copy.deepcopy(UNIFORM_AXIS)), out, map_layers=grid_layers(), cube=CUBE)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    viewer = subprocess.Popen([sys.executable, "-u", "-m", "tribokin", "view", str(out)], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True, env=env)
    try:
        match = read_line_matching(viewer.stdout, r"scene at (http://127\.0\.0\.1:\d+/static/) \(meshcat-server pid (\d+)")
        url, server_pid = match.group(1), int(match.group(2))
        with urllib.request.urlopen(url, timeout=10) as response:
            assert response.status == 200 and b"meshcat" in response.read().lower()
        viewer.send_signal(signal.SIGINT)
        assert viewer.wait(timeout=20) == 0, viewer.stderr.read()
    finally:
        if viewer.poll() is None:
            viewer.kill()
    assert not Path(f"/proc/{server_pid}").exists()  # the server was stopped and reaped
    with pytest.raises(OSError):
        urllib.request.urlopen(url, timeout=2)


def test_view_of_a_folder_without_scene_is_one_line_exit_2(tmp_path):
    done = subprocess.run([sys.executable, "-m", "tribokin", "view", str(tmp_path)], capture_output=True, text=True)
    assert done.returncode == 2 and len(done.stderr.strip().splitlines()) == 1
    assert "summary.json" in done.stderr and "tribokin run" in done.stderr
