"""Studies: the study file's schema, reading and the assembly of robot and joint models."""
