"""Shared test helpers: robots, studies, measurement files and viewer layers used by several test files."""
