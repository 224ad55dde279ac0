"""Calibration: fit the joint model (stiffness, backlash, instrument noise) to measured clouds.

Pure numerics on plain arrays. Modules: :mod:`.data` (measured series and the kinematics at their
poses), :mod:`.model` (parameters, which are free, and what they predict at a pose),
:mod:`.likelihood` (within-pose log-likelihood and its gradient), :mod:`.frame` (measurements in an
unregistered frame: the likelihood with the frame's rotation as a nuisance parameter, its starts,
θ's profile information), :mod:`.fit` (maximum likelihood, standard errors, intervals, AIC),
:mod:`.identifiability` (rank, condition, what the data cannot determine and what to do),
:mod:`.cross_validation` (predicted RP_l and vAP with prediction intervals, leave-one-pose-out).

Points and Jacobians in the same frame: ``fit(..., frame="registered")``. Points in a measuring
frame (a laser tracker's) not registered to the world: ``frame="unknown"`` fits the frame's
rotation with θ, so only what does not depend on the frame informs θ (the ellipsoids' shapes and
their relative orientations, the barycentre differences' lengths and angles), and θ's standard
errors account for the rotation being estimated.
"""
