"""Robots several test files use: a gantry with a spindle, a screw (no serial chain), random configurations, Gen3
with wide revolute joints."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin

from conftest import GEN3_URDF
from tribokin.kinematics.robot import Robot

#: A gantry whose ram slides along -z (Pinocchio's PrismaticUnaligned) with a spindle turning about z at its end.
GANTRY_URDF = """<?xml version="1.0"?>
<robot name="gantry">
  <link name="frame"/>
  <joint name="x" type="prismatic"><parent link="frame"/><child link="bridge"/>
    <origin xyz="0 0 1.0"/><axis xyz="1 0 0"/><limit lower="0" upper="2" effort="1" velocity="1"/></joint>
  <link name="bridge"/>
  <joint name="y" type="prismatic"><parent link="bridge"/><child link="carriage"/>
    <origin xyz="0 0 0.1" rpy="0 0 0.3"/><axis xyz="0 1 0"/><limit lower="0" upper="1" effort="1" velocity="1"/></joint>
  <link name="carriage"/>
  <joint name="z" type="prismatic"><parent link="carriage"/><child link="ram"/>
    <origin xyz="0.05 0 0"/><axis xyz="0 0 -1"/><limit lower="0" upper="0.5" effort="1" velocity="1"/></joint>
  <link name="ram"/>
  <joint name="ram_end" type="fixed"><parent link="ram"/><child link="flange"/><origin xyz="0 0 -0.2"/></joint>
  <link name="flange"/>
  <joint name="c" type="revolute"><parent link="flange"/><child link="spindle"/>
    <origin xyz="0 0 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <link name="spindle"/>
  <joint name="tool_joint" type="fixed"><parent link="spindle"/><child link="tool"/>
    <origin xyz="0.15 0 -0.1"/></joint>
  <link name="tool"/>
</robot>
"""


def screw_robot() -> Robot:
    """A helical joint (10 mm a turn, about z) carrying a tool 0.1 m off its axis: no axis joint, so no
    :func:`~tribokin.kinematics.chain.serial_chain`."""
    model = pin.Model()
    screw = model.addJoint(0, pin.JointModelHelicalUnaligned(np.array([0.0, 0.0, 1.0]), 0.01), pin.SE3.Identity(),
                           "screw")
    model.addFrame(pin.Frame("tool", screw, 0, pin.SE3(np.eye(3), np.array([0.1, 0.0, 0.0])), pin.FrameType.OP_FRAME))
    return Robot(model, "tool", "screw", np.zeros(1))


def random_q(robot: Robot, count: int, seed: int = 4) -> np.ndarray:
    """(count, nv) configurations within the joint limits (revolute ranges capped at ±4 rad)."""
    rng = np.random.default_rng(seed)
    return rng.uniform(np.maximum(robot.lower_limits, -4), np.minimum(robot.upper_limits, 4), (count, robot.model.nv))


def wide_revolute_urdf(tmp_path):
    """The Gen3 URDF with every continuous joint made revolute within ±1000 rad."""
    root = ET.parse(GEN3_URDF).getroot()
    for joint in root.iter("joint"):
        if joint.get("type") == "continuous":
            joint.set("type", "revolute")
            joint.find("limit").attrib.update(lower="-1000", upper="1000")
    path = tmp_path / "gen3_revolute.urdf"
    path.write_text(ET.tostring(root, encoding="unicode"))
    return path
