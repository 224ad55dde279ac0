"""calibrated.toml: the study's own text with fitted values, measured poses and paths that still name its files."""

from __future__ import annotations

import sys
from pathlib import Path

from tribokin.study.calibrated_study import REWRITTEN, WrittenFrictionKey, WrittenValue, calibrated_study_text

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

STUDY = """# my study: keep this comment
[robot]
urdf = "robots/arm.urdf"   # relative to the study
package_dirs = ["robots", "/opt/meshes"]

[joints]
stiffness = 1e5
friction = { file = "laws/law.toml" }

[joints.j2]
backlash = 1e-5   # a guess

[[poses]]
name = "home"
q = [0.0, 0.0]
friction = { log = "logs/run.csv" }
"""


def test_values_poses_and_comments(tmp_path):
    values = [WrittenValue("j1", "stiffness", 61234.5, "fitted: 95 % interval [5.1e4, 7.2e4] N·m/rad"),
              WrittenValue("j2", "backlash", 2.5e-05, "fitted")]
    text = calibrated_study_text(STUDY, tmp_path, tmp_path, ["made by a test", ""], values,
                                 [("P1", [0.1, -0.2], ["+x", "-0.6+0.8+0.0"])])
    assert text.startswith("# made by a test\n#\n") and "# my study: keep this comment" in text
    parsed = tomllib.loads(text)
    assert parsed["joints"]["j1"]["stiffness"] == 61234.5 and parsed["joints"]["j2"]["backlash"] == 2.5e-05
    assert parsed["joints"]["stiffness"] == 1e5  # the defaults stay
    assert [p["name"] for p in parsed["poses"]] == ["home", "P1"] and parsed["poses"][1]["q"] == [0.1, -0.2]
    assert parsed["poses"][1]["directions"] == ["+x", "-0.6+0.8+0.0"]
    assert "fitted: 95 % interval [5.1e4, 7.2e4] N·m/rad" in text


def test_relative_paths_name_the_same_files_from_the_output_folder(tmp_path):
    source, out = tmp_path / "studies", tmp_path / "results" / "fit"
    text = calibrated_study_text(STUDY, source, out, [], [], [])
    parsed = tomllib.loads(text)
    resolved = lambda path: (out / path).resolve()  # noqa: E731
    assert resolved(parsed["robot"]["urdf"]) == (source / "robots" / "arm.urdf").resolve()
    assert resolved(parsed["robot"]["package_dirs"][0]) == (source / "robots").resolve()
    assert parsed["robot"]["package_dirs"][1] == "/opt/meshes"  # absolute: as written
    assert resolved(parsed["joints"]["friction"]["file"]) == (source / "laws" / "law.toml").resolve()
    assert resolved(parsed["poses"][0]["friction"]["log"]) == (source / "logs" / "run.csv").resolve()
    assert Path(parsed["robot"]["urdf"]).as_posix() == "../../studies/robots/arm.urdf"
    assert [resolved(folder) for folder in parsed["study"]["data_dirs"]] == [source.resolve()]  # its files readable


def test_data_dirs_are_moved_and_a_study_naming_no_files_gets_none(tmp_path):
    source, out = tmp_path / "studies", tmp_path / "results" / "fit"
    listed = STUDY.replace("# my study: keep this comment", '[study]\ndata_dirs = ["shared", "/srv/logs"]') + \
        '\n[[scenarios]]\nname = "other"\nstudy = { data_dirs = ["other"] }\n'
    parsed = tomllib.loads(calibrated_study_text(listed, source, out, [], [], []))
    assert parsed["study"]["data_dirs"] == ["../../studies", "../../studies/shared", "/srv/logs"]
    assert parsed["scenarios"][0]["study"]["data_dirs"] == ["../../studies", "../../studies/other"]
    plain = STUDY.replace('friction = { file = "laws/law.toml" }', 'friction = { preset = "42CD4-raw" }').replace(
        'friction = { log = "logs/run.csv" }', "")
    assert "data_dirs" not in calibrated_study_text(plain, source, out, [], [], [])


def test_a_friction_key_goes_into_its_table_with_its_comment(tmp_path):
    """calibrate --fit-ar1's ar1: into an inline friction table (the comment on its line) and a friction table of its
    own (the comment on the key); a root dotted key's inline table too, in place."""
    study = STUDY + '\n[joints.j3.friction_torque_Nm]\nlaw = "gaussian"\nmean = 1.0\nstd = 0.1\n'
    frictions = (WrittenFrictionKey(None, "friction", "ar1", 0.25, "ar1 fitted: [0.1, 0.4]"),
                 WrittenFrictionKey("j3", "friction_torque_Nm", "ar1", -0.125, "ar1 fitted: [-0.3, 0.05]"))
    text = calibrated_study_text(study, tmp_path, tmp_path, [], [], [], frictions)
    parsed = tomllib.loads(text)
    assert parsed["joints"]["friction"] == {"file": "laws/law.toml", "ar1": 0.25}
    assert parsed["joints"]["j3"]["friction_torque_Nm"] == {"law": "gaussian", "mean": 1.0, "std": 0.1, "ar1": -0.125}
    assert next(line for line in text.splitlines() if line.startswith("friction =")).endswith(
        "# ar1 fitted: [0.1, 0.4]")
    assert "ar1 = -0.125 # ar1 fitted: [-0.3, 0.05]" in text and REWRITTEN not in text
    dotted = 'joints.stiffness = 1e5\njoints.friction = { law = "gaussian", mean = 0.1, std = 0.01 }\n'
    text = calibrated_study_text(dotted, tmp_path, tmp_path, [], [], [], frictions[:1])
    assert tomllib.loads(text)["joints"]["friction"] == {"law": "gaussian", "mean": 0.1, "std": 0.01, "ar1": 0.25}
    assert text.endswith("ar1 = 0.25} # ar1 fitted: [0.1, 0.4]\n") and REWRITTEN not in text
