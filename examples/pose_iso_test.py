"""A pose's ISO 9283 test from Python, without a study file.

A ``pin.Model`` built from a URDF becomes a ``tribokin.Robot`` (reduced to the tool's chain); every joint gets its
error model (friction law, stiffness, bearing span; one joint its own law); the pose is tested over 30 cycles from
each approach direction and its position repeatability RP_l and accuracy AP_p are printed in µm.
"""

from pathlib import Path

import pinocchio as pin

import tribokin

URDF = Path(__file__).resolve().parent.parent / "urdf" / "cartesian_xyz.urdf"

model = pin.buildModelFromUrdf(str(URDF))  # any pin.Model: from a URDF, robot_descriptions, built joint by joint
robot = tribokin.Robot.from_pinocchio(model, tool_frame="tool")
print(f"robot: {robot.label}, joints {', '.join(robot.joint_names)}")

joints = tribokin.joint_models(robot, friction=tribokin.preset("42CD4-raw"), stiffness=2.0e7,  # N/m
                               bearing_span_m=0.2, joints={"z": {"friction": tribokin.preset("42CD4-treated")}})
pose = tribokin.pose_test(robot, joints, [0.3, 0.2, 0.1], name="P", cycles=30, seed=7, payload_kg=5.0,
                          approach="bidirectional")

row = pose.report_row()
print(f"commanded position: {pose.commanded_position_m.round(4).tolist()} m, bearing loads "
      f"{pose.normal_forces_N.round(1).tolist()} N")
for label, figures in row["directions"].items():
    print(f"approach {label}: RP_l = {figures['RP_l_um']:.3f} um, AP_p = {figures['AP_p_um']:.3f} um "
          f"({figures['cycles']} cycles)")
print(f"RP_l over both directions: {row['RP_l_all_directions_um']:.3f} um")
