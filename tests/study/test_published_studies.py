"""The shipped joint models from public sources (``studies/*-published.toml``) say where every number comes from:
each value under ``[joints]`` carries on its line a source key defined, with its address, in the file's header,
or the word "estimated"; and every joint of the arm has its own cited stiffness and friction torque, so no
value falls back to an uncited default. (That the studies run is tests/test_run_axis.py's every-shipped-study test.)"""

import re
import sys

import pytest

from conftest import STUDIES
from tribokin.kinematics.robot import load_example_robot

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

PUBLISHED = sorted(STUDIES.glob("*-published.toml"))
SOURCE = re.compile(r"^# (\[[A-Z0-9-]+\])\s")
SECTION = re.compile(r"^\[([^\]]+)\]")


def sources(lines: list[str]) -> set[str]:
    """Source keys the header defines, each with an address (https://...) in its own block of lines."""
    keys, key = set(), None
    for line in lines:
        if not line.startswith("#"):
            break
        if match := SOURCE.match(line):
            key = match.group(1)
        elif line.strip() == "#":
            key = None
        if key and "https://" in line:
            keys.add(key)
    return keys


def uncited_joint_values(text: str) -> list[str]:
    lines = text.splitlines()
    keys, section, uncited = sources(lines), None, []
    for line in lines:
        if match := SECTION.match(line):
            section = match.group(1)
        elif section and (section == "joints" or section.startswith("joints.")) and "=" in line.split("#")[0]:
            value, _, comment = line.partition("#")
            if re.search(r"\d", value) and "estimated" not in comment and not any(key in comment for key in keys):
                uncited.append(f"[{section}] {line.strip()}")
    return uncited


def test_there_is_a_published_joint_model_for_each_shipped_arm():
    assert [path.stem for path in PUBLISHED] == ["panda-published", "ur10-published", "ur5-published"]


@pytest.mark.parametrize("path", [*PUBLISHED, STUDIES / "ur5-warm-up.toml"], ids=lambda p: p.stem)
def test_every_joint_value_is_cited_or_said_to_be_estimated(path):
    assert uncited_joint_values(path.read_text(encoding="utf-8")) == []


@pytest.mark.parametrize("path", PUBLISHED, ids=lambda p: p.stem)
def test_every_joint_has_its_own_stiffness_and_friction_torque(path):
    study = tomllib.loads(path.read_text(encoding="utf-8"))
    joints = study["joints"]
    robot = load_example_robot(study["robot"]["name"])
    assert "bearing_span_m" in joints
    assert sorted(name for name, value in joints.items() if isinstance(value, dict)) == sorted(robot.joint_names)
    for name in robot.joint_names:
        assert {"stiffness", "friction_torque_Nm"} <= joints[name].keys(), name


def test_the_check_finds_an_uncited_value():
    text = ("# [SRC] A catalogue, https://example.org\n#\n[joints]\nstiffness = 1.0e4   # [SRC] Table 1\n"
            "[joints.a]\nbacklash = 1e-5   # a guess\nnoise_std = 0.0  # estimated: none\n[iso_cube]\nside_m = 0.3\n")
    assert uncited_joint_values(text) == ["[joints.a] backlash = 1e-5   # a guess"]
    assert uncited_joint_values(text.replace("https://example.org", "no address")) == [
        "[joints] stiffness = 1.0e4   # [SRC] Table 1", "[joints.a] backlash = 1e-5   # a guess"]
