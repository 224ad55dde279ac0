"""The default tool frame: the end of the longest chain of joints, not the model's last frame (a sensor's in many
descriptions): Gen3's tool frame or end effector, not its camera; every tested robot's frame as before; tiago's arm;
floating-base legged robots refused with what would do; the candidates `tribokin robots --frames` lists."""

import xml.etree.ElementTree as ET

import pinocchio as pin
import pytest

from conftest import GEN3_URDF
from tribokin import InputError, run_study
from tribokin.errors import RobotDescriptionError
from tribokin.kinematics.robot import (
    TESTED_ROBOTS,
    _example_robot,
    candidate_tool_frames,
    load_example_robot,
    load_urdf,
)
from tribokin.kinematics.tool_frames import is_sensor, tool_rank

#: Each tested robot's tool frame before the default changed (the model's last frame), but kinova's: its last frame
#: is the tip of a fixed finger, its end effector is j2s6s200_end_effector.
TOOL_FRAMES = {"ur3": "tool0", "ur5": "tool0", "ur10": "tool0", "panda": "panda_hand_tcp", "xarm7": "link_eef",
               "z1": "gripperMover", "so100": "jaw", "kinova": "j2s6s200_end_effector"}


def test_gen3_measures_its_tool_frame_or_end_effector_not_a_camera(tmp_path):
    assert load_urdf(GEN3_URDF).tool_frame == "tool_frame"
    root = ET.parse(GEN3_URDF).getroot()  # the arm alone (gen3_macro.xacro): no tool_frame on its end effector
    for element in [*root.iter("link"), *root.iter("joint")]:
        if element.get("name") in ("tool_frame", "tool_frame_joint"):
            root.remove(element)
    arm = tmp_path / "gen3_arm.urdf"
    arm.write_text(ET.tostring(root, encoding="unicode"))
    assert pin.buildModelFromUrdf(str(arm)).frames[-1].name == "camera_depth_frame"  # the former default
    robot = load_urdf(arm)
    assert robot.tool_frame == "end_effector_link" and robot.joint_names == [f"joint_{i}" for i in range(1, 8)]


@pytest.mark.parametrize("name", TESTED_ROBOTS)
def test_tested_robots_keep_their_tool_frames(name):
    assert load_example_robot(name).tool_frame == TOOL_FRAMES[name]
    last = _example_robot(name)[0].frames[-1].name
    assert (last == TOOL_FRAMES[name]) == (name != "kinova")


def test_tiagos_arm_gets_an_arm_frame_and_anymal_kinova_its_arm():
    tiago = load_example_robot("tiago")
    assert is_sensor(_example_robot("tiago")[0].frames[-1].name)  # the former default: rgbd_laser_link
    assert tiago.tool_frame == "hand_grasping_frame"
    assert tiago.joint_names == ["torso_lift_joint"] + [f"arm_{i}_joint" for i in range(1, 8)]
    dual = load_example_robot("tiago_dual")  # two arms on the torso: the first in model order
    assert dual.tool_frame == "hand_left_grasping_frame" and dual.joint_names[-1] == "arm_left_7_joint"
    legged = load_example_robot("anymal_kinova")  # its arm is longer than its legs
    assert legged.tool_frame == "j2s6s200_end_effector" and legged.joint_names[0] == "j2s6s200_joint_1"


@pytest.mark.parametrize("name, limbs", [("anymal", "'LF_HAA', 'LH_HAA', 'RF_HAA', 'RH_HAA'"),
                                         ("solo12", "'FL_HAA', 'FR_HAA', 'HL_HAA', 'HR_HAA'"),
                                         ("talos", "'arm_left_1_joint', 'arm_right_1_joint'")])
def test_floating_base_legged_robots_are_refused_with_what_would_do(name, limbs):
    with pytest.raises(RobotDescriptionError) as error:
        load_example_robot(name)
    assert error.value.argument == "tool_frame"
    message = str(error.value)
    assert message.startswith(f"{name} has a floating base (joint 'root_joint') and its longest chains of joints are "
                              f"separate limbs (from joints {limbs})")
    assert "a URDF without the floating joint, or robot.tool_frame set to a frame on an arm" in message
    study = {"robot": {"name": name}, "joints": {"friction": {"preset": "42CD4-raw"}, "stiffness": 1e5},
             "poses": [{"q": [0.0]}]}
    with pytest.raises(InputError, match=f"^<mapping>: robot.tool_frame: {name} has a floating base") as refused:
        run_study(study)
    assert "\n" not in str(refused.value)
    foot = load_example_robot("anymal", "LF_FOOT")  # named, the base held in place
    assert foot.joint_names == ["LF_HAA", "LF_HFE", "LF_KFE"]


def test_candidates_list_the_default_first_then_every_chains_end_and_sensors_last():
    ur5 = candidate_tool_frames("ur5")
    assert ur5.default == "tool0" and ur5.frames == (("tool0", 6), ("ee_link", 6), ("wrist_3_link", 6))
    panda = candidate_tool_frames("panda")
    assert panda.frames[0] == ("panda_hand_tcp", 7) and ("panda_leftfinger", 8) in panda.frames
    gen3 = candidate_tool_frames(str(GEN3_URDF))
    assert [name for name, _ in gen3.frames] == ["tool_frame", "end_effector_link", "bracelet_link", "camera_link",
                                                 "camera_color_frame", "camera_depth_frame"]
    anymal = candidate_tool_frames("anymal")
    assert anymal.default is None and "floating base" in anymal.why_none and anymal.frames[0] == ("LF_FOOT", 3)


def test_names_that_look_like_tools_and_sensors():
    assert [tool_rank(name) for name in ("tool0", "panda_hand_tcp", "flange", "EndEffector_Link", "link_eef",
                                         "ee_link", "wrist_3_link", "toolbar_pee")] == [0, 0, 1, 2, 2, 2, 3, 3]
    assert [is_sensor(name) for name in ("camera_depth_frame", "imu_link", "rgbd_laser_link", "ultraSound_right",
                                         "base_link", "tool0")] == [True, True, True, True, False, False]
