"""``scene.npz``: the inputs of a study's scene that the output folder does not already hold.

``tribokin view DIR`` rebuilds the scene from the folder without re-running
anything: the robot from ``summary.json["study"]["robot_spec"]`` (absolute
paths; its meshes are read again from disk), the pose names from
``summary.json``, the cycle positions from
``samples.npz`` (absent when the study has no pose), and from ``scene.npz`` the drawing configuration
``robot_q``, the magnification, the map layers
(``map/<label>/points_m`` (N, 3) [m], ``map/<label>/values_um`` (N,) [µm])
in their order (``map_labels``), and the ISO cube (``cube_centre_m`` (3,) [m], ``cube_edge_m`` [m]).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from tribokin.errors import InputError
from tribokin.kinematics.robot import Robot
from tribokin.viz.scene import Cube, MapLayer

SCENE_FILE = "scene.npz"


@dataclass
class CycleCloud:
    """The cycles of one pose, as a scene draws them: ``name`` and ``positions_m`` (n, 3) [m]."""

    name: str
    positions_m: np.ndarray


@dataclass
class SceneInputs:
    """Everything :func:`tribokin.viz.scene.build_scene` needs, read back from an output folder."""

    robot: Robot
    q: np.ndarray
    poses: list[CycleCloud]
    map_layers: dict[str, MapLayer]
    cube: Cube | None
    magnification: float


def save_scene_inputs(folder: Path, q, magnification: float, map_layers: dict[str, MapLayer] | None = None,
                      cube: Cube | None = None) -> None:
    """Write ``folder/scene.npz``."""
    layers = list((map_layers or {}).values())
    arrays = {"robot_q": np.asarray(q, dtype=float), "magnification": np.float64(magnification),
              "map_labels": np.array([layer.label for layer in layers], dtype=str),
              "map_quantities": np.array([layer.quantity for layer in layers], dtype=str)}
    for layer in layers:
        arrays[f"map/{layer.label}/points_m"] = layer.points_m
        arrays[f"map/{layer.label}/values_um"] = layer.values_um
    if cube is not None:
        arrays["cube_centre_m"] = np.asarray(cube.centre_m, dtype=float)
        arrays["cube_edge_m"] = np.float64(cube.edge_m)
    np.savez_compressed(Path(folder) / SCENE_FILE, **arrays)


def load_scene_inputs(folder) -> SceneInputs:
    """Read the scene of an output folder written by ``tribokin run``."""
    from tribokin.study.assembly import load_robot_spec
    from tribokin.study.spec import RobotSpec

    folder = Path(folder)
    for name in ("summary.json", SCENE_FILE):
        _require_file(folder, name)
    summary = json.loads((folder / "summary.json").read_text(encoding="utf-8"))
    robot = load_robot_spec(RobotSpec(**summary["study"]["robot_spec"]), folder / "summary.json")
    poses = []
    if summary["poses"]:  # a map-only run writes no samples.npz
        _require_file(folder, "samples.npz")
        with np.load(folder / "samples.npz") as samples:
            poses = [CycleCloud(row["name"], samples[f"{row['name']}/positions_m"]) for row in summary["poses"]]
    with np.load(folder / SCENE_FILE) as scene:
        labels = [str(label) for label in scene["map_labels"]]
        quantities = [str(q) for q in scene["map_quantities"]] if "map_quantities" in scene else ["RP_l"] * len(labels)
        layers = {label: MapLayer(scene[f"map/{label}/points_m"], scene[f"map/{label}/values_um"], label,
                                  quantity=quantity) for label, quantity in zip(labels, quantities, strict=True)}
        cube = Cube(tuple(scene["cube_centre_m"]), float(scene["cube_edge_m"])) if "cube_edge_m" in scene else None
        return SceneInputs(robot, scene["robot_q"], poses, layers, cube, float(scene["magnification"]))


def _require_file(folder: Path, name: str) -> None:
    if not (folder / name).is_file():
        raise InputError(f"no {name} here; give a folder written by `tribokin run` (report not 'none')", folder, name)
