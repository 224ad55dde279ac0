"""Workspace maps: target grids and their IK, the on-disk store, streamed statistics, the map run."""
