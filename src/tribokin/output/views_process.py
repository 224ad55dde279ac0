"""The views of a run (figures, report, scene) drawn by a process of its own, forked when the command starts.

While the command's serial start (its imports, the study, the robot, a map's row heads) keeps one core busy, this
process imports what draws (matplotlib, meshcat: benchmarks/startup.py measures them) on the core that would otherwise
compete with the map's workers for it, loads the study's robot and reads the meshes its report draws. It then draws the
results it is sent into the output folder (:func:`~tribokin.viz.contents.write_views`). The map's statistics, which
the report shows, are sent after them when a local worker computes them (:meth:`ViewsProcess.send_statistics`); else
this process computes them and sends them back. The same files as drawn by the writing process: the same code, the
same inputs.

Forked only on Linux-like systems (``fork``), with two cores or more for this process, and while the command runs no
other thread; else (and through the Python API) the views are drawn by the writing process
(:func:`~tribokin.output.writers.write_results` without one), as they are for results whose poses' samples are large
(:data:`SENT_POSE_BYTES`), and if this process is lost, or declines: its study or robot did not load, or the study
file changed between its reading and the command's.

A map's figures, the end of the run's critical path, are shared with helpers this process forks when it is sent
them (:class:`FigureHelpers`): one per further core, each drawing every (k + 1)-th figure into the same folder
meanwhile; a figure a helper did not draw (it failed, or was killed) is drawn here, its error raised here.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import threading
import traceback
from concurrent.futures import Future
from contextlib import suppress
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, NoReturn

from tribokin.execution import end_with_parent

if TYPE_CHECKING:
    from tribokin.maps.result import MapStatistics

#: The largest poses' samples [bytes] sent to the views' process: sending more would take that much memory twice again
#: (the pickled copy, the process's copy), beyond what the run's memory check counts (a map's results are on disk).
SENT_POSE_BYTES = 64 << 20


class RemoteTraceback(Exception):
    """The traceback, as text, of an unexpected error in the views' process (the cause of the error raised here)."""

    def __str__(self) -> str:
        return self.args[0]


class ViewsProcess:
    """The process that draws a run's views: :meth:`start` it, :meth:`draw` once, :meth:`wait`, :meth:`close`."""

    def __init__(self, process, connection):
        self._process, self._connection = process, connection

    @classmethod
    def start(cls, study, cycles: int | None, seed: int | None, report: str) -> ViewsProcess | None:
        """Fork the process for the study at path ``study`` (with the command line's ``cycles`` and ``seed``) and its
        ``report`` (``"full"``, ``"light"``, ``"none"``), or ``None`` where it would not pay or could deadlock
        (see the module)."""
        if _cores() < 2 or "fork" not in multiprocessing.get_all_start_methods() or threading.active_count() > 1:
            return None
        here, there = multiprocessing.Pipe()
        process = multiprocessing.get_context("fork").Process(
            target=_serve, args=(there, os.getpid(), study, cycles, seed, report), daemon=True, name="tribokin-views")
        process.start()
        there.close()
        return cls(process, here)

    def draw(self, result, folder: Path, report: str, map_layers, cube, summary_follows: bool = False) -> bool:
        """Send ``result`` (a :class:`~tribokin.run.StudyResult`; its robot is the process's own) to be drawn into
        ``folder`` as :func:`~tribokin.viz.contents.write_views` draws it; ``False`` if the process is gone.
        ``summary_follows``: the map's statistics will be sent (:meth:`send_statistics`), not computed there. ``False``
        too for results whose poses' samples take more than ``SENT_POSE_BYTES``: drawn by the writing process."""
        if sum(values.nbytes for pose in result.poses for values in pose.samples().values()) > SENT_POSE_BYTES:
            return False
        try:
            self._connection.send((replace(result, robot=None), folder, report, map_layers, cube, summary_follows))
        except OSError:  # it ended (killed, out of memory): the writing process draws instead
            return False
        return True

    def send_statistics(self, statistics: MapStatistics) -> None:
        """Send the map's statistics (computed meanwhile on a worker) for the report, which waits for them."""
        try:
            self._connection.send(statistics)
        except OSError:  # it ended: :meth:`wait` says so
            pass

    def wait(self) -> tuple[bool, MapStatistics | None]:
        """Whether the views were drawn, and the map's statistics (``None`` without a map, or when sent), once
        they are; ``(False, None)`` if the process ended first, or declined (its study or robot did not load, or the
        study file changed since it read it). Raises the error that drawing raised."""
        try:
            outcome, value, remote = self._connection.recv()
        except (EOFError, OSError):
            return False, None
        if outcome == "error":
            raise value from (None if remote is None else RemoteTraceback(remote))
        return outcome == "done", value

    def close(self) -> None:
        """End the process (at once, if it is still drawing: the output folder is then being discarded)."""
        if self._process.is_alive():
            self._process.kill()
        self._process.join()
        self._connection.close()


def _serve(connection, parent: int, study, cycles, seed, report: str) -> None:
    """The views' process: prepare, then draw the one job sent, reply, and end."""
    from tribokin.errors import TribokinError

    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the command answers Ctrl-C, and ends this process
    end_with_parent(parent)
    robot, study_sha256 = _prepared(study, cycles, seed, report)
    try:
        result, folder, report, map_layers, cube, summary_follows = connection.recv()
    except EOFError:  # the command ended without results to draw (an error, or nothing to run)
        return
    if robot is None or result.reproduce.get("study_sha256") != study_sha256:  # the study changed since, or did not
        connection.send(("declined", None, None))                               # load here: the command draws
        return
    helpers = None
    try:
        from tribokin.viz.contents import write_views

        result = replace(result, robot=robot)
        helpers = FigureHelpers.start(result, folder)  # before this process starts a thread
        if result.map is not None and summary_follows:
            result.map.use_statistics(_received(connection))
        write_views(result, folder, report, map_layers, cube, None if helpers is None else helpers.elsewhere())
        reply = ("done", None if result.map is None or summary_follows else result.map.statistics(), None)
    except BaseException as error:  # noqa: BLE001 - every error goes back to the command, which raises it
        reply = ("error", error, None if isinstance(error, TribokinError) else traceback.format_exc())
    finally:
        if helpers is not None:
            helpers.close()
    try:
        connection.send(reply)
    except Exception:  # noqa: BLE001 - an error that does not pickle goes back as its text
        connection.send(("error", RuntimeError(repr(reply[1])), reply[2]))


def _received(connection) -> Future:
    """The next object ``connection`` receives, as a future (received by a thread, while this one draws)."""
    future = Future()

    def receive() -> None:
        try:
            future.set_result(connection.recv())
        except BaseException as error:  # noqa: BLE001 - the command ended: whoever waits for it learns why
            future.set_exception(error)

    threading.Thread(target=receive, daemon=True).start()
    return future


def _prepared(study, cycles, seed, report: str):
    """Import what draws, load the study's robot (with the meshes its report draws, none for ``"none"``) and read the
    geometry the report draws: the robot and the study's SHA-256, or ``(None, None)`` if either does not load here
    (the command says why, or draws itself)."""
    try:
        import pinocchio.visualize  # noqa: F401 - what draws the robot

        import tribokin.viz.contents  # noqa: F401 - matplotlib, meshcat
        from tribokin.study.assembly import load_robot
        from tribokin.study.reading import load_study
        from tribokin.viz.scene import robot_geometry

        loaded = load_study(study, cycles, seed)
        robot = load_robot(loaded, meshes=report != "none")
        if report != "none":
            robot_geometry(robot, report)
        return robot, loaded.sha256
    except Exception:  # noqa: BLE001 - reported by the command, which checks every input
        return None, None


def _cores() -> int:
    """The cores this process may run on."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


class FigureHelpers:
    """Processes forked from the views' process that draw shares of a map's figures into its output folder meanwhile:
    :meth:`start`, hand :meth:`elsewhere` to :func:`~tribokin.viz.contents.write_views`, :meth:`close` in any
    case."""

    def __init__(self, result, folder: Path, shares: dict[int, list[str]]):
        self._result, self._folder, self._shares = result, folder, shares

    @classmethod
    def start(cls, result, folder: Path) -> FigureHelpers | None:
        """Fork one helper per core beyond this process's first (at most one per map figure but this process's
        first), the i-th drawing figures i, i + k + 1, ... (k helpers) of the map of ``result`` (a
        :class:`~tribokin.run.StudyResult`) into ``folder``; ``None`` without a map, a further core or a second
        figure, or beside another thread (a fork could deadlock). A share whose fork fails is drawn here."""
        if result.map is None or threading.active_count() > 1:
            return None
        from tribokin.viz.maps import map_figure_names

        names = map_figure_names(result.map)
        count = min(_cores() - 1, len(names) - 1)
        if count < 1:
            return None
        shares, parent = {}, os.getpid()
        for i in range(1, count + 1):
            share = names[i::count + 1]
            try:
                pid = os.fork()
            except OSError:  # no process to spare (a limit, memory): this share and the next are drawn here
                break
            if pid == 0:
                _draw_share(parent, result, folder, share)
            shares[pid] = share
        return cls(result, folder, shares) if shares else None

    def elsewhere(self):
        """The figures the helpers draw, and how to wait for them (:class:`~tribokin.viz.contents.DrawnElsewhere`)."""
        from tribokin.viz.contents import DrawnElsewhere

        return DrawnElsewhere(frozenset(name for share in self._shares.values() for name in share), self.wait)

    def wait(self) -> None:
        """Return once every helper has ended; the figures of one that did not end well are drawn here (its error,
        if any, raised here)."""
        from tribokin.viz.maps import save_map_figures

        while self._shares:
            pid, share = next(iter(self._shares.items()))
            _, status = os.waitpid(pid, 0)
            del self._shares[pid]
            if os.waitstatus_to_exitcode(status) != 0:
                save_map_figures(self._result.map, self._folder, self._result.name, share)

    def close(self) -> None:
        """End the helpers still drawing (an error here: the output folder is being discarded)."""
        for pid in self._shares:
            with suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
        self._shares.clear()


def _draw_share(parent: int, result, folder: Path, share: list[str]) -> NoReturn:
    """A helper's life: draw the map figures ``share`` of ``result`` into ``folder``, and end (status 0 once drawn,
    1 on any error: its parent draws them again, and raises it)."""
    status = 1
    try:
        end_with_parent(parent)
        from tribokin.viz.maps import save_map_figures

        save_map_figures(result.map, folder, result.name, share)
        status = 0
    finally:
        os._exit(status)

