"""Mesh safety: every mesh a URDF names must lie inside the robot's package folders.

:func:`confine_meshes` runs on the URDF's XML before Pinocchio reads it. Each
``<mesh filename=...>`` is resolved the way Pinocchio resolves it (``package://``
and ``model://`` URIs and relative paths against the package folders in order,
``file://`` URIs and absolute paths as they are), then to its real path (symlinks
followed). A mesh outside every package folder is refused, whether its file
exists or not, and so is a Collada (``.dae``) mesh whose images (textures, which
the viewers read and embed) lie outside; the others are rewritten to their real
paths, so Pinocchio opens exactly the files checked and searches no other folder
(not even ``ROS_PACKAGE_PATH``). A mesh that is not a file inside them is returned, named by its path in its package
folder (the loaders then read no geometry, and the views draw the robot as a skeleton), or, where every mesh must
be found (``required``: example-robot-data's own files), an error naming it, the URDF and where it was looked for.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from pathlib import Path

from tribokin.errors import RobotDescriptionError

#: URI schemes Pinocchio resolves against its package folders.
PACKAGE_SCHEMES = ("package", "model")
#: What the error of a mesh that cannot be read says to do: load the robot without meshes (:func:`~tribokin.kinematics.
#: robot.load_urdf`'s argument; a command names its own option instead).
WITHOUT_MESHES = "meshes=False reads no mesh"


def mesh_candidates(reference: str, package_dirs: list[Path]) -> list[Path] | None:
    """The files Pinocchio tries, in order, for the mesh ``reference``: a package URI or relative path in each of
    ``package_dirs``, a ``file://`` URI or absolute path as it is; ``None`` for a URI scheme Pinocchio refuses (it
    then reads nothing)."""
    scheme, separator, rest = reference.partition("://")
    if _names_a_file(reference):
        return [Path(rest if separator else reference)]
    if separator and scheme not in PACKAGE_SCHEMES:
        return None
    return [Path(f"{folder}/{rest if separator else reference}") for folder in package_dirs]


def _names_a_file(reference: str) -> bool:
    """Whether the mesh ``reference`` names its file directly (a ``file://`` URI or an absolute path), rather than
    in the package folders."""
    scheme, separator, _ = reference.partition("://")
    return scheme == "file" if separator else os.path.isabs(reference)


def resolve_mesh(reference: str, package_dirs: list[Path]) -> Path | None:
    """The real path of the file Pinocchio opens for the mesh ``reference``, or ``None`` for a URI
    scheme Pinocchio refuses (it then reads nothing).

    A package URI or relative path found in none of ``package_dirs`` resolves in the first one
    (where it is missing: Pinocchio reads nothing there either).
    """
    candidates = mesh_candidates(reference, package_dirs)
    if candidates is None:
        return None
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
                   allowed_dirs: list[Path] | None = None, required: bool = False) -> tuple[str, ...]:
    """Point every ``<mesh filename=...>`` of ``urdf`` (in place) at the real path of its file, after
    checking that file, and the images of a Collada mesh, lie inside ``allowed_dirs`` (default:
    ``package_dirs``).

    Args:
        urdf: the root element of the URDF at ``urdf_path``.
        urdf_path: the URDF file (named in errors).
        package_dirs: the folders Pinocchio searches, in order.
        allowed_dirs: the folders meshes may lie in (default: ``package_dirs``).
        required: every mesh must be a file; else one that is missing is returned (and left to Pinocchio, which
            reads nothing there).

    Returns:
        the meshes that are not files, each once, in the URDF's order, by their path relative to the allowed folder
        they were looked for in (``pkg/meshes/base.stl`` for ``package://pkg/meshes/base.stl``).

    Raises:
        RobotDescriptionError: naming the first mesh (or image) that resolves outside ``allowed_dirs``, else, when
            ``required``, the first mesh that is not a file, the URDF and where it was looked for.
    """
    roots = [Path(folder).resolve() for folder in (package_dirs if allowed_dirs is None else allowed_dirs)]
    missing = {}
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
        if not mesh.is_file():
            root = next(root for root in roots if mesh.is_relative_to(root))
            missing.setdefault(str(mesh.relative_to(root)), reference)
        element.set("filename", str(mesh))
    if required and missing:
        raise missing_mesh_error(list(missing.values()), urdf_path, package_dirs)
    return tuple(missing)


def missing_mesh_error(missing: list[str], urdf_path: Path, package_dirs: list[Path]) -> RobotDescriptionError:
    """The error of meshes ``missing`` (references as the URDF writes them, the first named) of ``urdf_path``."""
    reference = missing[0]
    searched = mesh_candidates(reference, package_dirs)
    where = (f"at {searched[0]}" if _names_a_file(reference) else f"in the package folders "
             f"({', '.join(map(str, package_dirs))}): no {', '.join(map(str, searched))}")
    others = f" (and {len(missing) - 1} other meshes)" if len(missing) > 1 else ""
    return RobotDescriptionError(f"mesh '{reference}' of {urdf_path} is not found {where}{others}; correct its path "
                                 "in the URDF or list the folder that holds it in robot.package_dirs", "package_dirs")


def missing_meshes_text(missing: tuple[str, ...]) -> str:
    """``missing`` (:func:`confine_meshes`'s) in a few words: the first, and how many others."""
    others = len(missing) - 1
    return missing[0] + (f" and {others} other{'s' if others > 1 else ''}" if others else "")
