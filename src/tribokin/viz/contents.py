"""What the views of a study's results show, decided in one place: the figures and their order, the map's
layers in the scene (thinned), the test cube; :func:`write_views` writes them into an output folder."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from matplotlib.figure import Figure

from tribokin.maps.result import MapResult
from tribokin.output.dispatch import result_figures
from tribokin.run import StudyResult
from tribokin.study.names import drift_figure_file, pose_figure_file
from tribokin.viz.figures import drift_figure, repeatability_field, save_drift_figure, save_repeatability_field
from tribokin.viz.maps import map_figure_names, map_figures_drawn, save_map_figures
from tribokin.viz.placement import PLACEMENT_FIGURE, placement_figure, save_placement_figure
from tribokin.viz.report import write_report
from tribokin.viz.scene import Cube, MapLayer
from tribokin.viz.scene_file import save_scene_inputs

#: Most map targets the 3-D scene draws per scenario (larger maps draw every k-th target along each axis).
SCENE_TARGETS = 50_000


#: The directional figures a map's scene shows as layers of their own (the reference scenario's).
DIRECTIONAL_LAYERS = ("vAP_p", "RP_l_multi")


def map_scene_layers(workspace_map: MapResult) -> dict[str, MapLayer]:
    """The map's RP_l per scenario as scene layers, and a directional map's vAP_p and RP_l_multi (``<reference>
    vAP_p``...), at most ``SCENE_TARGETS`` targets each, spread over the grid."""
    shown, stride = workspace_map.grid.thinned(SCENE_TARGETS)
    shown = shown.ravel()
    points = workspace_map.read("position_m", shown)
    layers = {s.name: MapLayer(points, s.figure("RP_l_um", shown), s.name, stride)
              for s in workspace_map.scenarios.values()}
    reference = workspace_map.reference
    for quantity in DIRECTIONAL_LAYERS:
        if reference.has(f"{quantity}_um"):
            label = f"{reference.name} {quantity}"
            layers[label] = MapLayer(points, reference.figure(f"{quantity}_um", shown), label, stride, quantity)
    return layers


def study_cube(result: StudyResult) -> Cube | None:
    """The study's ISO 9283 test cube, if it has one."""
    iso_cube = result.settings.get("iso_cube")
    return None if iso_cube is None else Cube(tuple(iso_cube["center_m"]), iso_cube["side_m"])


def figure_names(result: StudyResult) -> list[str]:
    """The figures of ``result``'s output folder in reading order, as the report's figures show them: the placement's
    heat map, each pose's field (poses in study order), then the map's (reference, scenarios, ratios, differences,
    winner); each pose's drift figure is in the report's drift section."""
    names = [PLACEMENT_FIGURE] if result.placement is not None else []
    names += [pose_figure_file(pose.name) for pose in result.poses]
    return names + (map_figure_names(result.map) if result.map is not None else [])


def pose_title(result: StudyResult, pose) -> str:
    """The title of a pose's figure in ``result``'s folder."""
    return f"{result.name} — {pose.name}"


def drift_title(result: StudyResult, drift) -> str:
    """The title of a pose's drift figure in ``result``'s folder."""
    return f"{result.name} — {drift.pose}: ISO 9283 drift test, simulated"


@result_figures.register(StudyResult)
def study_figures(result: StudyResult) -> dict[str, Figure]:
    """The figures :func:`write_views` writes, by file name in :func:`figure_names`' order (each pose's drift
    figure after the poses' fields), as matplotlib Figures (each saved as a PNG, the folder's bytes:
    :func:`tribokin.viz.canvas.save_png`)."""
    figures = {} if result.placement is None else {PLACEMENT_FIGURE: placement_figure(result.placement, result.name)}
    figures.update({pose_figure_file(pose.name): repeatability_field(pose, pose_title(result, pose))
                    for pose in result.poses})
    figures.update({drift_figure_file(drift.pose): drift_figure(drift, drift_title(result, drift))
                    for drift in result.drifts})
    return figures | (map_figures_drawn(result.map, result.name) if result.map is not None else {})


@dataclass(frozen=True)
class DrawnElsewhere:
    """Map figures another process draws into the same folder meanwhile: their file ``names``, and ``wait()``,
    which returns once they are there."""

    names: frozenset[str]
    wait: Callable[[], None]


def write_views(result: StudyResult, folder: Path, report: str = "full", map_layers: dict[str, MapLayer] | None = None,
                cube: Cube | None = None, elsewhere: DrawnElsewhere | None = None) -> None:
    """Draw into ``folder`` the placement's heat map, one figure per pose (and its drift test's) and the map's
    figures (but those drawn ``elsewhere``, waited for before the report); with ``report`` ``"full"`` or
    ``"light"`` (robot visual or collision meshes) also ``report.html`` and ``scene.npz`` (for ``tribokin view``),
    drawing ``map_layers`` (default: the map's scenarios, :func:`map_scene_layers`) and ``cube`` (default: the
    study's)."""
    for pose in result.poses:
        save_repeatability_field(pose, folder / pose_figure_file(pose.name), pose_title(result, pose))
    for drift in result.drifts:
        save_drift_figure(drift, folder / drift_figure_file(drift.pose), drift_title(result, drift))
    if result.map is not None:
        save_map_figures(result.map, folder, result.name, None if elsewhere is None else
                         [name for name in map_figure_names(result.map) if name not in elsewhere.names])
    if result.placement is not None:
        save_placement_figure(result.placement, folder / PLACEMENT_FIGURE, result.name)
    if elsewhere is not None:
        elsewhere.wait()
    if report == "none":
        return
    cube = study_cube(result) if cube is None else cube
    if map_layers is None and result.map is not None:
        map_layers = map_scene_layers(result.map)
    _, info = write_report(result, result.robot, folder, figure_names(result), map_layers, cube, variant=report)
    save_scene_inputs(folder, result.display_configuration(), info.magnification, map_layers, cube)
