"""Output folders are written all at once: a run killed while writing leaves no partial folder, and the
next run clears what it left."""

import errno
import os
import signal
import subprocess
import sys
import time

import pytest

from conftest import AXIS_STUDY_TOML, killed_after
from helpers.command import in_process
from tribokin import InputError
from tribokin.cli import main
from tribokin.output.folder import atomic_folder, remove_leftovers

# Six poses: writing their figures and the report takes long enough to be caught in the middle.
STUDY = AXIS_STUDY_TOML.replace('[[poses]]\nname = "P1"\nq = [0.25]\n',
                                "".join(f"[[poses]]\nq = [{0.05 * (k + 1)}]\n" for k in range(6)))


def test_run_killed_while_writing_leaves_no_output_folder(tmp_path):
    study = tmp_path / "study.toml"
    study.write_text(STUDY)
    out = tmp_path / "out"
    command = [sys.executable, "-m", "tribokin", "run", study, "--out", out]
    run = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 60
    while not list(tmp_path.glob(".out.partial-*/poses.csv")) and run.poll() is None and time.monotonic() < deadline:
        time.sleep(0.002)
    run.send_signal(signal.SIGKILL)
    run.wait()
    assert run.returncode == -signal.SIGKILL  # killed while writing, not finished
    assert not out.exists() and len(list(tmp_path.glob(".out.partial-*"))) == 1

    done = in_process(*command[3:])  # the next run: what it clears is the command's doing, not its process's
    assert done.returncode == 0, done.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out", "study.toml"]  # the partial folder was cleared
    assert (out / "report.html").is_file() and len(list(out.glob("field_P*.png"))) == 6


def test_failed_write_removes_its_temporary_folder_and_keeps_the_old_one(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "old.txt").write_text("old")
    with pytest.raises(RuntimeError):
        with atomic_folder(out, force=True) as folder:
            (folder / "new.txt").write_text("new")
            raise RuntimeError("disk full")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"] and (out / "old.txt").read_text() == "old"
    with atomic_folder(out, force=True) as folder:
        (folder / "new.txt").write_text("new")
    assert sorted(p.name for p in out.iterdir()) == ["new.txt"] and sorted(tmp_path.iterdir()) == [out]


def test_folder_that_appears_meanwhile_is_not_replaced_without_force(tmp_path):
    out = tmp_path / "out"
    with pytest.raises(InputError, match="appeared"):
        with atomic_folder(out) as folder:
            (folder / "new.txt").write_text("new")
            out.mkdir()
            (out / "theirs.txt").write_text("theirs")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"] and (out / "theirs.txt").read_text() == "theirs"


def _replace(out) -> None:
    with atomic_folder(out, force=True) as folder:
        (folder / "new.txt").write_text("new")


@pytest.mark.parametrize("can_exchange", [True, False], ids=["exchanged", "moved-aside"])
def test_force_replacement_killed_at_any_step_loses_neither_folder(tmp_path, monkeypatch, can_exchange):
    """Where the system cannot exchange two folders, the old one is moved aside first; the next run moves it back."""
    if not can_exchange:
        monkeypatch.setattr("tribokin.output.folder.exchange", lambda first, second: False)
    out = tmp_path / "out"
    kill_after, restores = 0, 0
    while True:
        kill_after += 1
        out.mkdir()
        (out / "old.txt").write_text("old")
        killed = killed_after(kill_after, ("tribokin.output.folder.exchange", "tribokin.output.folder.remove",
                                           "os.replace"), lambda: _replace(out))
        restored = remove_leftovers(out)  # as the next run does, holding the lock
        assert sorted(tmp_path.iterdir()) == [out]
        contents = {p.name: p.read_text() for p in out.iterdir()}
        assert contents in ({"old.txt": "old"}, {"new.txt": "new"}), kill_after
        restores += restored is not None
        if not killed:
            break
        for path in out.iterdir():
            path.unlink()
        out.rmdir()
    assert contents == {"new.txt": "new"}  # the last run was not killed
    assert (kill_after, restores) == ((3, 0) if can_exchange else (5, 1))  # out was missing at one point only


def test_full_disk_while_writing_is_one_line_and_leaves_nothing(tmp_path, monkeypatch, capsys):
    """The disk is made to fill up while samples.npz is written (no mount needed): the run ends in one line."""
    import tribokin.output.writers

    study = tmp_path / "study.toml"
    study.write_text(STUDY)
    real = tribokin.output.writers.write_samples

    def fills_the_disk(result, folder):
        real(result, folder)
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(folder / "samples.npz"))

    monkeypatch.setattr("tribokin.output.writers.write_samples", fills_the_disk)
    status = main(["run", str(study), "--out", str(tmp_path / "out"), "--report", "none"])
    error = capsys.readouterr().err
    assert status == 2 and len(error.splitlines()) == 1 and "Traceback" not in error, error
    assert "samples.npz" in error and "needed more than " in error and "--out" in error
    assert sorted(p.name for p in tmp_path.iterdir()) == ["study.toml"]


def test_next_run_moves_back_an_output_folder_a_killed_force_run_left_aside_and_says_so(tmp_path, capsys):
    study = tmp_path / "study.toml"
    study.write_text(STUDY)
    aside = tmp_path / ".out.old-x1y2"  # as a --force run killed between its two renames leaves it
    (aside / "out").mkdir(parents=True)
    (aside / "out" / "old.txt").write_text("old")
    status = main(["run", str(study), "--out", str(tmp_path / "out"), "--report", "none"])
    captured = capsys.readouterr()
    assert f"moved '{tmp_path / 'out'}' back from '{aside}'" in captured.out
    assert status == 2 and "output folder exists" in captured.err  # now it does: --force would replace it
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out", "study.toml"]
    assert (tmp_path / "out" / "old.txt").read_text() == "old"
