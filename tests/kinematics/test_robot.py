"""Robots: example-robot-data arms and URDFs, reduced to the tool's chain, with a tool point at an offset; errors
list valid names."""

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from conftest import AXIS_URDF, ROOT
from tribokin.errors import ConfigurationError, RobotDescriptionError
from tribokin.kinematics import robot as robot_module
from tribokin.kinematics.robot import TESTED_ROBOTS, load_example_robot, load_urdf, rigid_placement


@pytest.mark.parametrize("name", TESTED_ROBOTS)
def test_example_robots_load_with_one_dof_chains(name):
    robot = load_example_robot(name)
    assert robot.model.nq == robot.model.nv + robot.continuous.sum() and robot.model.nv == len(robot.joint_names) >= 5
    q = np.clip(robot.reference_q, robot.lower_limits, robot.upper_limits)
    assert np.all(np.isfinite(robot.tool_placement(q).translation))
    assert robot.tool_frame == [f.name for f in robot.model.frames][-1] or robot.tool_frame


@pytest.mark.parametrize("name", TESTED_ROBOTS + ("panda_collision", "a1", "anymal_kinova"))
def test_example_robots_are_read_as_example_robot_datas_loader_reads_them(name):
    """The arms and the free flyers (so100, a1, anymal_kinova), read from their loader's attributes with no mesh read,
    and panda_collision (a loader of its own, run whole): the same whole model (the free flyer's limits included),
    reference posture and geometry objects as the loader gives."""
    from example_robot_data.robots_loader import loader

    model, read_geometry, reference_q = robot_module._read_example_robot(name)
    wrapper = loader(name).robot
    assert model == wrapper.model
    assert np.array_equal(reference_q, pin.neutral(wrapper.model) if wrapper.q0 is None else wrapper.q0)
    for kind, theirs in ((pin.GeometryType.VISUAL, wrapper.visual_model),
                         (pin.GeometryType.COLLISION, wrapper.collision_model)):
        ours = read_geometry(kind)
        assert [(g.name, Path(g.meshPath).resolve(), g.parentJoint, g.parentFrame) for g in ours.geometryObjects] == \
            [(g.name, Path(g.meshPath).resolve(), g.parentJoint, g.parentFrame) for g in theirs.geometryObjects]
        assert all(np.array_equal(a.placement.homogeneous, b.placement.homogeneous)
                   for a, b in zip(ours.geometryObjects, theirs.geometryObjects, strict=True))


def test_an_arms_meshes_are_read_when_first_asked_for_each_kind_once(monkeypatch):
    """Loading the UR5 reads no mesh; its collision meshes are read when the collision model is first asked for (a
    light report), its visual ones (a third of a second) only with the visual model; each once."""
    read = []
    build = pin.buildGeomFromUrdf
    monkeypatch.setattr(pin, "buildGeomFromUrdf", lambda model, path, kind, *rest: read.append(kind) or
                        build(model, path, kind, *rest))
    robot_module._example_robot.cache_clear()
    try:
        robot = load_example_robot("ur5", base=rigid_placement([0.1, 0.2, 0.3], [0, 0, 30]))
        assert read == []
        assert robot.collision_model.ngeoms == 8 and read == [pin.GeometryType.COLLISION]
        assert robot.collision_model is robot.collision_model and read == [pin.GeometryType.COLLISION]
        assert robot.visual_model.ngeoms > 0 and read == [pin.GeometryType.COLLISION, pin.GeometryType.VISUAL]
        assert load_example_robot("ur5").visual_model.ngeoms > 0 and len(read) == 2  # read once per process
    finally:
        robot_module._example_robot.cache_clear()


def test_panda_fingers_are_locked():
    panda = load_example_robot("panda")
    assert panda.joint_names == [f"panda_joint{i}" for i in range(1, 8)]


def test_a_urdf_in_a_robots_folder_of_its_own_reads_example_robot_datas_meshes():
    """tiago (like kinova, anymal, solo) keeps its URDF in tiago_description/robots/, inside example-robot-data's
    robots folder: its meshes resolve against the outer one (they were refused as outside the inner one)."""
    tiago = load_example_robot("tiago", "arm_7_link")
    meshes = [Path(geometry.meshPath).resolve() for geometry in tiago.visual_model.geometryObjects
              if "/" in geometry.meshPath]  # not a primitive ("BOX")
    assert len(meshes) > 20 and all(path.is_file() for path in meshes)
    assert all("example-robot-data/robots/tiago_description/meshes/" in path.as_posix() for path in meshes)


def test_a_robot_example_robot_data_cannot_load_is_refused_on_one_line():
    """cassie's description is an SDF file: a Pinocchio built without SDF (this one, CI's) cannot read it, and the
    refusal says why on one line; one built with SDF reads it, and cassie then runs or is refused like any robot."""
    if pin.WITH_SDFORMAT:
        try:
            load_example_robot("cassie")
        except RobotDescriptionError as error:
            assert "\n" not in str(error)
        return
    with pytest.raises(RobotDescriptionError, match="example-robot-data cannot load 'cassie': its description is an "
                       "SDF file, and this Pinocchio .* was built without SDF") as error:
        load_example_robot("cassie")
    assert error.value.argument == "name" and "\n" not in str(error.value)


def test_a_reference_posture_outside_the_limits_is_brought_within_them():
    """kinova's SRDF posture gives joint 3 -1.5707 rad, limited to [0.33, 5.95] rad: a whole turn on, the same
    posture; panda_collision has none (0 rad), outside joint 4's [-3.07, -0.07] rad: clipped."""
    kinova = load_example_robot("kinova")
    assert kinova.reference_q[2] == pytest.approx(-1.5707 + 2 * np.pi, abs=1e-12)
    assert kinova.reference_q[[0, 1, 3, 4, 5]].tolist() == [1.5707, 2.618, 3.1415, 2.618, 0.0]
    assert load_example_robot("panda_collision").reference_q[3] == -0.0698


def test_a_joint_without_travel_is_refused(tmp_path):
    urdf = tmp_path / "stuck.urdf"
    urdf.write_text(AXIS_URDF.read_text().replace('lower="0.0" upper="0.40"', 'lower="0.2" upper="0.2"'))
    with pytest.raises(RobotDescriptionError, match=r"^joint 'x' moves the tool, but its limits \[0.2, 0.2\] leave "
                       r"it no travel; give it a range \(the URDF's <limit lower=... upper=...>\), or make it "
                       "continuous$"):
        load_urdf(urdf, "tool")


def test_unknown_robot_and_frame_list_the_valid_ones():
    with pytest.raises(RobotDescriptionError, match="did you mean 'ur5'.*valid names: .*panda.*ur10") as error:
        load_example_robot("ur55")
    assert error.value.argument == "name" and "\n" not in str(error.value)
    with pytest.raises(RobotDescriptionError, match="tool0") as error:
        load_example_robot("ur5", tool_frame="tool9")
    assert error.value.argument == "tool_frame"


def test_missing_and_malformed_urdf(tmp_path):
    with pytest.raises(RobotDescriptionError, match="not found") as error:
        load_urdf(tmp_path / "none.urdf")
    assert error.value.argument == "path"
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot name='x'><link name='a'></robot>")
    with pytest.raises(RobotDescriptionError, match="cannot read URDF"):
        load_urdf(bad)


def test_gantry_kinematics():
    gantry = load_urdf(ROOT / "urdf" / "cartesian_xyz.urdf")
    assert gantry.joint_names == ["x", "y", "z"] and gantry.tool_frame == "tool"
    assert gantry.joint_is_prismatic.all()
    assert gantry.tool_placement([0.1, 0.2, 0.3]).translation == pytest.approx([0.3, 0.2, 0.5])
    assert gantry.lower_limits.tolist() == [0, 0, 0] and min(gantry.upper_limits) >= 0.5


OFFSET_M = np.array([0.01, -0.02, 0.1])


def ur5_tool_point(offset_m=OFFSET_M, rpy_deg=(0.0, 90.0, 0.0)):
    return load_example_robot("ur5", tool_offset=rigid_placement(offset_m, rpy_deg))


def configurations(robot, count=5, seed=3):
    """``count`` random configurations within the joint limits and a turn either way [rad]."""
    rng = np.random.default_rng(seed)
    return rng.uniform(np.maximum(robot.lower_limits, -np.pi), np.minimum(robot.upper_limits, np.pi),
                       (count, robot.model.nv))


def test_a_tool_offset_is_a_point_fixed_to_the_tool_frame():
    flange, probe = load_example_robot("ur5"), ur5_tool_point()
    assert probe.tool_frame == "tool0_tool_point" and probe.label == "ur5"
    assert probe.joint_names == flange.joint_names and probe.reference_q.tolist() == flange.reference_q.tolist()
    pitch = np.radians(90.0)  # roll, pitch, yaw = 0, 90, 0: a rotation about y by the pitch
    rotation = np.array([[np.cos(pitch), 0, np.sin(pitch)], [0, 1, 0], [-np.sin(pitch), 0, np.cos(pitch)]])
    for q in configurations(flange):
        tool0, point = flange.tool_placement(q), probe.tool_placement(q)
        assert point.translation == pytest.approx(tool0.rotation @ OFFSET_M + tool0.translation, abs=1e-12)
        assert point.rotation == pytest.approx(tool0.rotation @ rotation, abs=1e-12)


def test_the_tool_points_position_jacobian_is_the_derivative_of_its_position():
    probe, step = ur5_tool_point(), 1e-6
    for q in configurations(probe, 3, seed=8):
        columns = [(probe.tool_placement(q + step * e).translation - probe.tool_placement(q - step * e).translation)
                   / (2 * step) for e in np.eye(probe.model.nv)]
        assert probe.tool_jacobian(q)[:3] == pytest.approx(np.array(columns).T, abs=1e-8)


def test_only_an_offset_off_the_last_joints_axis_lets_that_joint_move_the_tool_point():
    """tool0's z axis is wrist_3's axis: a point on it does not move when wrist_3 turns, one off it does (so a
    calibration needs offsets off the axis to see wrist_3)."""
    on_axis, off_axis = ur5_tool_point([0.0, 0.0, 0.1], None), ur5_tool_point([0.05, 0.0, 0.1], None)
    assert on_axis.joint_names[-1] == "wrist_3_joint"
    for q in configurations(on_axis):
        assert np.abs(on_axis.tool_jacobian(q)[:3, -1]).max() < 1e-12
        assert np.linalg.norm(off_axis.tool_jacobian(q)[:3, -1]) == pytest.approx(0.05, rel=1e-9)


def test_a_urdfs_tool_point_is_named_after_its_frame_and_may_not_take_an_existing_name(tmp_path):
    gantry = load_urdf(ROOT / "urdf" / "cartesian_xyz.urdf", tool_offset=rigid_placement([0.0, 0.0, -0.1]))
    assert gantry.tool_frame == "tool_tool_point"
    assert gantry.tool_placement([0.1, 0.2, 0.3]).translation == pytest.approx([0.3, 0.2, 0.4])
    urdf = tmp_path / "axis.urdf"
    urdf.write_text(AXIS_URDF.read_text().replace('<link name="tool"/>', '<link name="tool"/>\n  <joint name="f" '
                    'type="fixed"><parent link="tool"/><child link="tool_tool_point"/></joint>\n  '
                    '<link name="tool_tool_point"/>'))
    with pytest.raises(RobotDescriptionError, match="already has a frame 'tool_tool_point'") as error:
        load_urdf(urdf, "tool", tool_offset=rigid_placement([0.0, 0.0, 0.1]))
    assert error.value.argument == "tool_frame"


def test_a_configuration_outside_the_limits_names_the_joints_unit():
    with pytest.raises(ConfigurationError, match=r"joint 'shoulder_pan_joint' = 7 rad is outside its limits "
                                                 r"\[-6\.28\d*, 6\.28\d*\] rad \(q is in metres for prismatic"):
        load_example_robot("ur5").check_configuration([7.0, 0, 0, 0, 0, 0])
