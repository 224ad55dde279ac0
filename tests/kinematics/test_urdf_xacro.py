"""Robot descriptions in xacro: the shipped two-link arm expanded with its arguments (the tool where the closed form
puts it), vendor descriptions (UR5e, Kinova Gen3) expanded under the expression allow-list, $(find) in the package
folders, files confined like meshes, expressions that would run code refused before they run, expansions stopped at
their limits, errors keyed by the argument at fault, and xacro's globals left as they were (bad input through the
command line: tests/integration/test_bad_input.py)."""

import glob
import json
import math
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import xacro
from xacro import substitution_args

from conftest import GEN3_URDF, ROOT, STUDIES
from tribokin.cli import main
from tribokin.errors import RobotDescriptionError
from tribokin.kinematics.robot import load_urdf
from tribokin.kinematics.urdf_xacro import expand_xacro
from tribokin.kinematics.xacro_guard import XacroLimits

TWO_LINK = ROOT / "urdf" / "two_link_description" / "urdf" / "two_link.urdf.xacro"
PACKAGES = [ROOT / "urdf"]
#: Vendor descriptions trimmed to the files their xacros open (provenance and licence beside each).
VENDOR = ROOT / "tests" / "data"

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


def recorded_opens(monkeypatch) -> list[str]:
    """Every file opened through ``builtins.open`` from now on (xacro's own opening and a payload's alike)."""
    opened = []
    real_open = open
    monkeypatch.setattr("builtins.open", lambda file, *args, **kwargs: (opened.append(str(file)),
                                                                         real_open(file, *args, **kwargs))[1])
    return opened


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
    opened = recorded_opens(monkeypatch)
    with pytest.raises(RobotDescriptionError) as error:
        expand_xacro(path, {}, dirs)
    assert error.value.argument == "package_dirs"
    assert error.value.message.endswith(f"outside the xacro's folder and the package folders ({path.parent}, "
                                        f"{tmp_path / 'share'}); move it under one of them or list its folder in "
                                        "robot.package_dirs")
    assert f"'{(tmp_path / 'outside' / 'evil').resolve()}" in error.value.message.replace(".xacro", "").replace(
        ".yaml", "")
    assert not [file for file in opened if str(tmp_path / "outside") in str(Path(file).resolve())]


@pytest.mark.parametrize("pattern, listed", [("../parts/*.xacro", True), ("../../../outside/*.xacro", False),
                                             ("../*/../../../outside/evil.xacro", False)],
                         ids=["inside", "outside", "climbing"])
def test_an_include_pattern_lists_only_the_folders(tmp_path, monkeypatch, pattern, listed):
    """A wildcard include expands inside the folders; one whose folder lies outside, or that climbs out after a
    wildcard, is refused before any folder is listed."""
    path, dirs = one_joint(tmp_path, f'<xacro:include filename="{pattern}"/>')
    (path.parent.parent / "parts").mkdir()
    (path.parent.parent / "parts" / "a.xacro").write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><link name="from_a"/></robot>')
    (tmp_path / "outside" / "evil.xacro").write_text(EMPTY)
    patterns, real_glob = [], glob.glob
    monkeypatch.setattr("glob.glob", lambda pattern, **kwargs: patterns.append(pattern) or real_glob(pattern))
    if listed:
        assert '<link name="from_a"/>' in expand_xacro(path, {}, dirs) and len(patterns) == 1
        return
    with pytest.raises(RobotDescriptionError) as error:
        expand_xacro(path, {}, dirs)
    assert error.value.argument == "package_dirs" and "lists folders outside the xacro's folder" in error.value.message
    assert patterns == []


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
    """Its find, open, eval hooks, element and text walk, file stack, argument table and list of includes are put
    back, after a refusal too; its warnings (an unknown attribute here) never reach the terminal."""
    path, dirs = one_joint(tmp_path, '<xacro:include filename="../parts.xacro" colour="red"/>')
    (path.parent.parent / "parts.xacro").write_text(EMPTY)

    def state():
        return (substitution_args._eval_find, substitution_args._eval_dict["find"], substitution_args._eval,
                substitution_args._eval_env, substitution_args._eval_optenv, xacro.safe_eval, xacro.eval_all,
                xacro.eval_text, xacro.replace_node, xacro.filestack, dict(xacro.substitution_args_context),
                list(xacro.all_includes))

    before = state()
    expand_xacro(path, {"reach_m": "0.3"}, dirs)
    with pytest.raises(RobotDescriptionError):
        expand_xacro(path, {"reach_m": "0.3"}, [tmp_path / "outside"])  # parts.xacro is then outside
    with pytest.raises(RobotDescriptionError):
        expand_xacro(laughs(tmp_path), {}, [tmp_path], XacroLimits(elements=100))
    assert state() == before
    assert not hasattr(xacro, "open")
    assert capfd.readouterr() == ("", "")


def ur5e_dh_tool(q) -> np.ndarray:
    """UR5e's flange position [m] from Universal Robots' published DH parameters, in the ROS description's base_link
    (the DH base turned half a turn about z)."""
    d, a = (0.1625, 0, 0, 0.1333, 0.0997, 0.0996), (0, -0.425, -0.3922, 0, 0, 0)
    alpha = (math.pi / 2, 0, 0, math.pi / 2, -math.pi / 2, 0)
    placement = np.eye(4)
    for qi, di, ai, alphai in zip(q, d, a, alpha, strict=True):
        c, s, ca, sa = math.cos(qi), math.sin(qi), math.cos(alphai), math.sin(alphai)
        placement = placement @ np.array([[c, -s * ca, s * sa, ai * c], [s, c * ca, -c * sa, ai * s],
                                          [0, sa, ca, di], [0, 0, 0, 1]])
    return np.diag([-1.0, -1.0, 1.0]) @ placement[:3, 3]


def test_vendor_descriptions_expand_under_the_allow_list():
    """UR's ur.urdf.xacro (xacro.load_yaml of four YAML files, subscripts into them, dict(...), comparisons) puts the
    UR5e's flange where its DH parameters do; Kinova's gen3.xacro (7 dof: boolean operators, not, 2*pi) is the same
    arm as Kinova's own gen3.urdf, placement for placement."""
    ur = load_urdf(VENDOR / "ur_description" / "urdf" / "ur.urdf.xacro", "tool0", [VENDOR], meshes=False,
                   xacro_args={"ur_type": "ur5e", "name": "ur"})
    gen3 = load_urdf(VENDOR / "kortex_description" / "robots" / "gen3.xacro", None, [VENDOR], meshes=False,
                     xacro_args={"dof": "7"})
    reference = load_urdf(GEN3_URDF, None, [GEN3_URDF.parent], meshes=False)
    assert ur.joint_names == ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint",
                              "wrist_2_joint", "wrist_3_joint"]
    assert gen3.joint_names == reference.joint_names == [f"joint_{i}" for i in range(1, 8)]
    rng = np.random.default_rng(35)
    for q in (np.zeros(6), *rng.uniform(-3, 3, (3, 6))):
        assert ur.tool_placement(q).translation == pytest.approx(ur5e_dh_tool(q), abs=1e-8)
    for q in (np.zeros(7), *rng.uniform(-2, 2, (3, 7))):
        assert np.allclose(gen3.tool_placement(q).homogeneous, reference.tool_placement(q).homogeneous, atol=1e-12)


def test_allowed_expressions_give_what_xacro_gives(tmp_path):
    """What real descriptions compute: math functions and constants (bare and math.*), min/max, int/float/str,
    dict(...) and subscripts, YAML keys dotted and subscripted, conditionals, boolean operators, properties and
    macro parameters, $(eval) with arguments; $(optenv) gives its default whatever the environment holds."""
    path, dirs = one_joint(tmp_path, """
      <xacro:property name="config" value="${xacro.load_yaml('k.yaml')}"/>
      <xacro:property name="half" value="${reach / 2}"/>
      <xacro:property name="reach" value="$(arg reach_m)"/>
      <xacro:macro name="m" params="size:=2 *block"><part n="${size * half}"><xacro:insert_block name="block"/></part>
      </xacro:macro>
      <values a="${radians(180) / pi + math.cos(0) + max(1, 2) - min(3, 4)}" b="${int('7') + float(2)}"
              c="${dict(x=1.5)['x'] * config.arm['length']}" d="${'yes' if config.arm.length > 1 and not 0 else 'no'}"
              e="${str(round(2.345, 2)) + 'm'}" f="$(eval reach_m * 2)" g="$(optenv HOME fallback)"/>
      <xacro:m size="3"><inside/></xacro:m>""")
    (path.parent / "k.yaml").write_text("arm:\n  length: 2.5\n")
    text = expand_xacro(path, {"reach_m": "0.5"}, dirs)
    assert '<values a="1.0" b="9.0" c="3.75" d="yes" e="2.35m" f="1.0" g="fallback"/>' in text
    assert '<part n="0.75"><inside/></part>' in text


#: Expressions of the attack campaign by kind: each would write ``{marker}`` or read ``{secret}`` (outside the
#: package folders) on xacro's own evaluation.
ATTACKS = {
    "comprehension": ("<origin xyz=\"${[c for c in [xacro.load_yaml] if c.__globals__['os'].system('touch {marker}') "
                      "or True] and 0.5}\"/>", "a list comprehension is not allowed in ${...}"),
    "lambda": ("<link name=\"${(lambda f: f.__globals__['__builtins__']['open']('{secret}').read())(xacro.load_yaml)}"
               "\"/>", "lambda is not allowed in ${...}"),
    "generator": ("<link name=\"${list(c.__globals__['os'].system('touch {marker}') for c in [xacro.load_yaml])}\"/>",
                  "a generator expression is not allowed in ${...}"),
    "attribute": ("<link name=\"${xacro.load_yaml.__globals__['__builtins__']['open']('{secret}').read()}\"/>",
                  "an attribute whose name starts with '_' is not allowed in ${...}"),
    "eval": ("<xacro:property name=\"p\" value=\"open('{secret}').read()\"/><link name=\"$(eval ${p})\"/>",
             "name 'open' is not defined"),
    "format": ("<xacro:property name=\"f\" value=\"{0.load_yaml.__globals__}\"/><link name=\"${f.format(xacro)}\"/>",
               "an attribute of a str is not allowed"),
    "python": ("<link name=\"${python.type(1)}\"/>", "xacro's global 'python' is not allowed in ${...}"),
    "load-yaml-outside": ("<link name=\"${xacro.load_yaml('{secret}')}\"/>", "outside the xacro's folder"),
}


@pytest.mark.parametrize("kind", ATTACKS)
def test_an_expression_that_would_run_code_or_read_a_file_is_refused_before_it_runs(tmp_path, monkeypatch, kind):
    """Refused in one line naming the xacro and the construct (none of the file's text), before it runs: no file
    written, nothing outside opened (the lambda reaches the real ``open`` through builtins, recorded here)."""
    marker, secret = tmp_path / "outside" / "pwned", tmp_path / "outside" / "secret.yaml"
    payload, what = ATTACKS[kind]
    path, dirs = one_joint(tmp_path, payload.replace("{marker}", str(marker)).replace("{secret}", str(secret)))
    secret.write_text("token: tribokin-secret\n")
    opened = recorded_opens(monkeypatch)
    with pytest.raises(RobotDescriptionError) as error:
        expand_xacro(path, {}, dirs)
    assert what in error.value.message and (str(path) in error.value.message or kind == "load-yaml-outside")
    assert "\n" not in error.value.message and "tribokin-secret" not in error.value.message
    assert not marker.exists() and str(secret) not in opened


def laughs(folder: Path, depth: int = 26) -> Path:
    """The campaign's macro growth: ``depth`` macros each calling the previous twice (2^depth links, 2 KB)."""
    lines = ['<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">',
             '<xacro:macro name="m0"><link name="l"/></xacro:macro>',
             *(f'<xacro:macro name="m{k}"><xacro:m{k - 1}/><xacro:m{k - 1}/></xacro:macro>'
               for k in range(1, depth + 1)),
             f'<xacro:m{depth}/></robot>']
    (folder / "laughs.urdf.xacro").write_text("\n".join(lines))
    return folder / "laughs.urdf.xacro"


def doubling(folder: Path, properties: int = 40, uses: int = 1) -> Path:
    """The campaign's doubling string: each property twice the previous (8 * 2^39 characters at the end), the last
    one the name of ``uses`` links."""
    lines = ['<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">',
             '<xacro:property name="s0" value="abcdefgh"/>',
             *(f'<xacro:property name="s{k}" value="${{s{k - 1} + s{k - 1}}}"/>' for k in range(1, properties)),
             *[f'<link name="${{s{properties - 1}}}"/>'] * uses, '</robot>']
    (folder / "doubling.urdf.xacro").write_text("\n".join(lines))
    return folder / "doubling.urdf.xacro"


def written(name: str, text: str) -> Callable[[Path], Path]:
    """A maker of the xacro ``name`` holding ``text``."""
    def make(folder: Path) -> Path:
        (folder / name).write_text(text)
        return folder / name

    return make


@pytest.mark.parametrize("make, limits, message", [
    (laughs, XacroLimits(elements=2_000),
     "expansion stopped past 2,000 elements (the size limit of a xacro expansion)"),
    (laughs, XacroLimits(seconds=0.3, elements=10**9), "expansion stopped after 0.3 s (the time limit"),
    (doubling, XacroLimits(characters=1_000_000), "an expression's value passes 200,000 characters"),
    (lambda folder: doubling(folder, 15, uses=10), XacroLimits(characters=1_000_000),
     "expansion stopped past 1,000,000 characters"),
    (written("dollars.urdf.xacro", f'<robot name="r"><link name="b">{"$a" * 50_000}</link></robot>'), XacroLimits(),
     "a text of 100,000 characters with 50,000 '$' (xacro would take a time growing as their product to read it)"),
    (written("big.urdf.xacro", f'<robot name="r"><!-- {"x" * 300_000} --></robot>'), XacroLimits(characters=1_000_000),
     "a file of more than 200,000 bytes (the size limit of one file"),
], ids=["macro-growth", "time", "doubling-string", "characters", "lexer", "file"])
def test_an_expansion_past_its_limits_stops_in_one_line(tmp_path, make, limits, message):
    """The campaign's macro growth and doubling string, with small limits (the defaults: the bad-input table):
    stopped within a step of the limit (characters: 8 * 2^14 ten times, each under a value's limit, together past
    the expansion's); a text whose '$' signs xacro's lexer would take long over (its time grows as their number
    times the text's length: 100 000 '$a' took 5.6 s there, 200 000 18 s), a file larger than a value may be."""
    path = make(tmp_path)
    start = time.monotonic()
    with pytest.raises(RobotDescriptionError) as error:
        expand_xacro(path, {}, [tmp_path], limits)
    assert error.value.argument == "path" and error.value.message.startswith(f"xacro '{path}': {message}")
    assert time.monotonic() - start < limits.seconds + 5


@pytest.mark.parametrize("value", ["5" * 5000, "-1e400"])
def test_a_number_no_double_holds_is_blamed_on_its_argument(value):
    """xacro reads it as a float, infinite, and the URDF parser then fails on robot.urdf; a value spelling inf is
    the user's word and reaches that parser (it names robot.urdf)."""
    with pytest.raises(RobotDescriptionError) as error:
        expand_xacro(TWO_LINK, {"upper_arm_m": value}, PACKAGES)
    assert error.value.argument == "xacro_args.upper_arm_m"
    assert error.value.message == (f"xacro '{TWO_LINK}': argument upper_arm_m ({len(value)} characters) reads as "
                                   f"{float(value)}, not a finite number; give a value within +-1.8e308")
    assert "length=\"inf\"" in expand_xacro(TWO_LINK, {"upper_arm_m": "inf"}, PACKAGES)


#: Blocks (single and multiple), conditionals, a namespace include and comments before macro calls: what xacro's
#: node replacement (done here in one pass) has to keep in order.
BLOCKS = """<robot name="b" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="parts.xacro" ns="parts"/>
  <xacro:macro name="wrap" params="n *first **rest">
    <!-- the wrapper -->
    <group n="${n}"><xacro:insert_block name="first"/><xacro:insert_block name="rest"/><tail/></group>
  </xacro:macro>
  <!-- before a call -->
  <xacro:wrap n="${parts.q * 2}"><a/><rest><b/>text<c/></rest></xacro:wrap>
  <xacro:if value="${parts.q > 1}"><kept/><also/></xacro:if>
  <xacro:unless value="true"><dropped/></xacro:unless>
  <xacro:wrap n="2"><d/><rest/></xacro:wrap>
</robot>
"""


@pytest.mark.parametrize("description", ["ur5e", "gen3", "two-link", "blocks"])
def test_an_expansion_gives_the_bytes_xacro_gives(tmp_path, monkeypatch, description):
    """The hooks change nothing of an expansion they allow: the same text as xacro's own (its find pointed at the
    package folders), for the vendor descriptions, the shipped arm and xacro's block and conditional constructs."""
    (tmp_path / "blocks.urdf.xacro").write_text(BLOCKS)
    (tmp_path / "parts.xacro").write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro"><xacro:property name="q" value="3"/></robot>')
    path, arguments, folders = {
        "ur5e": (VENDOR / "ur_description/urdf/ur.urdf.xacro", {"ur_type": "ur5e", "name": "ur"}, [VENDOR]),
        "gen3": (VENDOR / "kortex_description/robots/gen3.xacro", {"dof": "7"}, [VENDOR]),
        "two-link": (TWO_LINK, {"upper_arm_m": "0.6"}, PACKAGES),
        "blocks": (tmp_path / "blocks.urdf.xacro", {}, [tmp_path])}[description]
    text = expand_xacro(path, arguments, folders)
    find = lambda package: str(next(folder / package for folder in folders if (folder / package).is_dir()))  # noqa: E731
    monkeypatch.setattr(substitution_args, "_eval_find", find)
    monkeypatch.setitem(substitution_args._eval_dict, "find", find)
    assert text == xacro.process_file(str(path.resolve()), mappings=dict(arguments)).toxml()
