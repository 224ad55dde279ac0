"""Robot descriptions in xacro: the shipped two-link arm expanded with its arguments (the tool where the closed form
puts it), $(find) in the package folders, files confined like meshes, errors keyed by the argument at fault, and
xacro's globals left as they were (bad input through the command line: tests/integration/test_bad_input.py)."""

import json
import math
from pathlib import Path

import numpy as np
import pytest
import xacro
from xacro import substitution_args

from conftest import ROOT, STUDIES
from tribokin.cli import main
from tribokin.errors import RobotDescriptionError
from tribokin.kinematics.robot import load_urdf
from tribokin.kinematics.urdf_xacro import expand_xacro

TWO_LINK = ROOT / "urdf" / "two_link_description" / "urdf" / "two_link.urdf.xacro"
PACKAGES = [ROOT / "urdf"]

#: A one-joint arm whose reach is the argument ``reach_m``; ``{extra}`` is replaced by a test's own lines.
ONE_JOINT = """<?xml version="1.0"?>
<robot name="one" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="reach_m" default="0.4"/>
  {extra}
  <link name="base"/>
  <joint name="j" type="revolute"><parent link="base"/><child link="tool"/><origin xyz="$(arg reach_m) 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <link name="tool"/>
</robot>
"""
EMPTY = '<robot xmlns:xacro="http://www.ros.org/wiki/xacro"/>\n'


def two_link_tool(upper_arm_m: float, forearm_m: float, q) -> np.ndarray:
    """The two-link arm's tool position [m], closed form."""
    return np.array([upper_arm_m * math.cos(q[0]) + forearm_m * math.cos(q[0] + q[1]),
                     upper_arm_m * math.sin(q[0]) + forearm_m * math.sin(q[0] + q[1]), 0.0])


def one_joint(tmp_path, extra: str = "") -> tuple:
    """``tmp_path/share/pkg/urdf/one.urdf.xacro`` with ``extra``; the package folder is ``tmp_path/share``."""
    folder = tmp_path / "share" / "pkg" / "urdf"
    folder.mkdir(parents=True)
    (tmp_path / "outside").mkdir()
    path = folder / "one.urdf.xacro"
    path.write_text(ONE_JOINT.format(extra=extra))
    return path, [tmp_path / "share"]


@pytest.mark.parametrize("arguments, lengths", [({}, (0.4, 0.3)), ({"upper_arm_m": "0.5"}, (0.5, 0.3)),
                                                ({"upper_arm_m": "0.8", "forearm_m": "0.25"}, (0.8, 0.25))])
def test_the_two_link_arm_puts_its_tool_where_its_link_lengths_say(arguments, lengths):
    robot = load_urdf(TWO_LINK, "tool", PACKAGES, xacro_args=arguments)
    assert robot.joint_names == ["shoulder", "elbow"]
    for q in ([0.0, 0.0], [0.3, 0.8], [-1.2, 2.2]):
        assert robot.tool_placement(q).translation == pytest.approx(two_link_tool(*lengths, q), abs=1e-12)
    assert [g.meshPath for g in robot.visual_model.geometryObjects][0] == str(
        (ROOT / "urdf/two_link_description/meshes/base_plate.stl").resolve())  # package:// of the expanded URDF


def test_a_pose_study_of_the_xacro_runs_and_records_its_arguments(tmp_path, capsys):
    """The shipped study through the command line, then with a longer upper arm: the commanded tool position moves
    as the closed form says; summary.json and the report record the arguments."""
    study = (STUDIES / "two-link-xacro.toml").read_text()
    positions = {}
    for upper_arm_m in (0.5, 0.65):
        path = tmp_path / f"arm-{upper_arm_m}.toml"
        path.write_text(study.replace('upper_arm_m = "0.5"', f'upper_arm_m = "{upper_arm_m}"')
                        .replace('"../urdf', f'"{ROOT}/urdf'))
        out = tmp_path / f"out-{upper_arm_m}"
        assert main(["run", str(path), "--out", str(out), "--cycles", "5"]) == 0, capsys.readouterr().err
        summary = json.loads((out / "summary.json").read_text())
        assert summary["study"]["robot_spec"]["xacro_args"] == {"upper_arm_m": str(upper_arm_m), "forearm_m": "0.35"}
        pose = summary["poses"][0]
        assert pose["q"] == [0.3, 0.8]
        positions[upper_arm_m] = np.array(pose["commanded_position_m"])
        assert positions[upper_arm_m] == pytest.approx(two_link_tool(upper_arm_m, 0.35, pose["q"]), abs=1e-12)
        page = (out / "report.html").read_text()
        assert f"xacro arguments</th><td>upper_arm_m = {upper_arm_m}, forearm_m = 0.35</td>" in page
        assert "Robot drawn from its visual geometry (--report full): 1 mesh and 2 cylinders." in page
    moved = positions[0.65] - positions[0.5]
    assert moved == pytest.approx(0.15 * np.array([math.cos(0.3), math.sin(0.3), 0.0]), abs=1e-12)


def test_find_resolves_in_the_package_folders_in_order(tmp_path):
    path, dirs = one_joint(tmp_path, '<xacro:include filename="$(find parts)/urdf/part.xacro"/>')
    for folder in ("a", "b"):
        (tmp_path / folder / "parts" / "urdf").mkdir(parents=True)
        (tmp_path / folder / "parts" / "urdf" / "part.xacro").write_text(
            f'<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="from_{folder}"/></robot>')
    text = expand_xacro(path, {}, [*dirs, tmp_path / "a", tmp_path / "b"])
    assert '<link name="from_a"/>' in text and "from_b" not in text
    with pytest.raises(RobotDescriptionError) as error:
        expand_xacro(path, {}, dirs)
    assert error.value.argument == "path" and error.value.message == (
        f"$(find parts): no folder 'parts' in the package folders ({tmp_path / 'share'}); list the folder that holds "
        "it in robot.package_dirs")


@pytest.mark.parametrize("extra", [
    '<xacro:include filename="../../../outside/evil.xacro"/>',
    '<xacro:include filename="../../../outside/evil.xacro" optional="true"/>',  # xacro skips an unreadable one
    '<xacro:include filename="link.xacro"/>',  # a symlink to outside/evil.xacro
    '<link name="${xacro.load_yaml(\'../../../outside/evil.yaml\').a}"/>',
], ids=["include", "optional-include", "symlink", "yaml"])
def test_a_file_outside_the_folders_is_refused_before_it_is_read(tmp_path, monkeypatch, extra):
    path, dirs = one_joint(tmp_path, extra)
    for name in ("evil.xacro", "evil.yaml"):
        (tmp_path / "outside" / name).write_text(EMPTY if name.endswith("xacro") else "a: 1\n")
    (path.parent / "link.xacro").symlink_to(tmp_path / "outside" / "evil.xacro")
    opened = []
    real_open = open
    monkeypatch.setattr("builtins.open", lambda file, *args, **kwargs: (opened.append(str(file)),
                                                                         real_open(file, *args, **kwargs))[1])
    with pytest.raises(RobotDescriptionError) as error:
        expand_xacro(path, {}, dirs)
    assert error.value.argument == "package_dirs"
    assert error.value.message.endswith(f"outside the xacro's folder and the package folders ({path.parent}, "
                                        f"{tmp_path / 'share'}); move it under one of them or list its folder in "
                                        "robot.package_dirs")
    assert f"'{(tmp_path / 'outside' / 'evil').resolve()}" in error.value.message.replace(".xacro", "").replace(
        ".yaml", "")
    assert not [file for file in opened if str(tmp_path / "outside") in str(Path(file).resolve())]


def test_an_included_file_inside_the_folders_is_read(tmp_path):
    path, dirs = one_joint(tmp_path, '<xacro:include filename="../parts.xacro"/>')
    (path.parent.parent / "parts.xacro").write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="part"/></robot>')
    assert '<link name="part"/>' in expand_xacro(path, {}, dirs)


@pytest.mark.parametrize("extra, arguments, key, message", [
    ('<link name="$(arg colour)"/>', {}, "xacro_args.colour",
     "xacro '{path}': Undefined substitution argument colour: set robot.xacro_args.colour = \"...\""),
    ("", {"reach": "0.5"}, "xacro_args.reach",
     "xacro '{path}' has no argument 'reach' (did you mean 'reach_m'?); its arguments: reach_m"),
    ('<link name="${$(arg reach_m) / 2}"/>', {"reach_m": "far"}, "xacro_args.reach_m",
     "xacro '{path}' with reach_m = 'far': name 'far' is not defined when evaluating expression '$(arg reach_m) / 2'"),
    ('<xacro:arg name="side" default="left"/><link name="${$(arg reach_m) / 2}"/>',
     {"side": "right", "reach_m": "0.5)"}, "xacro_args.reach_m",
     "xacro '{path}' with reach_m = '0.5)': unmatched ')' (<expression>, line 1) when evaluating expression "
     "'$(arg reach_m) / 2'"),
    ('<xacro:include filename="missing.xacro"/>', {"reach_m": "0.5"}, "path",
     "cannot expand xacro '{path}': No such file or directory: {folder}/missing.xacro"),
    ('<xacro:include filename="nested.xacro"/>', {}, "path",
     "cannot expand xacro '{path}' (in {folder}/nested.xacro): No such file or directory: {folder}/missing.xacro"),
    ('<link name="open"', {}, "path", "cannot expand xacro '{path}': not well-formed (invalid token): line 5, "
     "column 2"),
], ids=["undefined-argument", "unknown-argument", "bad-value", "bad-value-among-two", "missing-include",
        "missing-nested-include", "malformed"])
def test_errors_name_the_argument_at_fault_or_the_file(tmp_path, extra, arguments, key, message):
    path, dirs = one_joint(tmp_path, extra)
    (path.parent / "nested.xacro").write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:include filename="missing.xacro"/></robot>')
    with pytest.raises(RobotDescriptionError) as error:
        expand_xacro(path, arguments, dirs)
    assert (error.value.argument, error.value.message) == (key, message.format(path=path, folder=path.parent))


def test_xacro_is_left_as_it_was_and_says_nothing(tmp_path, capfd):
    """Its find, open, file stack, argument table and list of includes are put back, after a refusal too; its
    warnings (an unknown attribute here) never reach the terminal."""
    path, dirs = one_joint(tmp_path, '<xacro:include filename="../parts.xacro" colour="red"/>')
    (path.parent.parent / "parts.xacro").write_text(EMPTY)
    before = (substitution_args._eval_find, substitution_args._eval_dict["find"], xacro.filestack,
              dict(xacro.substitution_args_context), list(xacro.all_includes))
    expand_xacro(path, {"reach_m": "0.3"}, dirs)
    with pytest.raises(RobotDescriptionError):
        expand_xacro(path, {"reach_m": "0.3"}, [tmp_path / "outside"])  # parts.xacro is then outside
    assert (substitution_args._eval_find, substitution_args._eval_dict["find"], xacro.filestack,
            dict(xacro.substitution_args_context), list(xacro.all_includes)) == before
    assert not hasattr(xacro, "open")
    assert capfd.readouterr() == ("", "")
