"""One run at a time per output folder: the second is refused while the first runs; a killed run's lock
is taken over."""

import errno
import os
import signal
import subprocess
import sys
import time

import pytest

from conftest import GANTRY_SAMPLED_MAP_TOML
from tribokin import InputError
from tribokin.output.lock import lock_path, output_lock


def test_second_holder_is_refused_until_the_first_releases(tmp_path):
    out = tmp_path / "out"
    with output_lock(out) as path:
        assert path == tmp_path / "out.lock" and path.read_text().split()[0] == str(os.getpid())
        with pytest.raises(InputError) as error:
            with output_lock(out):
                pass  # pragma: no cover
        assert error.value.key == "--out" and f"(pid {os.getpid()} on " in error.value.message
        assert path.exists()  # the refused attempt left the holder's lock alone
    assert not lock_path(out).exists()
    with output_lock(out):
        assert lock_path(out).exists()
    assert list(tmp_path.iterdir()) == []


def test_lock_of_a_killed_process_is_taken_over(tmp_path):
    out = tmp_path / "out"
    holder = subprocess.Popen([sys.executable, "-c", "import sys, time; from tribokin.output.lock import output_lock\n"
                               f"with output_lock({str(out)!r}):\n    print('held', flush=True); time.sleep(60)"],
                              stdout=subprocess.PIPE, text=True)
    assert holder.stdout.readline().strip() == "held"
    with pytest.raises(InputError, match=f"pid {holder.pid} "):
        with output_lock(out):
            pass  # pragma: no cover
    holder.send_signal(signal.SIGKILL)
    holder.wait()
    assert lock_path(out).exists()  # stale: the file stays, its flock went with the process
    with output_lock(out) as path:
        assert path.read_text().split()[0] == str(os.getpid())
    assert not lock_path(out).exists()


def _holds(pid: int, path) -> bool:
    """Whether the lock file at ``path`` names process ``pid`` as its holder."""
    try:
        return path.read_text().split()[:1] == [str(pid)]
    except FileNotFoundError:
        return False


def test_second_run_into_the_same_folder_is_refused_while_the_first_runs(tmp_path):
    study = tmp_path / "study.toml"
    study.write_text(GANTRY_SAMPLED_MAP_TOML.replace("cycles = 400", "cycles = 40000"))  # still running at the end
    out = tmp_path / "out"
    command = [sys.executable, "-m", "tribokin", "run", study, "--out", out, "--report", "none"]
    first = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 60
        while not _holds(first.pid, lock_path(out)) and first.poll() is None and time.monotonic() < deadline:
            time.sleep(0.005)
        for extra in ([], ["--force"], ["--resume"]):
            second = subprocess.run(command + extra, capture_output=True, text=True)
            assert second.returncode == 2 and len(second.stderr.splitlines()) == 1, second.stderr
            assert f"another tribokin run (pid {first.pid} on " in second.stderr and "--out" in second.stderr
            assert first.poll() is None  # the first was still running: the second was refused, not queued
        assert not out.exists() and _holds(first.pid, lock_path(out))
    finally:
        first.send_signal(signal.SIGKILL)
        first.wait()


def test_a_forked_child_does_not_hold_the_lock_after_its_parent_is_killed(tmp_path):
    """A local worker forked during a run inherits the lock's descriptor; it closes it, so the lock ends with the run.
    The child says so once its fork has returned (the descriptor closed), before the parent is killed: until it has
    run, it still holds the lock."""
    out = tmp_path / "out"
    holder = subprocess.Popen([sys.executable, "-c", "import os, time; from tribokin.output.lock import output_lock\n"
                               f"with output_lock({str(out)!r}):\n"
                               "    child = os.fork()\n"
                               "    if child == 0:\n        os.write(1, b'forked\\n')\n        time.sleep(60)\n"
                               "        os._exit(0)\n"
                               "    os.write(1, b'%d\\n' % child); time.sleep(60)"],
                              stdout=subprocess.PIPE, text=True)
    lines = {holder.stdout.readline().strip() for _ in range(2)}  # parent's and child's, each one write, either order
    child = int((lines - {"forked"}).pop())
    try:
        holder.send_signal(signal.SIGKILL)
        holder.wait()
        assert os.path.exists(f"/proc/{child}")  # the child lives on...
        with output_lock(out) as path:  # ...and holds no lock
            assert path.read_text().split()[0] == str(os.getpid())
    finally:
        os.kill(child, signal.SIGKILL)


def test_a_full_disk_when_writing_the_lock_is_one_error_and_leaves_no_lock(tmp_path, monkeypatch):
    def full(fd, data):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(os, "write", full)
    with pytest.raises(InputError, match="disk is full .* a few bytes for the lock file") as error:
        with output_lock(tmp_path / "out"):
            pass  # pragma: no cover
    assert error.value.key == "--out" and list(tmp_path.iterdir()) == []
