"""Files resolved and confined before anything opens them: tribokin.confinement."""

from __future__ import annotations

import os
import socket

import pytest

from tribokin.confinement import confined_file, regular_file
from tribokin.errors import InputError

SECRET = "tribokin-secret-marker-7f3a"


@pytest.fixture
def tree(tmp_path):
    """``study/`` holding ``log.csv`` and ``data/``; ``outside/secret.csv`` beside it."""
    (tmp_path / "study" / "data").mkdir(parents=True)
    (tmp_path / "outside").mkdir()
    (tmp_path / "study" / "log.csv").write_text("cycle,mu\n")
    (tmp_path / "study" / "data" / "in.csv").write_text("cycle,mu\n")
    (tmp_path / "outside" / "secret.csv").write_text(SECRET)
    return tmp_path


def _refused(call, *words) -> InputError:
    with pytest.raises(InputError) as caught:
        call()
    line = caught.value.one_line()
    assert SECRET not in line and "\n" not in line
    for word in words:
        assert word in line, (word, line)
    return caught.value


def test_a_file_inside_a_root_resolves_to_its_real_path(tree):
    study = tree / "study"
    assert confined_file(study / "log.csv", [study], "s.toml", "log") == study / "log.csv"
    assert confined_file(study / "data" / ".." / "log.csv", [study], "s.toml", "log") == study / "log.csv"
    (study / "link.csv").symlink_to("data/in.csv")
    assert confined_file(study / "link.csv", [study], "s.toml", "log") == study / "data" / "in.csv"


def test_a_listed_folder_admits_a_file_outside_the_first(tree):
    study, outside = tree / "study", tree / "outside"
    assert confined_file(outside / "secret.csv", [study, study / ".." / "outside"], "s.toml", "log") == \
        outside / "secret.csv"


@pytest.mark.parametrize("name", ["absolute", "dot-dot", "symlink", "symlinked-folder", "missing-outside"])
def test_a_path_out_of_the_roots_is_refused_naming_source_key_and_remedy(tree, name):
    study, secret = tree / "study", tree / "outside" / "secret.csv"
    if name == "symlink":
        (study / "link.csv").symlink_to(secret)
    if name == "symlinked-folder":
        (study / "data" / "out").symlink_to(tree / "outside")
    path = {"absolute": secret, "dot-dot": study / ".." / "outside" / "secret.csv", "symlink": study / "link.csv",
            "symlinked-folder": study / "data" / "out" / "secret.csv",
            "missing-outside": tree / "outside" / "nothing.csv"}[name]
    error = _refused(lambda: confined_file(path, [study], "s.toml", "joints.friction.log"), "outside",
                     str(study), "study.data_dirs", "move it under")
    assert error.source == "s.toml" and error.key == "joints.friction.log"
    if name not in ("absolute", "missing-outside"):  # given as they resolve
        assert f"(resolved: {tree / 'outside'}" in error.message


def test_a_root_given_through_a_symlink_is_resolved_too(tree):
    (tree / "alias").symlink_to(tree / "study")
    assert confined_file(tree / "alias" / "log.csv", [tree / "alias"], "s.toml", "log") == tree / "study" / "log.csv"


@pytest.mark.parametrize("path", ["/proc/self/environ", "/proc/self/cmdline", "/dev/zero", "/dev/null",
                                  "/sys/kernel/mm/transparent_hugepage/enabled"])
def test_system_files_are_refused_even_inside_a_root(path):
    _refused(lambda: regular_file(path, "command line", "FILE"), "system file", "/proc")
    _refused(lambda: confined_file(path, ["/"], "s.toml", "log"), "system file")


def test_a_symlink_to_a_system_file_is_refused(tree):
    (tree / "study" / "env.csv").symlink_to("/proc/self/environ")
    _refused(lambda: regular_file(tree / "study" / "env.csv", "command line", "FILE"), "system file",
             "(resolved: /proc/")


def test_special_files_are_refused_without_opening_them(tree):
    fifo = tree / "study" / "fifo.csv"
    os.mkfifo(fifo)  # opening it to read would block: the check must not open it
    _refused(lambda: confined_file(fifo, [tree / "study"], "s.toml", "log"), "FIFO", "name a regular file")
    _refused(lambda: regular_file(tree / "study" / "data", "command line", "FILE"), "a folder")
    with socket.socket(socket.AF_UNIX) as server:
        server.bind(str(tree / "study" / "sock.csv"))
        _refused(lambda: regular_file(tree / "study" / "sock.csv", "command line", "FILE"), "a socket")


def test_missing_files_and_loops(tree):
    study = tree / "study"
    error = _refused(lambda: regular_file(study / "none.csv", study / "none.csv"), "file not found")
    assert error.message == "file not found; check the path"  # the file itself is the source: named once
    _refused(lambda: confined_file(study / "none.csv", [study], "s.toml", "log", "not found; write it"),
             f"'{study / 'none.csv'}'", "not found; write it")
    (study / "a.csv").symlink_to("b.csv")
    (study / "b.csv").symlink_to("a.csv")
    _refused(lambda: regular_file(study / "a.csv", "command line", "FILE"), "cannot be read")


def test_a_path_with_a_nul_is_one_error():
    _refused(lambda: regular_file("a\0b.csv", "command line", "FILE"), "not a path")
