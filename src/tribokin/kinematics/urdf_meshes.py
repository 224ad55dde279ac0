"""Mesh safety: every mesh a URDF names must lie inside the robot's package folders.

:func:`confine_meshes` runs on the URDF's XML before Pinocchio reads it. Each
``<mesh filename=...>`` is resolved the way Pinocchio resolves it (``package://``
and ``model://`` URIs and relative paths against the package folders in order,
``file://`` URIs and absolute paths as they are), then to its real path (symlinks
followed). A mesh outside every package folder is refused, whether its file
exists or not, and so is a Collada (``.dae``) mesh whose images (textures, which
the viewers read and embed) lie outside; the others are rewritten to their real
paths, so Pinocchio opens exactly the files checked and searches no other folder
(not even ``ROS_PACKAGE_PATH``).
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from pathlib import Path

from tribokin.errors import RobotDescriptionError

#: URI schemes Pinocchio resolves against its package folders.
PACKAGE_SCHEMES = ("package", "model")


def resolve_mesh(reference: str, package_dirs: list[Path]) -> Path | None:
    """The real path of the file Pinocchio opens for the mesh ``reference``, or ``None`` for a URI
    scheme Pinocchio refuses (it then reads nothing).

    A package URI or relative path found in none of ``package_dirs`` resolves in the first one
    (where it is missing: Pinocchio reads nothing there either).
    """
    scheme, separator, rest = reference.partition("://")
    if (separator and scheme == "file") or (not separator and os.path.isabs(reference)):
        return Path(rest if separator else reference).resolve()
    if separator and scheme not in PACKAGE_SCHEMES:
        return None
    candidates = [Path(f"{folder}/{rest if separator else reference}") for folder in package_dirs]
    return next((c for c in candidates if os.path.exists(c)), candidates[0]).resolve()


def collada_images(mesh: Path) -> list[Path]:
    """The real paths of the image files the viewers read with the Collada mesh ``mesh`` (Pinocchio's
    ``DaeMeshGeometry``: each ``init_from`` of its ``library_images``, relative to its folder); none
    when it is not a readable ``.dae`` file."""
    if mesh.suffix.lower() != ".dae":
        return []
    try:
        root = ET.parse(mesh).getroot()
    except (ET.ParseError, OSError):
        return []  # the viewers fail on it too, reading no image
    return [(mesh.parent / image.text).resolve() for library in root.iter() if library.tag.endswith("library_images")
            for image in library.iter() if "init_from" in image.tag and image.text]


def confine_meshes(urdf: ET.Element, urdf_path: Path, package_dirs: list[Path],
                   allowed_dirs: list[Path] | None = None) -> None:
    """Point every ``<mesh filename=...>`` of ``urdf`` (in place) at the real path of its file, after
    checking that file, and the images of a Collada mesh, lie inside ``allowed_dirs`` (default:
    ``package_dirs``).

    Args:
        urdf: the root element of the URDF at ``urdf_path``.
        package_dirs: the folders Pinocchio searches, in order.

    Raises:
        RobotDescriptionError: naming the first mesh (or image) that resolves outside ``allowed_dirs``.
    """
    roots = [Path(folder).resolve() for folder in (package_dirs if allowed_dirs is None else allowed_dirs)]
    for element in urdf.iter("mesh"):
        reference = element.get("filename")
        mesh = None if reference is None else resolve_mesh(reference, package_dirs)
        if mesh is None:
            continue
        for path, role in [(mesh, "resolves to"), *((image, "reads the image") for image in collada_images(mesh))]:
            if not any(path.is_relative_to(root) for root in roots):
                raise RobotDescriptionError(f"mesh '{reference}' of {urdf_path} {role} '{path}', outside the package "
                                            f"folders ({', '.join(map(str, roots))}); move it under one of them or "
                                            "list its folder in robot.package_dirs", "package_dirs")
        element.set("filename", str(mesh))
