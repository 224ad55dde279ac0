"""The meshcat scene of a study: robot, RP_l maps, ISO cube, and magnified cycle clouds.

Scene paths (each a toggle in meshcat's GUI):

- ``tribokin/robot``            the robot's meshes at the chosen configuration, or, where its meshes were not found,
  its skeleton: links as segments, joints as cylinders on their axes (:func:`draw_skeleton`);
- ``tribokin/maps/<label>``     one point cloud per map layer (scenario), coloured by RP_l;
- ``tribokin/cube``             the ISO 9283 test cube and its points P1–P5;
- ``tribokin/poses/<pose>``     the cycle cloud, its 3-sigma covariance ellipsoid and a label.

Cycle deviations are micrometres: they are drawn around their barycenter,
magnified by a factor written on screen (``clouds ×20000``; not drawn without poses).

The view opens framed on what is drawn (:func:`framing`): meshcat's camera always looks at, and turns about, the
origin, so everything under ``tribokin`` (and meshcat's axes) is moved to put the centre of the robot's and the
results' bounding box there, and the camera is placed to see all of it.
"""

from __future__ import annotations

import math
import os
import warnings
from dataclasses import dataclass, field

import meshcat.geometry as mg
import numpy as np
import pinocchio as pin

from tribokin.errors import InputError
from tribokin.iso9283.metrics import barycenter, position_repeatability
from tribokin.kinematics.robot import Robot
from tribokin.kinematics.urdf_meshes import missing_meshes_text
from tribokin.units import UM_PER_M
from tribokin.viz.colours import ColourScale

#: on-screen size [m] of the largest magnified cycle cloud (its largest distance from the barycenter).
CLOUD_SCREEN_SIZE_M = 0.03
VARIANTS = ("full", "light")
CLOUD_RGB = (0.85, 0.10, 0.35)
CUBE_COLOUR = 0x1D3557
LINK_COLOUR = 0x6C757D
JOINT_COLOUR = 0xE07A1F
#: a skeleton's link radius, joint radius and joint length, as fractions of the largest extent of its chain.
SKELETON_SIZES = (0.012, 0.03, 0.09)
#: the direction the camera looks from, in the world frame (z up): in front, to the right, above.
VIEW_FROM = np.array([1.8, -1.2, 1.5]) / np.linalg.norm([1.8, -1.2, 1.5])
#: the vertical field of view of meshcat's camera [deg].
FIELD_OF_VIEW_DEG = 75.0
#: the width of the view framed, as a multiple of its height (the report's scene is 1.8 times as wide as high).
VIEW_ASPECT = 1.5
#: the framed box grows by this fraction of its diagonal on every side (the robot's meshes reach past its frames).
FRAME_MARGIN = 0.05
#: the smallest half side [m] of the framed box (a single point, a robot folded on itself).
FRAME_MIN_RADIUS_M = 0.1


@dataclass
class MapLayer:
    """One map figure (a scenario's RP_l, or a directional figure) drawn as a coloured point cloud.

    Attributes:
        points_m: (N, 3) target positions in the world frame [m].
        values_um: (N,) the figure at each target [µm]; NaN where the target is unreachable (drawn grey).
        label: the layer's name (the scenario's, for RP_l), shown in the GUI and the report.
        stride: 1 when the layer holds every target of its map, k when every k-th along each grid axis.
        quantity: the figure shown (``"RP_l"``, ``"vAP_p"``, ``"RP_l_multi"``): layers of one quantity share a
            colour scale.
    """

    points_m: np.ndarray
    values_um: np.ndarray
    label: str
    stride: int = 1
    quantity: str = "RP_l"

    def __post_init__(self):
        self.points_m = np.asarray(self.points_m, dtype=float)
        self.values_um = np.asarray(self.values_um, dtype=float)
        source = f"map layer '{self.label}'"
        if self.points_m.ndim != 2 or self.points_m.shape[1] != 3 or not np.all(np.isfinite(self.points_m)):
            raise InputError(f"must be an (N, 3) array of finite positions (got shape {self.points_m.shape})",
                             source, "points_m")
        if self.values_um.shape != (len(self.points_m),):
            raise InputError(f"needs one value per point: shape ({len(self.points_m)},), got {self.values_um.shape}",
                             source, "values_um")
        if "/" in self.label or not self.label.strip():
            raise InputError("must be a non-empty name without '/'", source, "label")


@dataclass(frozen=True)
class Cube:
    """An ISO 9283 test cube with edges parallel to the world axes.

    Attributes:
        centre_m: (3,) centre [m]. edge_m: edge length [m].
    """

    centre_m: tuple[float, float, float]
    edge_m: float

    def corners_m(self) -> np.ndarray:
        """(8, 3) corners [m], index bits (x, y, z) = (i & 1, i & 2, i & 4)."""
        signs = np.array([[(i >> k & 1) * 2 - 1 for k in range(3)] for i in range(8)], dtype=float)
        return np.asarray(self.centre_m) + 0.5 * self.edge_m * signs

    def test_points_m(self) -> dict[str, np.ndarray]:
        """P1 at the centre; P2–P5 at 0.8 of the way from the centre to the corners of the diagonal plane
        through corners 0, 3, 7, 4 (ISO 9283: 10 % of the diagonal from the corners)."""
        corners, centre = self.corners_m(), np.asarray(self.centre_m, dtype=float)
        plane = [corners[i] for i in (7, 4, 0, 3)]
        return {"P1": centre, **{f"P{k + 2}": centre + 0.8 * (c - centre) for k, c in enumerate(plane)}}


@dataclass
class RobotDrawn:
    """The robot's geometry :func:`draw_robot` drew.

    Attributes:
        geometry: the geometry set, ``"visual"`` (variant ``"full"``) or ``"collision"`` (``"light"``), or
            ``"skeleton"`` (the robot has no geometry: :func:`draw_skeleton`).
        meshes: the mesh file of each mesh object drawn, in the model's order (a file drawn twice is named twice).
        shapes: the kind of each primitive shape drawn (``"box"``, ``"cylinder"``, ...).
        not_drawn: names of the geometry objects meshcat could not draw.
        missing: a skeleton's: the meshes not found (:attr:`~tribokin.kinematics.robot.Robot.missing_meshes`).
    """

    geometry: str
    meshes: list[str] = field(default_factory=list)
    shapes: list[str] = field(default_factory=list)
    not_drawn: list[str] = field(default_factory=list)
    missing: tuple[str, ...] = ()

    def skeleton_text(self) -> str:
        """Why and how a skeleton is drawn, in a sentence (without its full stop)."""
        why = (f"its meshes were not found in its package folders ({missing_meshes_text(self.missing)})"
               if self.missing else "it was loaded without its meshes")
        return f"robot drawn as a skeleton (links as segments, joints as cylinders on their axes): {why}"


@dataclass
class SceneInfo:
    """What :func:`build_scene` drew: the magnification, the map colour scale of each quantity (RP_l first), notes
    for the user and the robot's geometry (``None``: the robot has none of the variant's set, not drawn)."""

    magnification: float
    colour_scales: dict[str, ColourScale]
    notes: list[str] = field(default_factory=list)
    robot: RobotDrawn | None = None


def _nice(value: float) -> float:
    """The largest of 1, 2, 5 × 10^k not above ``value`` (to rounding: 9999.999... gives 10000)."""
    value *= 1 + 1e-9
    power = 10.0 ** math.floor(math.log10(value))
    return max(step * power for step in (1, 2, 5) if step * power <= value)


def choose_magnification(poses, screen_size_m: float = CLOUD_SCREEN_SIZE_M) -> float:
    """A round magnification that draws the largest cycle cloud ``screen_size_m`` across [-].

    The cloud size is the largest distance of a cycle from its barycenter; with no
    spread at all (frictionless), the magnification is 1.
    """
    radius = max((np.linalg.norm(p.positions_m - barycenter(p.positions_m), axis=1).max() for p in poses), default=0)
    return _nice(screen_size_m / radius) if radius > 0 else 1.0


def _hex(rgb) -> int:
    r, g, b = (int(round(255 * c)) for c in rgb)
    return (r << 16) + (g << 8) + b


class _Sprite(mg.Object):
    _type = "Sprite"


class _SpriteMaterial(mg.GenericMaterial):
    _type = "SpriteMaterial"


def draw_text(node, text: str, position_m, height_m: float = 0.25) -> None:
    """A camera-facing text label ``height_m`` across (meshcat 0.3.2 has no text geometry)."""
    texture = mg.GenericTexture({"type": "_text", "text": text, "font_size": 36, "font_face": "sans-serif"})
    node.set_object(_Sprite(mg.Box([1e-3] * 3), _SpriteMaterial(map=texture, transparent=True)))
    transform = np.diag([height_m, height_m, height_m, 1.0])
    transform[:3, 3] = position_m
    node.set_transform(transform)


def _point_size_m(points_m: np.ndarray) -> float:
    """A point size [m] of about half the typical spacing of ``points_m``."""
    extent = np.ptp(points_m, axis=0) if len(points_m) > 1 else np.zeros(3)
    occupied = [e for e in extent if e > 1e-9]
    if not occupied:
        return 0.02
    spacing = (np.prod(occupied) / len(points_m)) ** (1 / len(occupied))
    return float(np.clip(0.6 * spacing, 0.004, 0.05))


def robot_geometry(robot: Robot, variant: str):
    """The geometry a report of ``variant`` draws, read on first use: ``("visual", the visual model)`` for
    ``"full"``, else ``("collision", the collision model)`` (a model is ``None`` where the robot has none)."""
    return ("visual", robot.visual_model) if variant == "full" else ("collision", robot.collision_model)


def draw_robot(vis, robot: Robot, q, variant: str) -> tuple[list[str], RobotDrawn | None]:
    """The robot at ``q`` under ``vis["tribokin/robot"]``; returns notes (e.g. no geometry) and what it drew.

    ``"full"`` draws the visual meshes, ``"light"`` the (much smaller) collision meshes (:func:`robot_geometry`); a
    robot without geometry (its meshes not found, or not loaded) is drawn as a skeleton (:func:`draw_skeleton`).
    """
    from pinocchio.visualize import MeshcatVisualizer

    kind, geometry = robot_geometry(robot, variant)
    if geometry is None:
        draw_skeleton(vis["tribokin/robot"], robot, q)
        return [], RobotDrawn("skeleton", missing=robot.missing_meshes)
    viewer = MeshcatVisualizer(robot.model, None, geometry)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")  # recorded, not shown: pinocchio warns that a custom window has no image
        viewer.initViewer(viewer=vis)     # capture, and of each object it cannot load
        viewer.loadViewerModel(rootNodeName="tribokin/robot")
    viewer.display(robot.configuration(q))
    messages = [str(warning.message) for warning in caught]
    drawn = RobotDrawn(kind)
    for item in geometry.geometryObjects:
        if any(f"geometry object: {item.name}\n" in m or f"object named {item.name} is not" in m for m in messages):
            drawn.not_drawn.append(item.name)
        elif os.path.isabs(item.meshPath):
            drawn.meshes.append(item.meshPath)
        else:
            drawn.shapes.append(type(item.geometry).__name__.lower())
    notes = [f"{robot.label}: {len(drawn.not_drawn)} {kind} geometry objects not drawn (meshcat cannot load them): "
             f"{', '.join(drawn.not_drawn)}"] if drawn.not_drawn else []
    return notes, drawn


def chain_placements(robot: Robot, q) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Where ``robot``'s chain is at ``q`` [m or rad], in the world frame: (nv + 2, 3) the points its links join
    [m] (its base: the root link's frame; each joint's origin, in chain order; the tool frame's origin), and per
    joint (nv, 3) its origin [m] and (nv, 3) its unit motion axis."""
    model, data = robot.model, robot.model.createData()
    pin.framesForwardKinematics(model, data, robot.configuration(q))
    bodies = [i for i, frame in enumerate(model.frames) if frame.parentJoint == 0 and frame.type == pin.FrameType.BODY]
    base = data.oMf[bodies[0]].translation if bodies else np.zeros(3)
    origins = np.array([data.oMi[j].translation for j in range(1, model.njoints)])
    axes = np.array([data.oMi[j].rotation @ axis
                     for j, axis in zip(range(1, model.njoints), robot.motion_axes, strict=True)])
    points = np.vstack([base, origins, data.oMf[robot.tool_frame_id].translation])
    return points, origins, axes


def _along(start, end) -> np.ndarray:
    """The 4 x 4 transform that puts a meshcat cylinder (centred, along its y axis) from ``start`` to ``end``."""
    start, end = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    direction = (end - start) / np.linalg.norm(end - start)
    helper = np.eye(3)[np.argmin(np.abs(direction))]  # the base axis least along it
    x = np.cross(direction, helper)
    x /= np.linalg.norm(x)
    transform = np.eye(4)
    transform[:3, :3] = np.column_stack([x, direction, np.cross(x, direction)])
    transform[:3, 3] = (start + end) / 2
    return transform


def draw_skeleton(node, robot: Robot, q) -> None:
    """``robot``'s kinematic chain at ``q`` under ``node``: each link a thin cylinder ``links/<i>`` between the points
    it joins, each joint a short, wider cylinder ``joints/<i>`` on its axis (:func:`chain_placements`), sized by the
    chain's largest extent (``SKELETON_SIZES``)."""
    points, origins, axes = chain_placements(robot, q)
    size = max(float(np.ptp(points, axis=0).max()), 0.1)
    link_radius, joint_radius, joint_length = (fraction * size for fraction in SKELETON_SIZES)
    for i, (start, end) in enumerate(zip(points[:-1], points[1:], strict=True)):
        length = float(np.linalg.norm(end - start))
        if length > 1e-9:  # joints at one point (a wrist) have no link between them
            link = node["links"][str(i)]
            link.set_object(mg.Cylinder(length, link_radius), mg.MeshLambertMaterial(color=LINK_COLOUR))
            link.set_transform(_along(start, end))
    for i, (origin, axis) in enumerate(zip(origins, axes, strict=True)):
        node["joints"][str(i)].set_object(mg.Cylinder(joint_length, joint_radius),
                                          mg.MeshLambertMaterial(color=JOINT_COLOUR))
        node["joints"][str(i)].set_transform(_along(origin - axis * joint_length / 2, origin + axis * joint_length / 2))


def draw_maps(vis, layers: dict[str, MapLayer], scales: dict[str, ColourScale]) -> None:
    """Each layer as a point cloud ``tribokin/maps/<label>``, coloured by its quantity's scale (NaN grey)."""
    for layer in layers.values():
        vis["tribokin/maps"][layer.label].set_object(mg.PointCloud(
            layer.points_m.T, scales[layer.quantity].rgb(layer.values_um).T, size=_point_size_m(layer.points_m)))


def draw_cube(vis, cube: Cube) -> None:
    """The cube's 12 edges and its points P1–P5, labelled."""
    corners = cube.corners_m()
    edges = [(i, i ^ bit) for i in range(8) for bit in (1, 2, 4) if i < i ^ bit]
    segments = np.array([corners[k] for edge in edges for k in edge]).T
    node = vis["tribokin/cube"]
    node["edges"].set_object(mg.LineSegments(mg.PointsGeometry(segments), mg.LineBasicMaterial(color=CUBE_COLOUR)))
    for name, point in cube.test_points_m().items():
        node[name].set_object(mg.Sphere(0.008), mg.MeshLambertMaterial(color=CUBE_COLOUR))
        node[name].set_transform(np.block([[np.eye(3), point[:, None]], [np.zeros((1, 3)), np.ones((1, 1))]]))
        draw_text(node[f"{name}_label"], name, point + [0, 0, 0.03], height_m=0.15)


def draw_pose(vis, pose, magnification: float) -> None:
    """The cycle cloud of ``pose`` magnified about its barycenter, its 3-sigma ellipsoid and a label."""
    centre = barycenter(pose.positions_m)
    deviations = pose.positions_m - centre
    node = vis["tribokin/poses"][pose.name]
    cloud = centre + magnification * deviations
    colours = np.tile(CLOUD_RGB, (len(cloud), 1))
    node["cloud"].set_object(mg.PointCloud(cloud.T, colours.T, size=0.004))
    covariance = np.cov(deviations.T) if len(deviations) > 1 else np.zeros((3, 3))
    variances, axes = np.linalg.eigh(covariance)
    radii = 3 * magnification * np.sqrt(np.clip(variances, 0, None))
    radii = np.maximum(radii, 0.02 * radii.max() + 1e-4)  # flat clouds: a visible disc, not nothing
    if np.linalg.det(axes) < 0:
        axes[:, 0] *= -1
    node["ellipsoid"].set_object(mg.Ellipsoid(radii), mg.MeshLambertMaterial(color=_hex(CLOUD_RGB), opacity=0.3))
    node["ellipsoid"].set_transform(np.block([[axes, centre[:, None]], [np.zeros((1, 3)), np.ones((1, 1))]]))
    rp_l_um = position_repeatability(pose.positions_m)[0] * UM_PER_M
    draw_text(node["label"], f"{pose.name}: RP_l {rp_l_um:.2f} µm", centre + [0, 0, max(radii.max(), 0.02) + 0.04])


def framing(points_m: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Where the camera looks and stands to see every one of ``points_m`` (k, 3) [m] (world frame): the centre of
    their bounding box (grown by ``FRAME_MARGIN`` of its diagonal on every side, to at least ``FRAME_MIN_RADIUS_M``
    from its centre), and the point in direction ``VIEW_FROM`` of it nearest to it from which each corner of that box
    lies within the view (``FIELD_OF_VIEW_DEG`` high, ``VIEW_ASPECT`` times as wide)."""
    low, high = points_m.min(axis=0), points_m.max(axis=0)
    centre = (low + high) / 2
    half = np.maximum((high - low) / 2 + FRAME_MARGIN * float(np.linalg.norm(high - low)), FRAME_MIN_RADIUS_M)
    corners = half * np.array([[(i >> k & 1) * 2 - 1 for k in range(3)] for i in range(8)])
    right = np.cross(VIEW_FROM, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, VIEW_FROM)
    tangent = math.tan(math.radians(FIELD_OF_VIEW_DEG / 2))
    towards = corners @ VIEW_FROM  # each corner's distance from the centre towards the camera
    distance = max(np.max(towards + np.abs(corners @ up) / tangent),
                   np.max(towards + np.abs(corners @ right) / (VIEW_ASPECT * tangent)))
    return centre, centre + float(distance) * VIEW_FROM


def _set_camera(vis, points_m: np.ndarray) -> None:
    """Frame ``points_m`` (:func:`framing`): move the drawing and meshcat's axes by minus the centre (meshcat's camera
    looks at the origin), place the camera, on a plain grey background."""
    centre, eye = framing(points_m)
    moved = np.eye(4)
    moved[:3, 3] = -centre
    vis["tribokin"].set_transform(moved)
    vis["/Axes"].set_transform(moved)
    x, y, z = eye - centre  # the camera's frame is the world's turned by 90 degrees about x (y up)
    vis["/Cameras/default/rotated/<object>"].set_property("position", [float(x), float(z), float(-y)])
    vis["/Background"].set_property("top_color", [0.98, 0.98, 0.98])
    vis["/Background"].set_property("bottom_color", [0.80, 0.80, 0.80])
    vis["/Grid"].set_property("visible", False)


def build_scene(vis, robot: Robot, q, poses, map_layers: dict[str, MapLayer] | None = None,
                cube: Cube | None = None, magnification: float | None = None, variant: str = "full") -> SceneInfo:
    """Draw a study into the meshcat visualizer ``vis``, framed: the drawing (``tribokin``) and meshcat's axes moved
    to put the centre of the robot's chain and the results at the origin, the camera placed to see them all
    (:func:`framing`).

    Args:
        vis: a ``meshcat.Visualizer`` (live, or static: :func:`tribokin.viz.static.static_visualizer`).
        robot: the robot.
        q: its configuration [m or rad] for the drawing.
        poses: objects with ``name``, ``positions_m`` (n, 3) [m]
            (e.g. :class:`~tribokin.simulation.pose_result.PoseResult`).
        map_layers: map figures (RP_l by scenario, directional figures) by label, each toggled on its own in the GUI,
            one colour scale per quantity.
        cube: the ISO 9283 test cube, drawn with P1–P5.
        magnification: cloud magnification [-] (default: :func:`choose_magnification`).
        variant: ``"full"`` (visual meshes) or ``"light"`` (collision meshes, far smaller pages).

    Raises:
        InputError: a mesh outside the robot's package folders, or an unknown variant.
    """
    if variant not in VARIANTS:
        raise InputError(f"must be one of {', '.join(VARIANTS)} (got {variant!r})", "command line", "--report")
    layers = dict(map_layers or {})
    magnification = magnification or choose_magnification(poses)
    notes, drawn = draw_robot(vis, robot, q, variant)
    quantities = dict.fromkeys(layer.quantity for layer in layers.values())
    scales = {quantity: ColourScale.spanning(*[layer.values_um for layer in layers.values()
                                               if layer.quantity == quantity]) for quantity in quantities}
    draw_maps(vis, layers, scales)
    if cube is not None:
        draw_cube(vis, cube)
    for pose in poses:
        draw_pose(vis, pose, magnification)
    tool = robot.tool_placement(q).translation
    if poses:
        draw_text(vis["tribokin/magnification"], f"clouds ×{magnification:g}", tool + [0, 0, 0.25], height_m=0.3)
    extent = [chain_placements(robot, q)[0]] + [p.positions_m for p in poses] + [layer.points_m for layer in
                                                                                 layers.values()]
    if cube is not None:
        extent.append(cube.corners_m())
    _set_camera(vis, np.vstack(extent))
    return SceneInfo(magnification, scales, notes, drawn)
