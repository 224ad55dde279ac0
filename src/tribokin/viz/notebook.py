"""Results in a notebook (Jupyter): the report's 3-D scene inline, offline and without a server, and the output
folder's figures as matplotlib Figures. Each is registered for its result's type in :mod:`tribokin.output.dispatch`,
through which the results' ``_repr_html_`` and ``figures()`` call it (figures sit above the results' stages); a
study's figures: :func:`tribokin.viz.contents.study_figures`."""

from __future__ import annotations

from matplotlib.figure import Figure

from tribokin.kinematics.robot import Robot
from tribokin.maps.result import MapResult
from tribokin.output.dispatch import result_figures, result_scene
from tribokin.run import StudyResult
from tribokin.simulation.pose_result import PoseResult
from tribokin.study.names import pose_figure_file
from tribokin.viz.contents import map_scene_layers, study_cube
from tribokin.viz.figures import repeatability_field
from tribokin.viz.maps import map_figures_drawn
from tribokin.viz.report import scene_frame, static_scene

#: The frame of a scene in a notebook's output: its full width, the report's height and border.
FRAME_STYLE = "width: 100%; height: 560px; border: 1px solid #bbb;"


def scene_html(robot: Robot | None, q, poses=(), map_layers=None, cube=None) -> str | None:
    """The scene the report draws (:func:`~tribokin.viz.report.static_scene`, visual meshes) in an ``<iframe
    srcdoc>``: the page and every scene command inside the output; ``None`` without a robot."""
    if robot is None:
        return None
    return scene_frame(static_scene(robot, q, list(poses), map_layers, cube)[0], FRAME_STYLE)


@result_scene.register(PoseResult)
def pose_scene(pose: PoseResult) -> str | None:
    """The robot at the pose, its cycle cloud and 3σ ellipsoid (magnified as in the report)."""
    return scene_html(pose.robot, pose.q, [pose])


@result_scene.register(MapResult)
def map_scene(workspace_map: MapResult) -> str | None:
    """The robot at the first reachable target (else its reference posture) and the map's layers, as a study's
    report draws them (:func:`~tribokin.viz.contents.map_scene_layers`)."""
    robot = workspace_map.robot
    if robot is None:
        return None
    q = workspace_map.first_reachable_q()
    return scene_html(robot, robot.reference_q if q is None else q, (), map_scene_layers(workspace_map))


@result_scene.register(StudyResult)
def study_scene(result: StudyResult) -> str | None:
    """``report.html``'s scene: its robot, poses, map layers and ISO cube."""
    layers = None if result.map is None else map_scene_layers(result.map)
    return scene_html(result.robot, result.display_configuration(), result.poses, layers, study_cube(result))


@result_figures.register(PoseResult)
def pose_figures(pose: PoseResult) -> dict[str, Figure]:
    """The pose's repeatability field by its file name in an output folder, titled with the pose's name (its drift
    test's figure, with ``[drift]``, is its study's: :func:`~tribokin.viz.contents.study_figures`)."""
    return {pose_figure_file(pose.name): repeatability_field(pose, pose.name)}


@result_figures.register(MapResult)
def map_figures(workspace_map: MapResult, title: str) -> dict[str, Figure]:
    """The map's heat maps by file name (:func:`~tribokin.viz.maps.save_map_figures`), titled ``title: ...``."""
    return map_figures_drawn(workspace_map, title)
