"""The live viewer of an output folder: meshcat-server on 127.0.0.1, stopped cleanly on Ctrl-C."""

from __future__ import annotations

import contextlib
import io
import subprocess
import time

import meshcat

from tribokin.viz.scene import SceneInfo, build_scene
from tribokin.viz.scene_file import load_scene_inputs


def start_live_scene(folder, variant: str = "full") -> tuple[meshcat.Visualizer, SceneInfo]:
    """Start a meshcat-server and draw the scene of ``folder`` into it (see :mod:`tribokin.viz.scene_file`)."""
    inputs = load_scene_inputs(folder)
    with contextlib.redirect_stdout(io.StringIO()):  # meshcat prints its own banner
        vis = meshcat.Visualizer()
    try:
        info = build_scene(vis, inputs.robot, inputs.q, inputs.poses, inputs.map_layers, inputs.cube,
                           inputs.magnification, variant)
    except BaseException:
        stop_server(vis)
        raise
    return vis, info


def stop_server(vis: meshcat.Visualizer, timeout_s: float = 5.0) -> None:
    """Terminate the visualizer's meshcat-server subprocess (``Visualizer.close()`` raises on meshcat 0.3.2)."""
    process = vis.window.server_proc
    process.terminate()
    try:
        process.wait(timeout_s)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()


def wait_until_interrupted(vis: meshcat.Visualizer) -> bool:
    """Block until Ctrl-C (True) or until the server dies on its own (False); the server is stopped either way."""
    try:
        while vis.window.server_proc.poll() is None:
            time.sleep(0.2)
        return False
    except KeyboardInterrupt:
        return True
    finally:
        stop_server(vis)
