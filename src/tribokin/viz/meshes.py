"""Mesh safety: only mesh files inside the robot's package folders may be read into a scene."""

from __future__ import annotations

from pathlib import Path

from tribokin.errors import InputError
from tribokin.robot import Robot


def mesh_files(robot: Robot, geometry_model) -> list[Path]:
    """The mesh files ``geometry_model`` reads, after checking each resolves inside ``robot.package_dirs``.

    Raises:
        InputError: naming the first mesh that resolves elsewhere (an absolute path
            outside, or ``..`` escaping the package folders).
    """
    if geometry_model is None:
        return []
    roots = [Path(d).resolve() for d in robot.package_dirs]
    files = []
    for geometry in geometry_model.geometryObjects:
        if not geometry.meshPath or not Path(geometry.meshPath).suffix:
            continue  # a primitive (box, cylinder...): no file
        mesh = Path(geometry.meshPath).resolve()
        if not any(mesh.is_relative_to(root) for root in roots):
            raise InputError(f"mesh '{geometry.meshPath}' of '{geometry.name}' resolves to '{mesh}', outside the "
                             f"package folders ({', '.join(map(str, roots)) or 'none'}); move it under one of them "
                             "or list its folder in robot.package_dirs", robot.label, "robot.package_dirs")
        files.append(mesh)
    return files
