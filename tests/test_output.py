"""Output folders are written all at once: a run killed while writing leaves no partial folder, and the
next run clears what it left."""

import signal
import subprocess
import sys
import time

import pytest

from conftest import AXIS_STUDY_TOML
from tribokin import InputError
from tribokin.output import atomic_folder

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
    while not list(tmp_path.glob(".out.partial-*/summary.json")) and run.poll() is None and time.monotonic() < deadline:
        time.sleep(0.002)
    run.send_signal(signal.SIGKILL)
    run.wait()
    assert run.returncode == -signal.SIGKILL  # killed while writing, not finished
    assert not out.exists() and len(list(tmp_path.glob(".out.partial-*"))) == 1

    done = subprocess.run(command, capture_output=True, text=True)
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
