"""Bad input through the `tribokin` command, as a table: study files, URDFs, tribometer logs, surface
profiles and command-line options.

Every case must give exit status 2 and exactly one line on stderr (``tribokin: error: ...``) naming the
file and the key at fault, no traceback, and leave the folder it ran in exactly as it was: no output
folder, no temporary or chunk folder, no lock file, pre-existing files untouched.
"""

from __future__ import annotations

import ctypes
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import AXIS_STUDY_TOML, AXIS_URDF, GANTRY_SAMPLED_MAP_TOML, ROOT
from helpers.measurement_files import GANTRY_CALIBRATE
from tribokin.cli import main
from tribokin.simulation.pose_test import PoseRunner


def _replace(text: str, old: str, new: str) -> str:
    assert old in text, old  # a case whose edit does not apply would test nothing
    return text.replace(old, new)


class Symlink(str):
    """A file of a case that is a symbolic link to this target."""


class Fifo(str):
    """A file of a case that is a FIFO (named pipe): reading it would block until something writes to it."""


STUDY = AXIS_STUDY_TOML
GANTRY_MAP = _replace(_replace(GANTRY_SAMPLED_MAP_TOML, "cycles = 400", "cycles = 5"), "resolution = [25, 40]",
                      "resolution = [4, 3]")

#: GANTRY_MAP with a pose, and a joint-space map of the axis after its pose: refusals of these must come before
#: the pose runs.
GANTRY_MAP_AND_POSE = GANTRY_MAP + '\n[[poses]]\nname = "P1"\nq = [0.3, 0.2, 0.1]\n'
AXIS_JOINT_MAP = STUDY + '\n[map]\nkind = "joint"\njoints = ["x"]\nranges = [[0.0, 0.3]]\ncounts = [4]\n'
#: AXIS_JOINT_MAP whose joint's friction is a time series (lag-one correlation 0.5), and one that warms up too.
SERIES_MAP = _replace(AXIS_JOINT_MAP, '{ preset = "42CD4-raw" }', '{ preset = "42CD4-raw", ar1 = 0.5 }')
WARMING_MAP = _replace(_replace(_replace(SERIES_MAP, "ar1 = 0.5", "ar1 = 0.5, thermal = { mu_per_K = -0.005 }"),
                                "seed = 3", "seed = 3\ncycle_time_s = 4.0"), "stiffness = 2.0e6",
                       "stiffness = 2.0e6\ntravel_per_cycle = 0.5")
SCENARIOS = '[[scenarios]]\nname = "raw"\n\n[[scenarios]]\nname = "b"\n\n[[scenarios]]\nname = "ratio_b"\n\n[map]'

MESHY_URDF = """<?xml version="1.0"?>
<robot name="meshy">
  <link name="base"><visual><geometry><mesh filename="package://pkg/../../evil.stl"/></geometry></visual></link>
  <joint name="x" type="prismatic"><parent link="base"/><child link="tool"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.4" effort="100" velocity="1"/></joint>
  <link name="tool"/>
</robot>
"""
#: The gantry whose base is drawn from the mesh ``{mesh}``.
MESHY_GANTRY_URDF = _replace((ROOT / "urdf" / "cartesian_xyz.urdf").read_text(),
                             '<geometry><box size="0.90 0.06 1.00"/></geometry>\n      <material',
                             '<geometry><mesh filename="{mesh}"/></geometry>\n      <material')
MESHY_GANTRY_MAP = _replace(GANTRY_MAP, f'urdf = "{ROOT / "urdf" / "cartesian_xyz.urdf"}"',
                            'urdf = "share/pkg/gantry.urdf"\npackage_dirs = ["share"]')
STL = ("solid t\nfacet normal 0 0 1\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 1 0\n endloop\n"
       "endfacet\nendsolid t\n")

#: The shipped two-link study, its xacro and package folder named by absolute paths.
TWO_LINK = _replace((ROOT / "studies" / "two-link-xacro.toml").read_text(), '"../urdf', f'"{ROOT}/urdf')
#: A one-joint arm in xacro, ``{include}`` replaced by a case's include.
ONE_JOINT_XACRO = """<robot name="one" xmlns:xacro="http://www.ros.org/wiki/xacro">
  {include}
  <link name="base"/>
  <joint name="x" type="prismatic"><parent link="base"/><child link="tool"/><axis xyz="1 0 0"/>
    <limit lower="0" upper="0.4" effort="100" velocity="1"/></joint>
  <link name="tool"/>
</robot>
"""
XACRO_URDF = 'urdf = "share/pkg/one.urdf.xacro"\npackage_dirs = ["share"]'


def xacro_case(include: str, *, expected, id, files=None):
    """A `tribokin run` case of the axis study on ``share/pkg/one.urdf.xacro`` including ``include``."""
    return study(f'urdf = "{AXIS_URDF}"', XACRO_URDF, expected=expected, id=id,
                 files={"share/pkg/one.urdf.xacro": ONE_JOINT_XACRO.format(include=include), **(files or {})})


GOOD_LOG = "cycle,mu\n" + "\n".join(f"{i},{0.12 + 0.01 * np.sin(i)}" for i in range(1, 41)) + "\n"
GOOD_PROFILE = "x_m,z_m\n" + "\n".join(f"{i * 1e-6},{1e-6 * np.sin(i / 3)}" for i in range(200)) + "\n"
TURNED = AXIS_URDF.parents[1] / "src" / "tribokin" / "data" / "profiles" / "turned.csv"
#: A surface law on the shipped profile, copied beside the study (``TURNED_FILE``): a study reads only its own folder's.
SURFACE_LAW = '{ surface = "turned.csv", normal_force_N = 150.0, contact_area_m2 = 1e-6, film_thickness_m = 1.2e-6 }'
TURNED_FILE = {"turned.csv": TURNED.read_bytes()}


def study(old: str | None = None, new: str = "", *options, expected, id, base=STUDY, files=None,
          at_fault="study.toml"):
    """A `tribokin run` case: ``base`` with ``old`` replaced by ``new``; stderr must name the file ``at_fault``."""
    text = base if old is None else _replace(base, old, new)
    return pytest.param({"study.toml": text, **(files or {})},
                        ["run", "{tmp}/study.toml", "--out", "{tmp}/out", "--report", "none", *options],
                        (f"{{tmp}}/{at_fault}", *expected), id=id)


def friction(law: str, *, expected, id):
    """A `tribokin run` case with ``joints.friction = law`` (the profile of ``SURFACE_LAW`` beside the study)."""
    return study('{ preset = "42CD4-raw" }', law, expected=expected, id=id, files=TURNED_FILE)


def map_state(line: str, base: str, expected, id):
    """A `tribokin run` case of ``base``'s joint map, not directional, with the ``[map]`` line ``line`` added."""
    return study("counts = [4]", f"counts = [4]\ndirectional = false\n{line}", base=base, expected=expected, id=id)


def measurement(command: str, content, *options, expected, id, at_fault="{tmp}/in.csv", files=None):
    """A `tribokin fit-friction` or `tribokin surface` case on ``in.csv`` (``None``: no such file)."""
    files = {**({} if content is None else {"in.csv": content}), **(files or {})}
    return pytest.param(files, [command, "{tmp}/in.csv", "--out", "{tmp}/out", *options],
                        (at_fault, *expected), id=id)


def command(argv, *, expected, id, files=None):
    """A case given as a whole command line."""
    return pytest.param({"study.toml": STUDY, **(files or {})}, argv, expected, id=id)


RUN = ["run", "{tmp}/study.toml", "--out", "{tmp}/out", "--report", "none"]

#: Written into the files a case must not read: no output of the case may hold it.
SECRET = "TRIBOKIN-SECRET-c0ffee"
SECRET_LOG = f"{SECRET},mu\n" + GOOD_LOG
SECRET_LAW = f'law = "constant"\nmu = 0.1\n# {SECRET}\n'
#: The study of the confinement cases sits in ``s/`` under the case's folder: ``{tmp}/secret.csv`` is outside it.
INNER_RUN = ["run", "{tmp}/s/study.toml", "--out", "{tmp}/out", "--report", "none"]
SURFACE_KEYS = "normal_force_N = 150.0, contact_area_m2 = 1e-6, film_thickness_m = 1.2e-6"


def confined(law: str, *, expected, id, files=None, base=STUDY, at_fault="s/study.toml"):
    """A `tribokin run` case of ``s/study.toml``: ``base`` with ``joints.friction = law`` (``{tmp}`` in the study's
    text is the case's folder)."""
    text = _replace(base, '{ preset = "42CD4-raw" }', law)
    return pytest.param({"s/study.toml": text, "secret.csv": SECRET_LOG, "secret.toml": SECRET_LAW, **(files or {})},
                        INNER_RUN, (f"{{tmp}}/{at_fault}", *expected), id=id)


OUTSIDE = ("outside the folders a study may read ({tmp}/s)", "study.data_dirs")
CALIBRATION_STUDY = STUDY + '\n[calibration]\nfit = ["stiffness"]\nnoise_floor_m = 1e-6\n'

# issue 35: files a study names resolve (symlinks followed) inside its folder or its study.data_dirs before anything
# opens them; no system file, FIFO or device is read; no error quotes a file's content
CONFINEMENT_CASES = [
    confined('{ log = "{tmp}/secret.csv" }', expected=("joints.friction.log", *OUTSIDE), id="confine-log-absolute"),
    confined('{ log = "../secret.csv" }', expected=("joints.friction.log", *OUTSIDE, "(resolved: {tmp}/secret.csv)"),
             id="confine-log-dot-dot"),
    confined('{ log = "link.csv" }', files={"s/link.csv": Symlink("../secret.csv")},
             expected=("joints.friction.log", *OUTSIDE, "(resolved: {tmp}/secret.csv)"), id="confine-log-symlink-out"),
    confined('{ log = "data/secret.csv" }', files={"s/data": Symlink("..")},
             expected=("joints.friction.log", *OUTSIDE, "(resolved: {tmp}/secret.csv)"),
             id="confine-log-symlinked-folder-out"),
    confined('{ log = "/etc/passwd" }', expected=("joints.friction.log", *OUTSIDE), id="confine-log-etc-passwd"),
    confined('{ file = "{tmp}/secret.toml" }', expected=("joints.friction.file", *OUTSIDE),
             id="confine-law-file-absolute"),
    confined('{ file = "../secret.toml" }', expected=("joints.friction.file", *OUTSIDE), id="confine-law-file-dot-dot"),
    confined('{ file = "law.toml" }', files={"s/law.toml": 'log = "../secret.csv"\n'}, at_fault="s/law.toml",
             expected=("log", *OUTSIDE), id="confine-law-file-naming-a-log-outside"),
    confined(f'{{ surface = "../secret.csv", {SURFACE_KEYS} }}', expected=("joints.friction.surface", *OUTSIDE),
             id="confine-surface-dot-dot"),
    confined(f'{{ surface = "/proc/self/environ", {SURFACE_KEYS} }}',
             expected=("joints.friction.surface", "outside the folders"), id="confine-surface-proc-environ"),
    confined(f'{{ surface = "/proc/self/environ", {SURFACE_KEYS} }}', base=STUDY.replace("seed = 3", 'seed = 3\n'
                                                                                          'data_dirs = ["/"]'),
             expected=("joints.friction.surface", "system file under /proc"), id="confine-surface-proc-data-dirs-root"),
    confined('{ log = "/dev/zero" }', base=STUDY.replace("seed = 3", 'seed = 3\ndata_dirs = ["/"]'),
             expected=("joints.friction.log", "'/dev/zero' is a system file"), id="confine-log-dev-zero"),
    confined('{ log = "pipe.csv" }', files={"s/pipe.csv": Fifo()},
             expected=("joints.friction.log", "is a FIFO (named pipe)"), id="confine-log-fifo"),
    confined('{ log = "logs" }', files={"s/logs/x.csv": GOOD_LOG},
             expected=("joints.friction.log", "is a folder"), id="confine-log-folder"),
    confined('{ preset = "42CD4-raw" }', base=STUDY.replace('q = [0.25]', 'q = [0.25]\nfriction = { log = '
                                                                          '"../secret.csv" }'),
             expected=("poses[0].friction.log", *OUTSIDE), id="confine-pose-log-dot-dot"),
    confined('{ preset = "42CD4-raw" }', base=GANTRY_MAP.replace(
        "[map]", '[[scenarios]]\nname = "logged"\njoints = { friction = { log = "../secret.csv" } }\n\n[map]'),
             expected=("scenarios[0].joints.friction.log", *OUTSIDE), id="confine-scenario-log-dot-dot"),
    # study.data_dirs admits a folder outside the study's: the log there is read (and then found too short)
    confined('{ log = "../logs/short.csv" }', base=STUDY.replace("seed = 3", 'seed = 3\ndata_dirs = ["../logs"]'),
             files={"logs/short.csv": "cycle,mu\n1,0.1\n"}, at_fault="s/../logs/short.csv",
             expected=("mu", "at least 20"), id="confine-data-dirs-admits-a-folder-outside"),
    confined('{ log = "../logs/short.csv" }', base=STUDY.replace("seed = 3", 'seed = 3\ndata_dirs = ["../log"]'),
             files={"logs/short.csv": "cycle,mu\n1,0.1\n"},
             expected=("joints.friction.log", "outside the folders a study may read ({tmp}/s, {tmp}/log)"),
             id="confine-data-dirs-lists-another-folder"),
    # files given on the command line: anywhere, but no system file, FIFO or device, and no content in the error
    measurement("fit-friction", None, files={"in.csv": Symlink("/proc/self/environ")},
                expected=("(resolved: /proc/", "system file"), id="confine-fit-friction-proc-environ"),
    command(["fit-friction", "/proc/self/environ", "--out", "{tmp}/out"],
            expected=("/proc/self/environ: ", "system file"), id="confine-fit-friction-proc-environ-absolute"),
    command(["surface", "/dev/zero", "--out", "{tmp}/out"], expected=("/dev/zero: ", "system file"),
            id="confine-surface-dev-zero"),
    measurement("surface", Fifo(), expected=("is a FIFO",), id="confine-surface-fifo"),
    command(["measure", "/proc/self/environ", "--out", "{tmp}/out"], expected=("/proc/self/environ: ", "system file"),
            id="confine-measure-proc-environ"),
    command(["measure", "{tmp}/in.csv", "--out", "{tmp}/out", "--noise-floor", "/dev/zero"],
            files={"in.csv": "pose,cycle,x_m,y_m,z_m\nP,1,0,0,0\nP,2,0,0,0\n"},
            expected=("/dev/zero: ", "system file"), id="confine-measure-noise-floor-dev-zero"),
    command(["calibrate", "{tmp}/study.toml", "--measurements", "/proc/self/environ", "--out", "{tmp}/out"],
            files={"study.toml": CALIBRATION_STUDY}, expected=("/proc/self/environ: ", "system file"),
            id="confine-calibrate-measurements-proc-environ"),
    command(["run", "/proc/self/environ", "--out", "{tmp}/out"], expected=("/proc/self/environ: ", "system file"),
            id="confine-run-study-proc-environ"),
    study(f'urdf = "{AXIS_URDF}"', 'urdf = "/proc/self/environ"', expected=("robot.urdf", "system file"),
          id="confine-robot-urdf-proc-environ"),
    study(f'urdf = "{AXIS_URDF}"', 'urdf = "robot.urdf"', files={"robot.urdf": Symlink("/proc/self/environ")},
          expected=("robot.urdf", "(resolved: /proc/", "system file"), id="confine-robot-urdf-symlink-proc"),
    study(f'urdf = "{AXIS_URDF}"', 'urdf = "robot.urdf.xacro"',
          files={"robot.urdf.xacro": Symlink("/proc/self/environ")},
          expected=("robot.urdf", "(resolved: /proc/", "system file"), id="confine-robot-xacro-symlink-proc"),
    measurement("fit-friction", SECRET_LOG.replace(",mu", ",friction"), expected=("mu", "line 1: expected a header"),
                id="confine-log-header-not-quoted"),
    measurement("fit-friction", GOOD_LOG.replace("\n8,", f"\n8,{SECRET}\n#"),
                expected=("mu", "line 9, column 2: expected a finite number"), id="confine-log-cell-not-quoted"),
    measurement("surface", GOOD_PROFILE.replace("\n2e-06,", f"\n2e-06,{SECRET}\n#"),
                expected=("z_m", "line 4, column 2: expected a finite number"), id="confine-profile-cell-not-quoted"),
    command(["measure", "{tmp}/in.csv", "--out", "{tmp}/out"],
            files={"in.csv": f"pose,cycle,x_m,y_m,z_m,{SECRET}\nP,1,0,0,0,0\nP,2,0,0,0,0\n"},
            expected=("in.csv: line 1, column 6: unknown column",), id="confine-measure-header-not-quoted"),
    command(["measure", "{tmp}/in.csv", "--out", "{tmp}/out"],
            files={"in.csv": f"pose,cycle,x_m,y_m,z_m\nP,1,0,0,0\nP,2,0,{SECRET},0\n"},
            expected=("in.csv: y_m: line 3, column 4: expected a finite number",),
            id="confine-measure-cell-not-quoted"),
    command(["calibrate", "{tmp}/study.toml", "--measurements", "{tmp}/in.csv", "--out", "{tmp}/out"],
            files={"study.toml": CALIBRATION_STUDY, "in.csv": f"{SECRET},cycle,x_m,y_m,z_m\nP,1,0,0,0\n"},
            expected=("in.csv: line 1, column 1: unknown column",), id="confine-calibrate-header-not-quoted"),
    confined('{ file = "law.toml" }', files={"s/law.toml": f'file = "{SECRET}"\n'}, at_fault="s/law.toml",
             expected=("file", "not another law file"), id="confine-law-file-name-not-quoted"),
]

# issue 19: names and pre-checks: refused before any pose or map target is measured
PRE_CHECKS = [
    study('name = "gantry-resume"', 'name = "gantry/resume"', base=GANTRY_MAP_AND_POSE,
          expected=("study.name", "'/'"), id="study-name-slash"),
    study('name = "P1"', 'name = "a/b"', expected=("poses[0].name", "'/'"), id="pose-name-slash"),
    study('name = "P1"', 'name = "a\\u0000b"', expected=("poses[0].name", "'a\\x00b'", "not printable"),
          id="pose-name-nul"),
    study('name = "P1"', 'name = "a\\tb"', expected=("poses[0].name", "not printable"), id="pose-name-tab"),
    study('name = "P1"', 'name = "' + "p" * 300 + '"', expected=("poses[0].name", "300 characters", "at most 100"),
          id="pose-name-300-characters"),
    study('name = "P1"', 'name = "' + "€" * 90 + '"', expected=("poses[0].name", "280 bytes", "255"),
          id="pose-name-too-many-bytes"),
    study('name = "P1"', 'name = ".P1"', expected=("poses[0].name", "starts with '.'"), id="pose-name-hidden"),
    study('[[poses]]\nname = "P1"', '[[poses]]\nname = "p1"\nq = [0.1]\n[[poses]]\nname = "P1"',
          expected=("poses[1].name", "writes field_P1.png, as poses[0].name does (field_p1.png", "case"),
          id="pose-names-differ-in-case"),
    study('name = "P1"', 'name = "p1"',
          base=_replace(GANTRY_MAP_AND_POSE, "[map]", "[iso_cube]\ncenter_m = [0.4, 0.3, 0.3]\nside_m = 0.1\n\n[map]"),
          expected=("poses[0].name", "writes field_p1.png, as iso_cube does (field_P1.png"),
          id="pose-name-clashes-with-iso-cube"),
    study("[map]", SCENARIOS, base=GANTRY_MAP_AND_POSE,
          expected=("scenarios[2].name", "writes map_RP_l_ratio_b.png, as scenarios[1].name does"),
          id="scenario-files-collide"),
    study('name = "ratio_b"', 'name = ".b"', base=_replace(GANTRY_MAP_AND_POSE, "[map]", SCENARIOS),
          expected=("scenarios[2].name", "starts with '.'"), id="scenario-name-hidden"),
    study('name = "ratio_b"', 'name = "c"\njoints = { w = { stiffness = 1.0 } }',
          base=_replace(GANTRY_MAP_AND_POSE, "[map]", SCENARIOS),
          expected=("scenarios[2].joints.w", "unknown joint 'w'"), id="scenario-joint-unknown"),
    # -- a scenario's robot: loaded (and checked as [robot] is) before the pose runs
    study('name = "ratio_b"', 'name = "c"\nrobot = { name = "ur55" }',
          base=_replace(GANTRY_MAP_AND_POSE, "[map]", SCENARIOS),
          expected=("scenarios[2].robot.name", "unknown robot 'ur55' (did you mean 'ur5'?)"),
          id="scenario-robot-unknown"),
    study('name = "ratio_b"', 'name = "c"\nrobot = { urdf = "missing.urdf" }',
          base=_replace(GANTRY_MAP_AND_POSE, "[map]", SCENARIOS),
          expected=("scenarios[2].robot.urdf", "{tmp}/missing.urdf' not found"), id="scenario-urdf-missing"),
    study('name = "ratio_b"', 'name = "c"\nrobot = { urdf = "share/pkg/gantry.urdf", package_dirs = ["share"] }',
          base=_replace(GANTRY_MAP_AND_POSE, "[map]", SCENARIOS),
          files={"share/pkg/gantry.urdf": MESHY_GANTRY_URDF.format(mesh="../evil.stl"), "evil.stl": STL},
          expected=("scenarios[2].robot.package_dirs", "evil.stl", "{tmp}/share"), id="scenario-mesh-outside"),
    study('name = "ratio_b"',
          f'name = "c"\nrobot = {{ urdf = "{ROOT}/urdf/two_link_description/urdf/two_link.urdf.xacro", '
          f'package_dirs = ["{ROOT}/urdf"], tool_frame = "tool", xacro_args = {{ upper_arm = "0.5" }} }}',
          base=_replace(GANTRY_MAP_AND_POSE, "[map]", SCENARIOS),
          expected=("scenarios[2].robot.xacro_args.upper_arm", "has no argument 'upper_arm'"),
          id="scenario-xacro-unknown-argument"),
    study('name = "ratio_b"', 'name = "c"\nrobot = { name = "ur5" }',
          base=_replace(GANTRY_MAP_AND_POSE, "[map]", SCENARIOS + "\nstart_q = [0.3, 0.2, 0.1]"),
          expected=("scenarios[2].map.start_q", "6"), id="scenario-robot-start-posture"),
    study('name = "raw"', 'name = "raw"\nrobot = { name = "ur5" }',
          base=_replace(GANTRY_MAP_AND_POSE, "[map]", SCENARIOS),
          expected=("scenarios[0].robot.name", "the first scenario is the reference"), id="scenario-reference-robot"),
    study('joints = ["x"]', 'joints = ["w"]', base=AXIS_JOINT_MAP, expected=("map.joints[0]", "unknown joint 'w'"),
          id="map-joint-unknown"),
    study("ranges = [[0.0, 0.3]]", "ranges = [[0.0, 0.5]]", base=AXIS_JOINT_MAP,
          expected=("map.ranges[0]", "leaves the limits"), id="map-range-outside-limits"),
    study("[map]", "[map]\nrpy_deg = [0, 0, 0]", base=GANTRY_MAP_AND_POSE,
          expected=("map.rpy_deg", "cannot hold the tool's orientation"), id="map-rpy-without-orientation"),
    study("[map]", "[map]\nstart_q = [0.1, 0.1]", base=GANTRY_MAP_AND_POSE, expected=("map.start_q",),
          id="map-start-q-wrong-length"),
]

#: What a xacro attack may read: a file outside the package folders (the rows' stderr must not hold its text).
XACRO_SECRET = "tribokin-secret\n"
#: A summary.json naming the xacro of ``xacro_case`` (relative paths: from the case's folder, where it runs).
XACRO_SUMMARY = ('{"study": {"robot_spec": {"urdf": "share/pkg/one.urdf.xacro", "name": null, "tool_frame": "tool", '
                 '"package_dirs": ["share"], "payload_kg": 0.0}}, "poses": []}')


def xacro_attack(payload: str, *, expected, id, key="urdf"):
    """The xacro line ``payload`` through every command that expands xacro: ``run``, ``robots --frames``, ``view`` of a
    folder whose summary.json names it, a scenario's robot, ``calibrate``; the key at fault is ``robot.<key>``. A
    payload writes ``pwned`` in the case's folder, or reads ``secret.txt`` beside it, when it runs."""
    files = {"share/pkg/one.urdf.xacro": ONE_JOINT_XACRO.format(include=payload), "secret.txt": XACRO_SECRET,
             "secret.yaml": f"token: {XACRO_SECRET}"}
    scenario = ('name = "c"\n'
                'robot = { urdf = "share/pkg/one.urdf.xacro", package_dirs = ["share"], tool_frame = "tool" }')
    calibration = '\n[calibration]\nfit = ["stiffness"]\nnoise_floor_m = 1e-5\n'
    return [
        study(f'urdf = "{AXIS_URDF}"', XACRO_URDF, expected=(f"robot.{key}", *expected), id=f"{id}-run", files=files),
        command(["robots", "--frames", "{tmp}/share/pkg/one.urdf.xacro"],
                expected=("command line: --frames", *expected), id=f"{id}-robots-frames", files=files),
        pytest.param({**files, "out/summary.json": XACRO_SUMMARY, "out/scene.npz": b""}, ["view", "{tmp}/out"],
                     ("{tmp}/out/summary.json", f"robot.{key}", *expected), id=f"{id}-view"),
        study('name = "ratio_b"', scenario, base=_replace(GANTRY_MAP_AND_POSE, "[map]", SCENARIOS),
              expected=(f"scenarios[2].robot.{key}", *expected), id=f"{id}-scenario", files=files),
        pytest.param({**files, "study.toml": _replace(STUDY, f'urdf = "{AXIS_URDF}"', XACRO_URDF) + calibration},
                     ["calibrate", "{tmp}/study.toml", "--measurements", "{tmp}/m.csv", "--out", "{tmp}/fit",
                      "--report", "none"], ("{tmp}/study.toml", f"robot.{key}", *expected), id=f"{id}-calibrate"),
    ]


def xacro_file_case(text: str, *, expected, id):
    """A `tribokin run` case of the axis study on ``share/pkg/one.urdf.xacro`` holding ``text``."""
    return study(f'urdf = "{AXIS_URDF}"', XACRO_URDF, expected=expected, id=id,
                 files={"share/pkg/one.urdf.xacro": text})


def _grown(lines: list[str]) -> str:
    return "\n".join(['<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">', *lines, "</robot>"])


# issue 35: a robot description runs no code, reads nothing outside, and its expansion is bounded
XACRO_ATTACKS = [
    *xacro_attack("<origin xyz=\"${[c for c in [xacro.load_yaml] if c.__globals__['os'].system('touch pwned') or True] "
                  "and 0.5}\"/>", expected=("a list comprehension is not allowed in $",), id="xacro-comprehension"),
    *xacro_attack("<link name=\"${(lambda f: f.__globals__['__builtins__']['open']('secret.txt').read())"
                  "(xacro.load_yaml)}\"/>", expected=("lambda is not allowed in $",), id="xacro-lambda"),
    *xacro_attack("<link name=\"${list(c.__globals__['os'].system('touch pwned') for c in [xacro.load_yaml])}\"/>",
                  expected=("a generator expression is not allowed in $",), id="xacro-generator"),
    *xacro_attack("<link name=\"${xacro.load_yaml.__globals__['__builtins__']['open']('secret.txt').read()}\"/>",
                  expected=("an attribute whose name starts with '_' is not allowed in $",), id="xacro-attribute"),
    *xacro_attack("<xacro:property name=\"p\" value=\"open('secret.txt').read()\"/><link name=\"$(eval ${p})\"/>",
                  expected=("name 'open' is not defined",), id="xacro-eval-open"),
    *xacro_attack("<link name=\"${xacro.load_yaml('../../secret.yaml')}\"/>", key="package_dirs",
                  expected=("xacro opens '{tmp}/share/pkg/../../secret.yaml', which resolves to '{tmp}/secret.yaml', "
                            "outside",), id="xacro-load-yaml-outside"),
    xacro_file_case(_grown(['<xacro:macro name="m0"><link name="l"/></xacro:macro>',
                            *(f'<xacro:macro name="m{k}"><xacro:m{k - 1}/><xacro:m{k - 1}/></xacro:macro>'
                              for k in range(1, 27)), "<xacro:m26/>"]),
                    expected=("robot.urdf", "expansion stopped past 20,000 elements (the size limit of a xacro "
                              "expansion)"), id="xacro-macro-growth"),
    xacro_file_case(_grown(['<xacro:property name="s0" value="abcdefgh"/>',
                            *(f'<xacro:property name="s{k}" value="${{s{k - 1} + s{k - 1}}}"/>' for k in range(1, 40)),
                            '<link name="${s39}"/>']),
                    expected=("robot.urdf", "an expression's value passes 10,000,000 characters"),
                    id="xacro-doubling-string"),
    study('upper_arm_m = "0.5"', f'upper_arm_m = "{"5" * 5000}"', base=TWO_LINK,
          expected=("robot.xacro_args.upper_arm_m", "argument upper_arm_m (5000 characters) reads as inf, not a finite "
                    "number"), id="xacro-argument-5000-digits"),
]



def gantry_measurements(poses=("P1", "P2", "P3")) -> str:
    """A measurement file of the gantry: each pose approached from + and -, 4 cycles each, a few µm apart."""
    lines = ["pose,cycle,direction,x_m,y_m,z_m,q_x,q_y,q_z"]
    for p, name in enumerate(poses):
        q = (0.1 + 0.1 * p, 0.2, 0.3 - 0.1 * p)
        for direction, sign in (("+", 1), ("-", -1)):
            for cycle in range(1, 5):
                point = [v + sign * 1e-5 + 1e-6 * ((cycle + i + p) % 3) for i, v in enumerate(q)]
                lines.append(",".join([name, str(cycle), direction, *map(repr, point), *map(repr, q)]))
    return "\n".join(lines) + "\n"


def calibrate(old: str | None = None, new: str = "", *, expected, id, poses=("P1", "P2", "P3"), at_fault="data.csv"):
    """A `tribokin calibrate` case: ``GANTRY_CALIBRATE`` with ``old`` replaced by ``new``, measured at ``poses``."""
    text = GANTRY_CALIBRATE if old is None else _replace(GANTRY_CALIBRATE, old, new)
    return pytest.param({"study.toml": text, "data.csv": gantry_measurements(poses)},
                        ["calibrate", "{tmp}/study.toml", "--measurements", "{tmp}/data.csv", "--out", "{tmp}/out",
                         "--report", "none"], (f"{{tmp}}/{at_fault}", *expected), id=id)


MEASURED = "pose,cycle,direction,x_m,y_m,z_m\n" + "".join(f"P1,{c},+,0.5,0.2,{0.3 + c * 1e-6}\n" for c in range(1, 4))

# issue 35: calibrate writes only what run accepts (its names checked before the fit), and smaller refusals
CALIBRATE_OUTPUT_CASES = [
    calibrate("[calibration]", '[[poses]]\nname = "p1"\nq = [0.1, 0.1, 0.1]\n\n[calibration]',
              expected=("pose 'P1': writes field_P1.png, as the study's poses[0].name does (field_p1.png", "case"),
              id="calibrate-measured-pose-differs-in-case-from-the-study-s"),
    calibrate("[calibration]", f'[[poses]]\nname = "{"p" * 100}"\nq = [0.1, 0.1, 0.1]\n\n[calibration]',
              poses=("p" * 100, "P2", "P3"),
              expected=("the study holds", "so calibrated.toml would name this measured pose 'measured-ppp",
                        "has 109 characters; a name may have at most 100"),
              id="calibrate-renamed-measured-pose-too-long"),
    calibrate("[calibration]", '[[poses]]\nname = "P1"\nq = [0.1, 0.1, 0.1]\n\n[[poses]]\nname = "measured-P1"\n'
              'q = [0.2, 0.1, 0.1]\n\n[calibration]',
              expected=("pose 'P1'", "the study holds 'P1' and 'measured-P1' already"),
              id="calibrate-renamed-measured-pose-taken"),
    study("chunk_rows = 1", 'chunk_rows = 1\nstatistic = "one-test"\ndirectional = true', base=GANTRY_MAP,
          expected=("map.directional", "a one-test map has no directional figures"), id="map-directional-one-test"),
    measurement("measure", MEASURED.replace("P1,2,", "P1,1e19,"),
                expected=("cycle", "line 3 holds 1e+19", "from 1 to 1e+15"), id="measure-cycle-1e19"),
    measurement("measure", MEASURED.replace("P1,2,", "P1,1e300,").replace("P1,3,", "P1,2e300,"),
                expected=("cycle", "line 3 holds 1e+300", "from 1 to 1e+15"), id="measure-cycles-1e300-2e300"),
    measurement("measure", MEASURED.replace("P1,2,+", "P1,2,\x1b[31m+"),
                expected=("direction", "line 3 holds '\\x1b[31m+'", "not printable"), id="measure-direction-escape"),
    measurement("measure", MEASURED.replace("P1,2,+", "P1,2,+\x00"),
                expected=("direction", "line 3 holds '+\\x00'", "not printable"), id="measure-direction-nul"),
    calibrate(None, poses=("P1", "P\x1b2", "P3"), expected=("pose", "line 10 holds 'P\\x1b2'", "not printable"),
              id="calibrate-pose-escape"),
    study("chunk_rows = 1", "chunk_rows = 1\n\n[placement]\ncandidates = [[0.0, 0.0, 0.0]]\nyaw_deg = [0, 360, -360]",
          base=GANTRY_MAP, expected=("placement.yaw_deg[1]", "360 is the same yaw as placement.yaw_deg[0] (modulo "
                                     "360°)"), id="placement-yaws-equal-modulo-360"),
]

CASES = [
    # -- study files: syntax, sections and keys
    study("[study]", "[study", expected=("not valid TOML",), id="toml-unclosed-table"),
    study("seed = 3", 'seed = 3\nseed = 4', expected=("not valid TOML",), id="toml-duplicate-key"),
    pytest.param({"study.toml": b"\xff\xfe[study]\n"}, RUN, ("{tmp}/study.toml", "not valid TOML"), id="toml-not-utf8"),
    pytest.param({}, RUN, ("{tmp}/study.toml", "not found"), id="study-file-missing"),
    study("[study]", "[stduy]", expected=("stduy", "did you mean 'study'"), id="unknown-section"),
    study("seed = 3", "seed = 3\nsede = 4", expected=("study.sede", "did you mean 'seed'"), id="unknown-study-key"),
    study("stiffness = 2.0e6", "stifness = 2.0e6", expected=("joints.stifness", "did you mean 'stiffness'"),
          id="unknown-joint-key"),
    study("tool_frame =", "tool_fram =", expected=("robot.tool_fram", "did you mean 'tool_frame'"),
          id="unknown-robot-key"),
    study('name = "P1"', 'name = "P1"\nnormal_force = 3.0', expected=("poses[0].normal_force",
                                                                        "did you mean 'normal_force_N'"),
          id="unknown-pose-key"),
    study("[joints]", "[joints]\n[robots]", expected=("did you mean 'robot'",), id="unknown-section-robots"),
    study("[[poses]]\nname = \"P1\"\nq = [0.25]", "", expected=("poses", "nothing to test"), id="no-poses"),
    study("stiffness = 2.0e6", "", expected=("joints.stiffness", "no stiffness"), id="stiffness-missing"),
    # -- wrong types, NaN and infinities
    study("cycles = 12", 'cycles = "12"', expected=("study.cycles", "whole number"), id="cycles-string"),
    study("cycles = 12", "cycles = 12.5", expected=("study.cycles",), id="cycles-float"),
    study("seed = 3", "seed = -1", expected=("study.seed",), id="seed-negative"),
    study("stiffness = 2.0e6", 'stiffness = "stiff"', expected=("joints.stiffness", "number"), id="stiffness-string"),
    study("stiffness = 2.0e6", "stiffness = nan", expected=("joints.stiffness", "finite"), id="stiffness-nan"),
    study("normal_force_N = 150.0", "normal_force_N = inf", expected=("joints.normal_force_N", "finite"),
          id="normal-force-inf"),
    study("stiffness = 2.0e6", "stiffness = 2.0e6\noffset = -inf", expected=("joints.offset", "finite"),
          id="offset-minus-inf"),
    study("q = [0.25]", "q = [nan]", expected=("poses[0].q[0]", "finite"), id="pose-q-nan"),
    study("q = [0.25]", 'q = "0.25"', expected=("poses[0].q",), id="pose-q-string"),
    study("seed = 3", 'seed = 3\napproach = "bidirectionnal"',
          expected=("study.approach", "did you mean 'bidirectional'"), id="approach-misspelt"),
    # -- values out of range
    study("cycles = 12", "cycles = 0", expected=("study.cycles", "between 2 and"), id="cycles-zero"),
    study("stiffness = 2.0e6", "stiffness = 0.0", expected=("joints.stiffness", "> 0"), id="stiffness-zero"),
    study("stiffness = 2.0e6", "stiffness = -2.0e6", expected=("joints.stiffness", "> 0"), id="stiffness-negative"),
    study("stiffness = 2.0e6", "stiffness = 2.0e6\nbacklash = -1e-6", expected=("joints.backlash", ">= 0"),
          id="backlash-negative"),
    study("normal_force_N = 150.0", "normal_force_N = -150.0", expected=("joints.normal_force_N", ">= 0"),
          id="normal-force-negative"),
    study("[[poses]]", "[joints.x]\nstiffness = 0\n\n[[poses]]", expected=("joints.x.stiffness", "> 0"),
          id="joint-override-stiffness-zero"),
    # -- friction laws
    friction('{ law = "gaussian", mean = 0.1, std = -0.1 }',
             expected=("joints.friction.std", "between 0 and 10", "never negative"),
             id="gaussian-std-negative"),
    friction('{ law = "gaussian", mean = nan, std = 0.01 }', expected=("joints.friction.mean", "finite"),
             id="gaussian-mean-nan"),
    friction('{ law = "uniform", low = 0.2, high = 0.1 }', expected=("joints.friction.low", "swap"),
             id="uniform-inverted-bounds"),
    friction('{ law = "uniform", low = -0.1, high = 0.1 }', expected=("joints.friction.low", "never negative"),
             id="uniform-negative-support"),
    friction('{ law = "constant", mu = -0.1 }', expected=("joints.friction.mu", "never negative"),
             id="constant-negative"),
    friction('{ law = "lognormal", mean = 0.0, std = 0.01 }', expected=("joints.friction.mean", "> 0"),
             id="lognormal-mean-zero"),
    friction('{ law = "empirical", values = [0.1, -0.2] }', expected=("joints.friction.values", "never negative"),
             id="empirical-negative-value"),
    friction('{ law = "empirical", values = ["a", "b"] }', expected=("joints.friction.values", "number"),
             id="empirical-strings"),
    friction('{ law = "empirical", values = 0.1 }', expected=("joints.friction.values", "list"),
             id="empirical-not-a-list"),
    friction('{ law = "uniform", low = "0.1", high = 0.2 }', expected=("joints.friction.low", "must be a number"),
             id="uniform-low-string"),
    # -- friction time keys (issue 38)
    friction('{ preset = "42CD4-raw", ar1 = 1.0 }', expected=("joints.friction.ar1", "strictly between -1 and 1"),
             id="ar1-one"),
    friction('{ preset = "42CD4-raw", ar1 = -1.5 }', expected=("joints.friction.ar1", "between -1 and 1"),
             id="ar1-below-minus-one"),
    friction('{ law = "lognormal", mean = 0.12, std = 0.2, ar1 = -0.5 }',
             expected=("joints.friction.ar1", "below -0.2647, the most negative lag-one correlation"),
             id="ar1-lognormal-unreachable"),
    friction('{ law = "constant", mu = 0.1, ar1 = 0.5 }', expected=("joints.friction.ar1", "no spread to correlate"),
             id="ar1-constant-law"),
    friction('{ preset = "42CD4-raw", run_in = { start = 0.2, tau_cycles = -5 } }',
             expected=("joints.friction.run_in.tau_cycles", "must be > 0"), id="run-in-tau-negative"),
    friction('{ preset = "42CD4-raw", run_in = { tau_cycles = 5 } }',
             expected=("joints.friction.run_in.start", "required"), id="run-in-start-missing"),
    friction('{ preset = "42CD4-raw", age_cycles = 500 }', expected=("joints.friction.age_cycles", "give run_in"),
             id="age-without-run-in"),
    friction('{ preset = "42CD4-raw", steady_mean_std = -0.01 }',
             expected=("joints.friction.steady_mean_std", "never negative"), id="steady-mean-std-negative"),
    friction('{ preset = "42CD4-raw", thermal = { time_constant_s = 0, mu_per_K = -0.005 } }',
             expected=("joints.friction.thermal.time_constant_s", "must be > 0"), id="thermal-time-constant-zero"),
    friction('{ preset = "42CD4-raw", thermal = { mu_table = [[20, 1.0], [60, 0.8], [40, 0.9]] } }',
             expected=("joints.friction.thermal.mu_table[2]", "temperatures must increase"),
             id="thermal-table-out-of-order"),
    friction('{ preset = "42CD4-raw", thermal = { mu_per_K = -0.005 } }',
             expected=("study.cycle_time_s", "joints.friction.thermal heats the joint"),
             id="thermal-without-cycle-time"),
    study("seed = 3", 'seed = 3\ncycle_time_s = 4.0', expected=("joints.travel_per_cycle", "travel per cycle"),
          id="thermal-without-travel",
          base=_replace(STUDY, '{ preset = "42CD4-raw" }',
                        '{ preset = "42CD4-raw", thermal = { mu_per_K = -0.005 } }')),
    friction('{ preset = "42CD4-raw", thermal = { resistance_K_per_W = 1.0 } }',
             expected=("joints.friction.thermal.mu_per_K", "mu_per_K (relative change per kelvin) or mu_table"),
             id="thermal-without-mu-dependence"),
    study("q = [0.25]", 'q = [0.25]\nfriction = { preset = "42CD4-raw", ar1 = 0.5 }',
          expected=("poses[0].friction.ar1", "a pose's friction is a law only"), id="ar1-on-a-pose"),
    study("counts = [4]", 'counts = [4]\nstate = "warm"', base=AXIS_JOINT_MAP,
          expected=("map.state", "no joint's friction is a time series"), id="map-state-without-time-keys"),
    map_state('state = "hot"', SERIES_MAP, ("map.state", 'must be "cold", "warm" or a table'), "map-state-misspelt"),
    map_state("state = { age_cycles = 100 }", SERIES_MAP, ("map.state.age_cycles", "no joint's friction has run_in"),
              "map-state-age-without-run-in"),
    map_state('compare = "warm"', SERIES_MAP, ("map.compare.after_s", "no joint's friction has thermal"),
              "map-compare-warm-without-thermal"),
    map_state("state = { after_s = -60 }", WARMING_MAP, ("map.state.after_s", "must be >= 0 (got -60)"),
              "map-state-negative-time"),
    map_state("state = { after_s = 5e6 }", WARMING_MAP, ("map.state.after_s", "more than 1,000,000 cycles of 4 s"),
              "map-state-too-long"),
    map_state("compare = { after = 60 }", WARMING_MAP, ("map.compare.after", "unknown key"), "map-compare-unknown-key"),
    study("seed = 3", "seed = 3", base=STUDY + "\n[drift]\nduration_s = 3600\n",
          expected=("study.cycle_time_s", "[drift] approaches each pose once a cycle"), id="drift-without-cycle-time"),
    study("seed = 3", "seed = 3\ncycle_time_s = 10.0", base=STUDY + "\n[drift]\nduration_s = 200\n",
          expected=("drift.duration_s", "200 s hold 20 cycles of 10 s, fewer than the first and last sets' 24"),
          id="drift-too-short"),
    study("[map]", '[[scenarios]]\nname = "raw"\n\n[[scenarios]]\nname = "worn"\njoints = { friction = { preset = '
          '"42CD4-raw", ar1 = 0.5 } }\n\n[map]\nstate = { age_cycles = 100 }', base=AXIS_JOINT_MAP,
          expected=("map.state.age_cycles", "no joint's friction has run_in"), id="map-state-age-no-scenario-runs-in"),
    study("[map]", '[[scenarios]]\nname = "raw"\n\n[[scenarios]]\nname = "change"\n\n[map]\ncompare = "cold"',
          base=SERIES_MAP, expected=("scenarios[1].name", "writes map_RP_l_change.png, as map.compare does"),
          id="scenario-named-like-a-change-map"),
    study("[map]", '[[scenarios]]\nname = "raw"\n\n[[scenarios]]\nname = "b"\n\n[[scenarios]]\nname = "change_b"\n\n'
          '[map]\ncompare = "cold"', base=SERIES_MAP,
          expected=("scenarios[2].name", "writes map_RP_l_change_b.png, as scenarios[1].name does"),
          id="scenario-named-like-another-scenarios-change-map"),
    study(None, base=GANTRY_MAP + '\n[[scenarios]]\nname = "raw"\n\n[[scenarios]]\nname = "hi"\n',
          expected=("scenarios[1].name", "writes map_RP_l_hi.png, as map.statistic does"),
          id="scenario-named-like-the-band-map"),
    study(None, base=GANTRY_MAP + '\n[[scenarios]]\nname = "raw"\n\n[[scenarios]]\nname = "Multi"\n',
          expected=("scenarios[1].name", "writes map_RP_l_Multi.png, as map.statistic does (map_RP_l_multi.png"),
          id="scenario-named-like-the-multi-directional-map"),
    study('{ preset = "42CD4-raw" }', '{ preset = "42CD4-raw", ar1 = 0.5 }',
          base=_replace(GANTRY_MAP, "chunk_rows = 1", "chunk_rows = 1\ndirectional = false\n\n[placement]\n"
                        "candidates = [[0.0, 0.0, 0.0]]"),
          expected=("joints.friction.ar1", "a placement search does not simulate friction time keys yet"),
          id="time-keys-in-a-placement-search"),
    friction('{ law = "uniform", low = 0.1 }', expected=("joints.friction.high", "needs high"),
             id="uniform-high-missing"),
    friction('{ law = "gausian", mean = 0.1, std = 0.01 }', expected=("joints.friction.law", "did you mean 'gaussian'"),
             id="law-misspelt"),
    friction('{ law = "gaussian", mean = 0.1, sigma = 0.01 }', expected=("joints.friction.sigma", "unknown key"),
             id="law-unknown-key"),
    friction('{ preset = "42CD4-rw" }', expected=("joints.friction.preset", "42CD4-raw"), id="preset-misspelt"),
    friction("0.12", expected=("joints.friction", "table"), id="friction-not-a-table"),
    friction('{ file = "nope.toml" }', expected=("joints.friction.file", "not found"), id="law-file-missing"),
    study('{ preset = "42CD4-raw" }', '{ file = "law.toml" }', files={"law.toml": 'law = "uniform"\nlow = 0.3\n'
                                                                                   "high = 0.1\n"},
          at_fault="law.toml", expected=("low", "swap"), id="law-file-inverted-bounds"),
    study('{ preset = "42CD4-raw" }', '{ log = "log.csv" }', files={"log.csv": "cycle,mu\n1,0.1\n"},
          at_fault="log.csv", expected=("mu", "at least 20"), id="law-log-too-short"),
    # -- robots, frames, joints, URDFs, meshes
    study(f'urdf = "{AXIS_URDF}"', 'name = "ur55"', expected=("robot.name", "did you mean 'ur5'"),
          id="unknown-robot"),
    study('tool_frame = "tool"', 'tool_frame = "tol"', expected=("robot.tool_frame", "did you mean 'tool'"),
          id="unknown-frame"),
    study("[[poses]]", "[joints.y]\nstiffness = 1.0\n\n[[poses]]", expected=("joints.y", "unknown joint 'y'"),
          id="unknown-joint"),
    study(f'urdf = "{AXIS_URDF}"', f'urdf = "{AXIS_URDF}"\nname = "ur5"', expected=("robot", "exactly one"),
          id="urdf-and-name"),
    study(f'urdf = "{AXIS_URDF}"', 'urdf = "missing.urdf"', expected=("robot.urdf", "not found"), id="urdf-missing"),
    study(f'urdf = "{AXIS_URDF}"', 'urdf = "robot.urdf"', files={"robot.urdf": "<robot name='r'><link "},
          expected=("robot.urdf", "cannot read URDF"), id="urdf-malformed"),
    study(f'urdf = "{AXIS_URDF}"', 'urdf = "robot.urdf"', files={"robot.urdf": ""},
          expected=("robot.urdf", "cannot read URDF"), id="urdf-empty"),
    study(f'urdf = "{AXIS_URDF}"', 'urdf = "share/pkg/meshy.urdf"\npackage_dirs = ["share"]',
          "--report", "full", files={"share/pkg/meshy.urdf": MESHY_URDF, "evil.stl": STL},
          expected=("robot.package_dirs", "evil.stl", "{tmp}/share"), id="mesh-outside-package"),
    study(f'urdf = "{AXIS_URDF}"', 'urdf = "share/pkg/meshy.urdf"\npackage_dirs = ["share"]',
          files={"share/pkg/meshy.urdf": MESHY_URDF.replace("evil.stl", "evil"), "evil": STL},
          expected=("robot.package_dirs", "evil'", "{tmp}/share"), id="mesh-outside-no-extension-report-none"),
    study(None, base=MESHY_GANTRY_MAP, files={"share/pkg/gantry.urdf": MESHY_GANTRY_URDF.format(mesh="../evil.stl"),
                                              "evil.stl": STL},
          expected=("robot.package_dirs", "evil.stl", "{tmp}/share"), id="mesh-outside-map-study"),
    # -- xacro robot descriptions
    study('upper_arm_m = "0.5"', 'upper_arm = "0.5"', base=TWO_LINK,
          expected=("robot.xacro_args.upper_arm", "has no argument 'upper_arm' (did you mean 'upper_arm_m'?); its "
                    "arguments: forearm_m, upper_arm_m"), id="xacro-unknown-argument"),
    study('upper_arm_m = "0.5"', 'upper_arm_m = "half a metre"', base=TWO_LINK,
          expected=("robot.xacro_args.upper_arm_m", "with upper_arm_m = 'half a metre': unsupported operand type(s) "
                    "for /: 'str' and 'int' when evaluating expression 'length / 2'"),
          id="xacro-bad-argument-value"),
    study('upper_arm_m = "0.5"', "upper_arm_m = 0.5", base=TWO_LINK,
          expected=("robot.xacro_args.upper_arm_m", 'must be a string', 'write upper_arm_m = "0.5"'),
          id="xacro-argument-not-a-string"),
    study('tool_frame = "tool"', 'tool_frame = "tool"\nxacro_args = { reach = "1" }',
          expected=("robot.xacro_args", "only a xacro file", "prismatic_axis.urdf"), id="xacro-arguments-of-a-urdf"),
    xacro_case('<xacro:include filename="parts.xacro"/>',
               expected=("robot.urdf", "cannot expand xacro '{tmp}/share/pkg/one.urdf.xacro': No such file or "
                         "directory: {tmp}/share/pkg/parts.xacro"), id="xacro-missing-include"),
    xacro_case('<xacro:include filename="$(find parts)/parts.xacro"/>',
               expected=("robot.urdf", "$(find parts): no folder 'parts' in the package folders ({tmp}/share)"),
               id="xacro-unknown-package"),
    xacro_case('<xacro:include filename="../../parts.xacro"/>', files={"parts.xacro": "<robot/>"},
               expected=("robot.package_dirs", "xacro opens '{tmp}/share/pkg/../../parts.xacro', which resolves to "
                         "'{tmp}/parts.xacro', outside"), id="xacro-include-outside"),
    xacro_case('<link name="$(arg colour)"/>',
               expected=("robot.xacro_args.colour", "Undefined substitution argument colour"),
               id="xacro-undefined-argument"),
    *XACRO_ATTACKS,  # issue 35: a robot description runs no code, reads nothing outside, its expansion bounded
    # -- poses, the ISO cube and maps that cannot be reached
    study("q = [0.25]", "q = [0.25, 0.1]", expected=("poses[0].q", "needs 1 values"), id="pose-q-wrong-length"),
    study("q = [0.25]", "q = [0.75]", expected=("poses[0].q", "outside its limits"), id="pose-unreachable"),
    study("[[poses]]\nname = \"P1\"", "[[poses]]\nname = \"P1\"\nq = [0.1]\n[[poses]]\nname = \"P1\"",
          expected=("poses.name", "twice"), id="pose-name-twice"),
    study("[map]", "[iso_cube]\ncenter_m = [3.0, 0.3, 0.4]\nside_m = 0.1\n\n[map]", base=GANTRY_MAP,
          expected=("iso_cube", "unreachable"), id="iso-cube-unreachable"),
    study("[map]", "[iso_cube]\nside_m = 0.0\n\n[map]", base=GANTRY_MAP, expected=("iso_cube.side_m", "> 0"),
          id="iso-cube-side-zero"),
    study("resolution = [4, 3]", "resolution = [0, 3]", base=GANTRY_MAP, expected=("map.resolution[0]", ">= 1"),
          id="map-resolution-zero"),
    study("axis_u = [1, 0, 0]", "axis_u = [1, 1, 0]", base=GANTRY_MAP, expected=("map.axis_u", "unit vector"),
          id="map-axis-not-unit"),
    study('kind = "plane"', 'kind = "plain"', base=GANTRY_MAP, expected=("map.kind", "did you mean 'plane'"),
          id="map-kind-misspelt"),
    study("extent_u_m = [0.0, 0.6]", "extent_u_m = [0.6, 0.0]", base=GANTRY_MAP, expected=("map.extent_u_m",),
          id="map-extent-inverted"),
    study("[map]", '[[scenarios]]\nname = "a"\njoints = { stifness = 1.0 }\n\n[map]', base=GANTRY_MAP,
          expected=("scenarios[0].joints.stifness", "did you mean 'stiffness'"), id="scenario-unknown-key"),
    *PRE_CHECKS,  # issue 19: names and pre-checks
    *CONFINEMENT_CASES,  # issue 35: files confined, system files refused, content never quoted
    *CALIBRATE_OUTPUT_CASES,  # issue 35: calibrate's output, and smaller refusals
    # -- command-line options
    command([*RUN, "--cycles", "0"], expected=("command line", "--cycles", "between 2 and"), id="option-cycles-zero"),
    command([*RUN, "--cycles", "many"], expected=("command line", "--cycles", "invalid int"),
            id="option-cycles-not-int"),
    command([*RUN, "--seed", "-4"], expected=("command line", "--seed", ">= 0"), id="option-seed-negative"),
    command([*RUN, "--workers", "0"], expected=("command line", "--workers", ">= 1"), id="option-workers-zero"),
    command([*RUN, "--workers", "2", "--scheduler", "tcp://127.0.0.1:9"], expected=("command line", "--scheduler"),
            id="option-workers-and-scheduler"),
    command([*RUN, "--scheduler", "tcp://127.0.0.1:9"], files={"study.toml": GANTRY_MAP},
            expected=("command line", "--scheduler", "cannot reach", "127.0.0.1:9"), id="scheduler-closed-port"),
    command([*RUN, "--scheduler", "not a url"], files={"study.toml": GANTRY_MAP},
            expected=("command line", "--scheduler", "'not a url' is not a scheduler address", "tcp://host:port"),
            id="scheduler-not-an-address"),
    command(["run", "{tmp}/study.toml", "--out", "{tmp}/out", "--report", "fancy"],
            expected=("command line", "--report", "invalid choice"), id="option-report-unknown"),
    command(["run", "{tmp}/study.toml"], expected=("command line", "--out"), id="option-out-missing"),
    command(["rnu", "{tmp}/study.toml"], expected=("command line", "invalid choice"), id="unknown-command"),
    command(["run", "{tmp}/study.toml", "--out", "/proc/tribokin-out", "--report", "none"],
            expected=("/proc/tribokin-out", "--out", "cannot write"), id="out-parent-unwritable"),
    command(["run", "{tmp}/study.toml", "--out", "{tmp}/no/such/out", "--report", "none"],
            expected=("{tmp}/no/such/out", "--out", "does not exist"), id="out-parent-missing"),
    command(RUN, files={"out/mine.txt": "precious"}, expected=("{tmp}/out", "--out", "--force"),
            id="out-exists-without-force"),
    command([*RUN, "--force"], files={"out": "a file"}, expected=("{tmp}/out", "--out", "is a file"),
            id="out-is-a-file"),
    command(RUN, files={"out": Symlink("gone")}, expected=("{tmp}/out", "--out", "symbolic link", "gone"),
            id="out-dangling-symlink"),
    command(["run", "{tmp}/study.toml", "--out", ".", "--report", "none", "--force"],
            expected=("tribokin: error: .: --out: ", "current folder or one of its parents"), id="out-here-force"),
    command(["run", "{tmp}/study.toml", "--out", "..", "--report", "none", "--force"],
            expected=("tribokin: error: ..: --out: ", "current folder or one of its parents"), id="out-parent-force"),
    command(RUN, files={"out.chunks/manifest.json": '{"key": "x"}'}, expected=("{tmp}/out.chunks", "--resume"),
            id="leftover-chunks-without-resume"),
    command([*RUN, "--resume"], files={"out.chunks/manifest.json": '{"key": "x"}'},
            expected=("{tmp}/out.chunks", "--resume", "no [map]"), id="resume-without-map"),
    study(None, "", "--resume", base=GANTRY_MAP, files={"out.chunks/manifest.json": '{"key": "x"}'},
          at_fault="out.chunks", expected=("--resume", "other settings"), id="resume-other-settings"),
    study(None, "", "--resume", "--force", base=GANTRY_MAP, files={"out.chunks/done/0": "", "out/old.txt": "old"},
          at_fault="out.chunks", expected=("--resume", "lacks manifest.json", "--force without --resume"),
          id="resume-damaged-chunks"),
    # -- tribometer logs (tribokin fit-friction)
    measurement("fit-friction", None, expected=("file not found",), id="log-missing"),
    measurement("fit-friction", "cycle,friction\n1,0.1\n", expected=("mu", "columns"), id="log-wrong-columns"),
    measurement("fit-friction", "cycle,mu\n" + "\n".join(f"{i},0.1" for i in range(5)) + "\n",
                expected=("mu", "at least 20"), id="log-too-short"),
    measurement("fit-friction", GOOD_LOG.replace("\n8,", "\n8,x"), expected=("mu", "line 9, column 2"),
                id="log-not-a-number"),
    measurement("fit-friction", GOOD_LOG.replace("\n8,", "\n8,nan\n#"), expected=("mu", "line 9, column 2", "finite"),
                id="log-nan"),
    measurement("fit-friction", GOOD_LOG.replace("\n8,", "\n8,-"), expected=("mu", "line 9", "never negative"),
                id="log-negative-mu"),
    measurement("fit-friction", "friction_force_N,normal_force_N\n" + "5,50\n" * 30 + "5,0\n",
                expected=("normal_force_N", "line 32: expected a normal force > 0"), id="log-zero-normal-force"),
    measurement("fit-friction", b"\xff\xfe\x00c", expected=("not a text CSV",), id="log-binary"),
    measurement("fit-friction", GOOD_LOG, "--running-in", "35", expected=("running_in", "fewer than 20"),
                id="log-running-in-too-long"),
    measurement("fit-friction", GOOD_LOG, "--running-in", "-1", expected=("running_in", ">= 0"),
                id="log-running-in-negative"),
    # -- surface profiles (tribokin surface)
    measurement("surface", "x_m,height\n1,2\n", expected=("x_m, z_m",), id="profile-wrong-columns"),
    measurement("surface", GOOD_PROFILE.replace("\n2e-06,", "\n2e-06,abc,"), expected=("z_m", "line 4, column 2"),
                id="profile-not-a-number"),
    measurement("surface", GOOD_PROFILE.replace("x_m,z_m\n", "x_m,z_m\nfoo,1\n"), expected=("x_m", "line 2, column 1"),
                id="profile-x-not-a-number"),
    measurement("surface", "x_m,z_m\n0,1\n1,2\n", expected=("x_m", "at least 50"), id="profile-too-short"),
    measurement("surface", GOOD_PROFILE.replace("\n3e-06,", "\n1e-06,"),
                expected=("x_m", "increase strictly; line 5 does not"), id="profile-x-not-increasing"),
    measurement("surface", "x_m,z_m\n" + "\n".join(f"{i * 1e-6},0" for i in range(100)) + "\n",
                expected=("peaks",), id="profile-without-peaks"),
    measurement("surface", GOOD_PROFILE, "--area-m2=-1e-6", at_fault="command line", expected=("--area-m2", "> 0"),
                id="surface-area-negative"),
    measurement("surface", GOOD_PROFILE, "--area-m2", "nan", at_fault="command line", expected=("--area-m2", "finite"),
                id="surface-area-nan"),
    measurement("surface", GOOD_PROFILE, "--z-range-m", "1e-6", "0", at_fault="command line",
                expected=("--z-range-m", "low <= high"), id="surface-z-range-inverted"),
    measurement("surface", GOOD_PROFILE, "--radius-range-m", "0", "nan", at_fault="command line",
                expected=("--radius-range-m[1]", "not nan"), id="surface-radius-nan"),
    measurement("fit-friction", GOOD_LOG, files={"out/law.toml": "mine"}, at_fault="{tmp}/out",
                expected=("--out", "--force"), id="fit-out-exists-without-force"),
    measurement("surface", GOOD_PROFILE, files={"out": "a file"}, at_fault="{tmp}/out", expected=("--out", "exists"),
                id="surface-out-is-a-file"),
    # issue 19: numeric extremes (each key's range, its reason in the error; lost motion beyond a joint's range)
    study("cycles = 12", "cycles = 1", expected=("study.cycles", "ISO 9283 needs at least 2"), id="cycles-one"),
    study("cycles = 12", "cycles = 1000000000000001", expected=("study.cycles", "30 million years"),
          id="cycles-beyond-1e15"),
    command([*RUN, "--cycles", "1"], expected=("command line", "--cycles", "at least 2"), id="option-cycles-one"),
    command([*RUN, "--cycles", "9" * 400], expected=("command line", "--cycles", "digits", "between 2 and"),
            id="option-cycles-400-digits"),
    study("seed = 3", "seed = 18446744073709551616", expected=("study.seed", "64-bit"), id="seed-beyond-64-bits"),
    command([*RUN, "--seed", "9" * 400], expected=("command line", "--seed", "digits", "64-bit"),
            id="option-seed-400-digits"),
    study("seed = 3", "seed = " + "9" * 5000, expected=("not valid TOML", "digits"), id="toml-5000-digit-number"),
    study('tool_frame = "tool"', 'tool_frame = "tool"\npayload_kg = 1e308', expected=("robot.payload_kg", "2.3 t"),
          id="payload-1e308"),
    study('tool_frame = "tool"', 'tool_frame = "tool"\ntool_offset_m = [0.0, 0.0, 20.0]',
          expected=("robot.tool_offset_m[2]", "between -10 and 10 m", "a few metres"), id="tool-offset-beyond-10-m"),
    study('tool_frame = "tool"', 'tool_frame = "tool"\nbase_xyz_m = [1e308, 0.0, 0.0]',
          expected=("robot.base_xyz_m[0]", "kilometre"), id="base-at-1e308"),
    study('tool_frame = "tool"', 'tool_frame = "tool"\nbase_rpy_deg = [0.0, 90.0]',
          expected=("robot.base_rpy_deg", "3"), id="base-rpy-two-angles"),
    study("normal_force_N = 150.0", "normal_force_N = 1e308", expected=("joints.normal_force_N", "1000 t"),
          id="normal-force-1e308"),
    study('name = "P1"', 'name = "P1"\nnormal_force_N = 1.1e7', expected=("poses[0].normal_force_N", "1000 t"),
          id="pose-normal-force-beyond-1e7"),
    study("stiffness = 2.0e6", "stiffness = 1e-300", expected=("joints.stiffness", "between 0.001 and 1e+12",
                                                                "kilometre"), id="stiffness-1e-300"),
    study("stiffness = 2.0e6", "stiffness = 1e13", expected=("joints.stiffness", "set its friction to 0"),
          id="stiffness-beyond-1e12"),
    study("stiffness = 2.0e6", "stiffness = " + "9" * 400, expected=("joints.stiffness", "finite", "digits"),
          id="stiffness-400-digits"),
    study("stiffness = 2.0e6", "stiffness = 2.0e6\nfriction_radius_m = 1e308",
          expected=("joints.friction_radius_m", "slewing rings"), id="friction-radius-1e308"),
    study("stiffness = 2.0e6", "stiffness = 2.0e6\nfriction_radius_m = 1e-300",
          expected=("joints.friction_radius_m", "0.1 mm"), id="friction-radius-1e-300"),
    study("stiffness = 2.0e6", "stiffness = 2.0e6\nbacklash = 1e308", expected=("joints.backlash", "broken drive"),
          id="backlash-1e308"),
    study("stiffness = 2.0e6", "stiffness = 2.0e6\noffset = 1e308", expected=("joints.offset", "broken drive"),
          id="offset-1e308"),
    study("stiffness = 2.0e6", "stiffness = 2.0e6\noffset = -0.2", expected=("joints.offset", "between -0.1 and 0.1"),
          id="offset-below-minus-0.1"),
    study("stiffness = 2.0e6", "stiffness = 2.0e6\nnoise_std = 1e200", expected=("joints.noise_std", "broken drive"),
          id="noise-1e200"),
    study("bearing_span_m = 0.2", "bearing_span_m = 1e-300", base=GANTRY_MAP,
          expected=("joints.bearing_span_m", "1 mm"), id="bearing-span-1e-300"),
    study("bearing_span_m = 0.2", "bearing_span_m = 100.0", base=GANTRY_MAP,
          expected=("joints.bearing_span_m", "between 0.001 and 10 m"), id="bearing-span-beyond-10-m"),
    study("q = [0.25]", "q = [1e308]", expected=("poses[0].q[0]", "kilometre"), id="pose-q-1e308"),
    study("[map]", "[iso_cube]\ncenter_m = [1e308, 0.3, 0.4]\n\n[map]", base=GANTRY_MAP,
          expected=("iso_cube.center_m[0]", "kilometre"), id="iso-cube-center-1e308"),
    study("[map]", "[iso_cube]\nside_m = 1e308\n\n[map]", base=GANTRY_MAP, expected=("iso_cube.side_m", "100 m"),
          id="iso-cube-side-1e308"),
    study("[map]", "[iso_cube]\nside_m = 1e-300\n\n[map]", base=GANTRY_MAP, expected=("iso_cube.side_m", "1 mm"),
          id="iso-cube-side-1e-300"),
    study("[map]", "[iso_cube]\nrpy_deg = [0, 1e308, 0]\n\n[map]", base=GANTRY_MAP,
          expected=("iso_cube.rpy_deg[1]", "one turn"), id="iso-cube-rpy-1e308"),
    study("origin_m = [0.2, 0.0, 0.4]", "origin_m = [0.2, 0.0, 1e308]", base=GANTRY_MAP,
          expected=("map.origin_m[2]", "kilometre"), id="map-origin-1e308"),
    study("extent_u_m = [0.0, 0.6]", "extent_u_m = [-1e308, 1e308]", base=GANTRY_MAP,
          expected=("map.extent_u_m[0]", "kilometre"), id="map-extent-1e308"),
    study("chunk_rows = 1", "chunk_rows = 1\nrpy_deg = [-400, 0, 0]", base=GANTRY_MAP,
          expected=("map.rpy_deg[0]", "between -360 and 360"), id="map-rpy-beyond-a-turn"),
    study("chunk_rows = 1", "chunk_rows = 1\nstart_q = [0.1, 0.1, -1e308]", base=GANTRY_MAP,
          expected=("map.start_q[2]", "kilometre"), id="map-start-q-1e308"),
    study("resolution = [4, 3]", "resolution = [4, " + "9" * 400 + "]", base=GANTRY_MAP,
          expected=("map.resolution[1]", "digits", "0.1 µm"), id="map-resolution-400-digits"),
    study("chunk_rows = 1", "chunk_rows = 100000000", base=GANTRY_MAP, expected=("map.chunk_rows", "memory"),
          id="map-chunk-rows-beyond-1e7"),
    friction('{ law = "constant", mu = 11.0 }', expected=("joints.friction.mu", "between 0 and 10", "sliding friction"),
             id="constant-mu-beyond-10"),
    friction('{ law = "constant", mu = ' + "9" * 400 + " }", expected=("joints.friction.mu", "finite", "401 digits"),
             id="constant-mu-400-digits"),
    friction('{ law = "gaussian", mean = 0.1, std = 1e308 }', expected=("joints.friction.std", "between 0 and 10"),
             id="gaussian-std-1e308"),
    friction('{ law = "uniform", low = 0.1, high = 1e308 }', expected=("joints.friction.high", "between 0 and 10"),
             id="uniform-high-1e308"),
    friction('{ law = "lognormal", mean = 1e-300, std = 1.0 }', expected=("joints.friction.mean", "superlubric"),
             id="lognormal-mean-1e-300"),
    friction('{ law = "empirical", values = [0.1, 1e308] }',
             expected=("joints.friction.values", "between 0 and 10", "1e+308"), id="empirical-value-1e308"),
    study('{ preset = "42CD4-raw" }', '{ file = "law.toml" }', files={"law.toml": 'file = "law.toml"\n'},
          at_fault="law.toml", expected=("file", "not another law file"), id="law-file-includes-itself"),
    study('{ preset = "42CD4-raw" }', '{ log = "log.csv" }',
          files={"log.csv": GOOD_LOG.replace("\n8,", "\n8,1e308\n#")},
          at_fault="log.csv", expected=("mu", "line 9 gives", "above 10"), id="law-log-mu-1e308"),
    friction(SURFACE_LAW.replace("contact_area_m2 = 1e-6", "contact_area_m2 = 1e300"),
             expected=("joints.friction.contact_area_m2", "100 cm²"), id="surface-area-1e300"),
    friction(SURFACE_LAW.replace("contact_area_m2 = 1e-6", "contact_area_m2 = 1e-2, cycles = 1000000"),
             expected=("joints.friction.contact_area_m2", "summits", "fewer cycles"), id="surface-too-many-summits"),
    friction(SURFACE_LAW.replace("film_thickness_m = 1.2e-6", "film_thickness_m = 1e-300"),
             expected=("joints.friction.film_thickness_m", "nanometres"), id="surface-film-1e-300"),
    friction(SURFACE_LAW.replace("normal_force_N = 150.0", "normal_force_N = 1e-300"),
             expected=("joints.friction.normal_force_N", "millinewtons"), id="surface-normal-force-1e-300"),
    friction(SURFACE_LAW.replace(" }", ", modulus_Pa = 1e308 }"), expected=("joints.friction.modulus_Pa", "diamond"),
             id="surface-modulus-1e308"),
    friction(SURFACE_LAW.replace(" }", ", mu_film = 11.0 }"),
             expected=("joints.friction.mu_film", "between 1e-06 and 10"),
             id="surface-mu-film-beyond-10"),
    friction(SURFACE_LAW.replace(" }", ", cycles = 10000000 }"), expected=("joints.friction.cycles", "between 1 and"),
             id="surface-cycles-beyond-1e6"),
    study("stiffness = 2.0e6", "stiffness = 1.0", expected=("joints.stiffness", "joint 'x': lost motion up to 24 m",
                                                             "exceeds the joint's range 0.4 m", "raise stiffness"),
          id="lost-motion-beyond-the-axis"),
    study("stiffness = 2.0e6", "stiffness = 2.0e6\nnoise_std = 0.1",
          expected=("joints.noise_std", "6 noise_std 0.6 m) up to 0.6 m exceeds the joint's range 0.4 m",
                    "lower noise_std"),
          id="noise-beyond-the-axis"),
    study("[[poses]]", "[joints.x]\nstiffness = 1.0\n\n[[poses]]", expected=("joints.x.stiffness", "lost motion up to"),
          id="joint-override-lost-motion-beyond-the-axis"),
    study("stiffness = 2.0e7", "stiffness = 1.0", base=GANTRY_MAP, expected=("joints.stiffness", "joint 'x'",
                                                                             "range 0.6 m"),
          id="map-computed-loads-lost-motion-beyond-the-axis"),
    study("[map]", '[[scenarios]]\nname = "soft"\njoints = { stiffness = 1.0 }\n\n[map]', base=GANTRY_MAP,
          expected=("scenarios[0].joints.stiffness", "lost motion up to"), id="scenario-lost-motion-beyond-the-axis"),
    measurement("fit-friction", GOOD_LOG.replace("\n8,", "\n8,1e308\n#"), expected=("mu", "line 9 gives", "above 10"),
                id="log-mu-1e308"),
    measurement("fit-friction", "friction_force_N,normal_force_N\n" + "5e300,1e-10\n" * 30,
                expected=("friction_force_N", "line 2 gives", "mu = inf"), id="log-force-ratio-overflows"),
    measurement("fit-friction", "cycle,mu\n" + "\n".join(f"{i},{1e-320 * (1 + i % 3)}" for i in range(1, 41)) + "\n",
                expected=("mu", "steady-state mean"), id="log-mu-subnormal"),
    measurement("fit-friction", "cycle,mu\n" + "\n".join(f"{i},0.12" for i in range(1, 41)) + "\n",
                expected=("mu", "no spread to fit", 'law = "constant", mu = 0.12'), id="log-constant-mu"),
    measurement("fit-friction", GOOD_LOG, "--running-in", "9" * 400, expected=("running_in", "more than all"),
                id="log-running-in-400-digits"),
    measurement("surface", GOOD_PROFILE.replace("\n2e-06,", "\n2e-06,1e308\n#"), expected=("z_m", "line 4 holds",
                                                                                            "micrometres"),
                id="profile-z-1e308"),
    measurement("surface", "x_m,z_m\n" + "\n".join(f"{i * 1e-320},{1e-6 * np.sin(i / 3)}" for i in range(200)) + "\n",
                expected=("x_m", "line 3 lies", "atomic"), id="profile-spacing-1e-320"),
    measurement("surface", "x_m,z_m\n" + "\n".join(f"{i * 1e-6},{1e-310 * np.sin(i / 3)}" for i in range(200)) + "\n",
                expected=("z_m", "summit statistics"), id="profile-heights-subnormal"),
    measurement("surface", GOOD_PROFILE, "--area-m2", "1e300", at_fault="command line",
                expected=("--area-m2", "square metre"), id="surface-area-option-1e300"),
    measurement("surface", GOOD_PROFILE, "--area-m2", "1e-300", at_fault="command line",
                expected=("--area-m2", "between 1e-12 and 1"), id="surface-area-option-1e-300"),
    measurement("surface", GOOD_PROFILE, "--z-range-m", "0", "1e300", at_fault="command line",
                expected=("--z-range-m[1]", "inf for no bound"), id="surface-z-range-1e300"),
    measurement("surface", GOOD_PROFILE, "--radius-range-m", "0", "1e300", at_fault="command line",
                expected=("--radius-range-m[1]", "far below a metre"), id="surface-radius-range-1e300"),
]

#: The UR5 calibration study without its map, and its measurements' header and data lines (issue 35).
CALIBRATE_STUDY = (ROOT / "studies" / "ur5-calibrate.toml").read_text(encoding="utf-8").split("\n# The calibrated")[0]
_TRACKER = [line for line in (ROOT / "studies" / "data" / "ur5-tracker.csv").read_text(encoding="utf-8").splitlines()
            if not line.startswith("#")]
TRACKER_HEADER, TRACKER_ROWS = _TRACKER[0], _TRACKER[1:]
#: A cell past the CSV reader's limit of 131 072 characters.
LONG_CELL = "1" * 131_073
#: Arrays nested 10 000 deep: deeper than a TOML reader recurses.
DEEP_ARRAY = "x = " + "[" * 10_000 + "]" * 10_000 + "\n"


def tracker(rows, edit=None) -> str:
    """The UR5 tracker file with ``rows`` (its data lines), each through ``edit(cells)`` if given."""
    lines = [",".join(edit(row.split(","))) if edit else row for row in rows]
    return "\n".join([TRACKER_HEADER, *lines]) + "\n"


def calibration(measurements: str, *options, expected, id, at_fault="{tmp}/in.csv", study=CALIBRATE_STUDY):
    """A `tribokin calibrate` case of ``study`` with the measurement file ``in.csv``."""
    return pytest.param({"study.toml": study, "in.csv": measurements},
                        ["calibrate", "{tmp}/study.toml", "--measurements", "{tmp}/in.csv", "--out", "{tmp}/out",
                         "--report", "none", *options], (at_fault, *expected), id=id)


def _same_point(cells: list[str]) -> list[str]:
    """A row of P1 '+x' moved onto the first row's point (its cycle kept)."""
    first = TRACKER_ROWS[0].split(",")
    return cells[:3] + first[3:6] + cells[6:] if cells[:3:2] == ["P1", "+x"] else cells


# issue 35: refusals that were tracebacks, each one line before any work
ROBUSTNESS_CASES = [
    measurement("measure", tracker(TRACKER_ROWS[:3]).replace("P1,2,", f"P1,{LONG_CELL},", 1),
                expected=("line 3: not a CSV file", "field limit (131072)"), id="measure-cell-beyond-the-csv-limit"),
    measurement("fit-friction", GOOD_LOG.replace("\n8,", f"\n{LONG_CELL},"),
                expected=("line 9: not a CSV file", "field limit (131072)"), id="log-cell-beyond-the-csv-limit"),
    calibration(tracker(TRACKER_ROWS).replace("P2,1,", f"P2,{LONG_CELL},", 1),
                expected=("line 92: not a CSV file", "field limit (131072)"), id="calibrate-cell-beyond-the-csv-limit"),
    measurement("measure", tracker(TRACKER_ROWS[:6]), "--seed", "-1", at_fault="command line",
                expected=("--seed", ">= 0"), id="measure-seed-negative"),
    measurement("measure", tracker(TRACKER_ROWS[:6]), "--seed", "9" * 4000, at_fault="command line",
                expected=("--seed", "2**64 - 1"), id="measure-seed-4000-digits"),
    calibration(tracker(TRACKER_ROWS), "--seed", "-1", at_fault="command line", expected=("--seed", ">= 0"),
                id="calibrate-seed-negative"),
    calibration(tracker(TRACKER_ROWS), "--seed", str(2 ** 64), at_fault="command line",
                expected=("--seed", "2**64 - 1"), id="calibrate-seed-beyond-64-bits"),
    calibration(tracker([row for row in TRACKER_ROWS if row.startswith("P1,")]),
                expected=("pose", "measures 1 pose", "two or more"), id="calibrate-one-pose"),
    calibration(tracker(TRACKER_ROWS, _same_point), expected=("x_m", "pose P1 '+x'", "all at the same point"),
                id="calibrate-series-without-spread"),
    study("[[poses]]", DEEP_ARRAY + "[[poses]]", expected=("line", "nested 10000 deep"), id="toml-nested-10000-deep"),
    calibration(tracker(TRACKER_ROWS), study=DEEP_ARRAY + CALIBRATE_STUDY, at_fault="{tmp}/study.toml",
                expected=("line 1", "nested 10000 deep"), id="calibrate-toml-nested-10000-deep"),
    study('{ preset = "42CD4-raw" }', '{ file = "law.toml" }', files={"law.toml": DEEP_ARRAY},
          at_fault="law.toml", expected=("line 1", "nested 10000 deep"), id="law-file-nested-10000-deep"),
]

#: A transform file of the measuring frame (``--transform``), ``{rotation}`` its rotation's line.
FRAME = "{rotation}\ntranslation_m = [0.1, 0.2, 0.3]\n"
IDENTITY = "rotation = [[1, 0, 0], [0, 1, 0], [0, 0, 1]]"


def framed(text: str, *options, expected, id, at_fault="{tmp}/frame.toml"):
    """A `tribokin measure` case of six rows of the UR5 tracker file with ``--transform frame.toml`` holding ``text``
    (then ``options``)."""
    return measurement("measure", tracker(TRACKER_ROWS[:6]), "--transform", "{tmp}/frame.toml", *options,
                       files={"frame.toml": text}, at_fault=at_fault, expected=expected, id=id)


# issue 37: the measuring frame is a choice (--registration, --transform), checked before any work
REGISTRATION_CASES = [
    measurement("measure", tracker(TRACKER_ROWS[:6]), "--registration", "bestfit", at_fault="command line",
                expected=("--registration", "invalid choice: 'bestfit'", "'auto', 'none', 'best-fit'"),
                id="measure-registration-unknown"),
    measurement("measure", MEASURED, "--registration", "best-fit", at_fault="{tmp}/in.csv: cx_m",
                expected=("--registration best-fit needs commanded positions (cx, cy, cz)", "no commanded"),
                id="measure-best-fit-without-commanded-positions"),
    pytest.param({"study.toml": GANTRY_CALIBRATE, "data.csv": gantry_measurements()},
                 ["calibrate", "{tmp}/study.toml", "--measurements", "{tmp}/data.csv", "--out", "{tmp}/out",
                  "--report", "none", "--registration", "best-fit"],
                 ("{tmp}/data.csv: cx_m", "--registration best-fit needs commanded positions"),
                 id="calibrate-best-fit-without-commanded-positions"),
    measurement("measure", tracker(TRACKER_ROWS[:6]), "--transform", "{tmp}/nowhere.toml", at_fault="command line",
                expected=("--transform", "nowhere.toml", "file not found"), id="measure-transform-missing"),
    measurement("measure", tracker(TRACKER_ROWS[:6]), "--transform", "/proc/self/environ", at_fault="command line",
                expected=("--transform", "system file"), id="measure-transform-proc-environ"),
    framed(FRAME.format(rotation=IDENTITY), "--registration", "none", at_fault="command line: --transform",
           expected=("leave out one of them",), id="measure-transform-and-registration"),
    framed(FRAME.format(rotation="rotation = [[1, 0, 0], [0, 1, 0], [0, 0, 1.01]]"),
           expected=("rotation: not a rotation", "orthonormal to 1e-06"), id="measure-transform-not-a-rotation"),
    framed(FRAME.format(rotation="rotation = [[1, 0, 0], [0, 1, 0], [0, 0, -1]]"),
           expected=("rotation: not a rotation", "determinant +1 (it is -1)"), id="measure-transform-reflection"),
    framed(FRAME.format(rotation="rotation = [[1, 0, 0], [0, 1, 0]]"), expected=("rotation", "3 rows of 3"),
           id="measure-transform-two-rows"),
    framed(FRAME.format(rotation=IDENTITY + "\nrpy_deg = [0, 0, 90]"), expected=("rotation", "either"),
           id="measure-transform-rotation-and-rpy"),
    framed(FRAME.format(rotation=IDENTITY).replace("translation_m", "translation"),
           expected=("translation: unknown key", "did you mean 'translation_m'"), id="measure-transform-unknown-key"),
    framed(FRAME.format(rotation=IDENTITY).replace("0.3]", "nan]"),
           expected=("translation_m", "3 finite numbers"), id="measure-transform-translation-nan"),
    framed(FRAME.format(rotation=IDENTITY)[:-3], expected=("not valid TOML",), id="measure-transform-not-toml"),
    pytest.param({"study.toml": CALIBRATE_STUDY, "in.csv": tracker(TRACKER_ROWS),
                  "frame.toml": FRAME.format(rotation="rpy_deg = [0, 90]")},
                 ["calibrate", "{tmp}/study.toml", "--measurements", "{tmp}/in.csv", "--out", "{tmp}/out",
                  "--transform", "{tmp}/frame.toml"], ("{tmp}/frame.toml: rpy_deg", "needs 3 values, roll, pitch, yaw"),
                 id="calibrate-transform-rpy-two-values"),
]


def _create(tmp: Path, files: dict) -> None:
    for name, content in files.items():
        path = tmp / name
        path.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(content, Symlink):
            path.symlink_to(content)
        elif isinstance(content, Fifo):
            os.mkfifo(path)
        else:  # "{tmp}" in a text stands for the case's folder
            path.write_bytes(content if isinstance(content, bytes) else content.replace("{tmp}", str(tmp)).encode())


def _tree(folder: Path) -> dict[str, bytes | str | None]:
    """Every file (its bytes), symbolic link (its target) and folder (``None``) below ``folder``."""
    return {str(p.relative_to(folder)): (os.readlink(p) if p.is_symlink() else p.read_bytes() if p.is_file() else None)
            for p in sorted(folder.rglob("*"))}


def test_bad_input_table_is_large_and_unambiguous():
    ids = [case.id for case in CASES + ROBUSTNESS_CASES + REGISTRATION_CASES]
    assert len(ids) >= 40 and len(set(ids)) == len(ids)


def _assert_refused(tmp: Path, before: dict, status: int, out: str, err: str, expected) -> None:
    lines = err.splitlines()
    assert status == 2, (out, err)
    assert len(lines) == 1 and lines[0].startswith("tribokin: error: "), err
    assert "Traceback" not in err and out == ""
    assert SECRET not in err and XACRO_SECRET.strip() not in err  # no error quotes what a file holds
    for text in expected:
        assert text.format(tmp=tmp) in lines[0], (text, lines[0])
    assert _tree(tmp) == before  # no output, temporary, chunk or lock file; nothing changed
    assert not Path("/proc/tribokin-out").exists()


def _run_refused(tmp: Path, capsys, monkeypatch, files, argv, expected) -> None:
    monkeypatch.chdir(tmp)  # also where the default output folders of fit-friction and surface would go
    _create(tmp, files)
    before = _tree(tmp)
    status = main([arg.format(tmp=tmp) for arg in argv])
    captured = capsys.readouterr()
    _assert_refused(tmp, before, status, captured.out, captured.err, expected)


@pytest.mark.parametrize("files, argv, expected", CASES + ROBUSTNESS_CASES + REGISTRATION_CASES)
def test_bad_input_is_one_line_exit_2_nothing_written(tmp_path, capsys, monkeypatch, files, argv, expected):
    _run_refused(tmp_path, capsys, monkeypatch, files, argv, expected)


@pytest.mark.parametrize("files, argv, expected", PRE_CHECKS)
def test_refused_before_any_pose_or_target_is_measured(tmp_path, capsys, monkeypatch, files, argv, expected):
    def measured(*args):
        raise AssertionError("a pose or map target was measured before the refusal")

    monkeypatch.setattr(PoseRunner, "draw", measured)
    _run_refused(tmp_path, capsys, monkeypatch, files, argv, expected)


@pytest.mark.parametrize("files, argv, expected", [case for case in CASES if case.id in (
    "toml-unclosed-table", "option-workers-zero", "log-not-a-number", "mesh-outside-package",
    "xacro-missing-include", "xacro-bad-argument-value")])
def test_bad_input_through_python_m_tribokin(tmp_path, files, argv, expected):
    _create(tmp_path, files)
    before = _tree(tmp_path)
    done = subprocess.run([sys.executable, "-m", "tribokin", *(arg.format(tmp=tmp_path) for arg in argv)],
                          capture_output=True, text=True, cwd=tmp_path)
    _assert_refused(tmp_path, before, done.returncode, done.stdout, done.stderr, expected)


def _watch_opens(path: Path) -> int:
    """A non-blocking Linux inotify descriptor that records every opening of ``path``."""
    libc = ctypes.CDLL(None, use_errno=True)
    descriptor = libc.inotify_init1(os.O_NONBLOCK)
    assert descriptor >= 0 and libc.inotify_add_watch(descriptor, bytes(path), 0x20) >= 0  # IN_OPEN
    return descriptor


def _opened(descriptor: int) -> bool:
    try:
        return len(os.read(descriptor, 4096)) > 0
    except BlockingIOError:
        return False


def test_outside_mesh_is_refused_before_anything_opens_it(tmp_path):
    """A map study through the command line, with no report: the outside mesh is never opened (the
    watch sees every open, Pinocchio's included), and nothing is left behind."""
    _create(tmp_path, {"study.toml": MESHY_GANTRY_MAP, "evil.stl": STL,
                       "share/pkg/gantry.urdf": MESHY_GANTRY_URDF.format(mesh=tmp_path / "evil.stl")})
    before = _tree(tmp_path)
    opens = _watch_opens(tmp_path / "evil.stl")
    try:
        assert not _opened(opens)
        done = subprocess.run([sys.executable, "-m", "tribokin", *(arg.format(tmp=tmp_path) for arg in RUN)],
                              capture_output=True, text=True, cwd=tmp_path)
        assert not _opened(opens)
        (tmp_path / "evil.stl").read_bytes()
        assert _opened(opens)  # the watch works
    finally:
        os.close(opens)
    _assert_refused(tmp_path, before, done.returncode, done.stdout, done.stderr,
                    ("{tmp}/study.toml: robot.package_dirs: mesh '{tmp}/evil.stl'", "{tmp}/share"))


def test_output_parent_that_cannot_hold_folders(tmp_path, capsys):
    """Refused for root too (unlike a read-only folder): the parent of --out is a file."""
    (tmp_path / "study.toml").write_text(STUDY)
    (tmp_path / "notes.txt").write_text("mine")
    status = main(["run", str(tmp_path / "study.toml"), "--out", str(tmp_path / "notes.txt" / "out"),
                   "--report", "none"])
    error = capsys.readouterr().err
    assert status == 2 and "--out" in error and len(error.strip().splitlines()) == 1
    assert (tmp_path / "notes.txt").read_text() == "mine" and sorted(p.name for p in tmp_path.iterdir()) == [
        "notes.txt", "study.toml"]


@pytest.mark.parametrize("files, argv, expected", [case for case in CONFINEMENT_CASES if case.id in (
    "confine-surface-proc-environ", "confine-fit-friction-proc-environ")])
def test_the_process_environment_is_never_printed(tmp_path, files, argv, expected):
    """The campaign's case: a study or a command naming /proc/self/environ printed the whole environment, here
    holding SECRET; a process of its own, as /proc/self/environ shows the environment a process started with."""
    _create(tmp_path, files)
    before = _tree(tmp_path)
    done = subprocess.run([sys.executable, "-m", "tribokin", *(arg.format(tmp=tmp_path) for arg in argv)],
                          capture_output=True, text=True, cwd=tmp_path, env={**os.environ, "TRIBOKIN_TEST": SECRET})
    assert SECRET not in done.stdout
    _assert_refused(tmp_path, before, done.returncode, done.stdout, done.stderr, expected)
