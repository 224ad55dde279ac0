"""Kinematics: robot loading (URDF, example-robot-data), inverse kinematics, bearing loads."""
