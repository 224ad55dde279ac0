"""Propagation of joint deviations to the tool: exact Pinocchio FK and the truncated product of exponentials."""
