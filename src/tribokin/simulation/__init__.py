"""Simulation: the joint error model and the run of one pose."""
