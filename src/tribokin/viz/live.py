"""The live viewer of an output folder: a meshcat server on 127.0.0.1 (:mod:`tribokin.viz.meshcat_server`),
stopped however the viewer ends."""

from __future__ import annotations

import contextlib
import io
import os
import signal
import subprocess
import sys
from collections.abc import Iterator
from dataclasses import dataclass

import meshcat

from tribokin.errors import InputError
from tribokin.viz.scene import SceneInfo, build_scene
from tribokin.viz.scene_file import load_scene_inputs

#: Signals that stop the viewer as Ctrl-C does (``kill``, a closed terminal).
STOP_SIGNALS = (signal.SIGTERM, signal.SIGHUP)


@dataclass
class MeshcatServer:
    """A running :mod:`tribokin.viz.meshcat_server` process and the URLs it listens on."""

    process: subprocess.Popen
    zmq_url: str
    web_url: str

    def stop(self, timeout_s: float = 5.0) -> None:
        """Terminate the server and reap it."""
        self.process.terminate()
        try:
            self.process.wait(timeout_s)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()


def start_server() -> MeshcatServer:
    """Start a meshcat server on 127.0.0.1 that dies with this process (see :mod:`tribokin.viz.meshcat_server`)."""
    process = subprocess.Popen([sys.executable, "-m", "tribokin.viz.meshcat_server", str(os.getpid())],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               start_new_session=True)  # a terminal's Ctrl-C reaches only the viewer
    with process.stdout, process.stderr:
        try:
            lines = [process.stdout.readline().strip() for _ in range(2)]
            urls = dict(line.split("=", 1) for line in lines if "=" in line)
            if set(urls) != {"zmq_url", "web_url"}:  # it ended before printing them
                why = process.stderr.read().strip().splitlines() or [f"exit status {process.wait()}"]
                raise InputError(f"meshcat server did not start: {why[-1]}", "meshcat-server")
        except BaseException:  # that, or Ctrl-C, SIGTERM or SIGHUP while the server starts
            process.kill()
            process.wait()
            raise
    return MeshcatServer(process, urls["zmq_url"], urls["web_url"])


@contextlib.contextmanager
def live_scene(folder, variant: str = "full") -> Iterator[tuple[MeshcatServer, SceneInfo]]:
    """Read the scene of ``folder`` (see :mod:`tribokin.viz.scene_file`), start a server, draw the scene
    into it and yield both; the server is stopped when the block ends, however it ends."""
    inputs = load_scene_inputs(folder)
    server = start_server()
    try:
        with contextlib.redirect_stdout(io.StringIO()):  # meshcat prints its own banner
            vis = meshcat.Visualizer(zmq_url=server.zmq_url)
        info = build_scene(vis, inputs.robot, inputs.q, inputs.poses, inputs.map_layers, inputs.cube,
                           inputs.magnification, variant)
        yield server, info
    finally:
        server.stop()


def _interrupt(signum: int, frame) -> None:
    raise KeyboardInterrupt(signal.Signals(signum).name)


@contextlib.contextmanager
def stop_signals_interrupt() -> Iterator[None]:
    """Within the block, SIGTERM and SIGHUP raise KeyboardInterrupt as Ctrl-C does (main thread only)."""
    previous = {signum: signal.signal(signum, _interrupt) for signum in STOP_SIGNALS}
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler)

