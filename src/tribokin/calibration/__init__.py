"""Calibration: fit the joint model (stiffness, backlash, instrument noise) to measured clouds.

Pure numerics on plain arrays. Modules: :mod:`.data` (measured series and the kinematics at their
poses), :mod:`.model` (parameters, which are free, and what they predict at a pose),
:mod:`.likelihood` (within-pose log-likelihood and its gradient), :mod:`.fit` (maximum likelihood,
standard errors, intervals, AIC), :mod:`.identifiability` (rank, condition, what the data cannot
determine and what to do), :mod:`.cross_validation` (predicted RP_l and vAP with prediction
intervals, leave-one-pose-out).
"""
