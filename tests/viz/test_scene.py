"""The meshcat scene, drawn into the server-less window and read back from its scene tree."""

import copy

import numpy as np
import pytest
import umsgpack
from meshcat.servers.tree import find_node

from conftest import AXIS_URDF
from helpers.viz_layers import CUBE, UNIFORM_AXIS, grid_layers
from tribokin.errors import InputError
from tribokin.kinematics.robot import load_urdf
from tribokin.run import run_study
from tribokin.viz.colours import UNREACHABLE_RGB, ColourScale
from tribokin.viz.scene import (
    FIELD_OF_VIEW_DEG,
    FRAME_MARGIN,
    VIEW_ASPECT,
    VIEW_FROM,
    MapLayer,
    build_scene,
    chain_placements,
    choose_magnification,
    framing,
)
from tribokin.viz.scene_file import CycleCloud
from tribokin.viz.static import static_visualizer


def unpack(packed: bytes) -> dict:
    return umsgpack.unpackb(packed)


def node(vis, path: str):
    return find_node(vis.window.tree, ["meshcat", *path.split("/")])


def attribute(obj: dict, name: str) -> np.ndarray:
    data = obj["object"]["geometries"][0]["data"]["attributes"][name]
    return np.frombuffer(data["array"].data, dtype=np.float32).reshape(-1, data["itemSize"])


@pytest.fixture(scope="module")
def drawn():
    result = run_study(copy.deepcopy(UNIFORM_AXIS))
    vis = static_visualizer()
    info = build_scene(vis, result.robot, result.poses[0].q, result.poses, grid_layers(), CUBE)
    return vis, info, result


def test_colour_scale_ends_and_unreachable_grey():
    scale = ColourScale.spanning(np.array([3.0, np.nan, 9.0]), np.array([5.0]))
    assert (scale.low_um, scale.high_um) == (3.0, 9.0)
    low, high, missing = scale.rgb(np.array([3.0, 9.0, np.nan]))
    np.testing.assert_allclose(low, [0.267, 0.005, 0.329], atol=0.01)   # viridis dark purple
    np.testing.assert_allclose(high, [0.993, 0.906, 0.144], atol=0.01)  # viridis yellow
    np.testing.assert_allclose(missing, UNREACHABLE_RGB)
    assert scale.css_gradient().startswith("linear-gradient(to right, rgb(68,1,84) 0%")


@pytest.mark.parametrize("radius_um, expected", [(3.0, 10_000), (4.0, 5_000), (0.02, 1_000_000)])
def test_magnification_is_round_and_draws_the_largest_cloud_a_few_cm(radius_um, expected):
    small = CycleCloud("a", np.array([[0.5, 0, 0], [0.5 + 0.002e-6, 0, 0]]))
    large = CycleCloud("b", np.array([[0.2, 0, 0], [0.2 + 2 * radius_um * 1e-6, 0, 0]]))
    magnification = choose_magnification([small, large])
    assert magnification == expected
    assert 0.01 <= magnification * radius_um * 1e-6 <= 0.03 + 1e-12


def test_no_spread_is_not_magnified():
    assert choose_magnification([CycleCloud("a", np.full((30, 3), 0.4))]) == 1.0


def test_each_map_is_its_own_toggle_coloured_by_rp_l(drawn):
    vis, info, _ = drawn
    layers = grid_layers()
    assert (info.colour_scales["RP_l"].low_um, info.colour_scales["RP_l"].high_um) == (1.0, 8.0)
    maps = node(vis, "tribokin/maps")
    assert sorted(maps) == ["baseline", "treated"]
    for label, layer in layers.items():
        obj = unpack(maps[label].object)
        np.testing.assert_allclose(attribute(obj, "position"), layer.points_m, atol=1e-6)
        np.testing.assert_allclose(attribute(obj, "color"), info.colour_scales["RP_l"].rgb(layer.values_um), atol=1e-6)
    grey = attribute(unpack(maps["baseline"].object), "color")[0]
    np.testing.assert_allclose(grey, UNREACHABLE_RGB, atol=1e-6)


def test_cloud_is_magnified_about_its_barycenter_with_its_3_sigma_ellipsoid(drawn):
    vis, info, result = drawn
    pose = result.poses[0]
    centre = pose.positions_m.mean(axis=0)
    cloud = attribute(unpack(node(vis, "tribokin/poses/P1/cloud").object), "position")
    np.testing.assert_allclose(cloud, centre + info.magnification * (pose.positions_m - centre), atol=1e-5)
    ellipsoid = unpack(node(vis, "tribokin/poses/P1/ellipsoid").object)
    radii = np.diag(np.reshape(ellipsoid["object"]["object"]["matrix"], (4, 4)))[:3]
    spread_x = 3 * info.magnification * pose.positions_m[:, 0].std(ddof=1)  # the axis only moves along x
    assert radii.max() == pytest.approx(spread_x, rel=1e-5)
    transform = np.reshape(unpack(node(vis, "tribokin/poses/P1/ellipsoid").transform)["matrix"], (4, 4)).T
    np.testing.assert_allclose(transform[:3, 3], centre, atol=1e-6)
    assert unpack(node(vis, "tribokin/magnification").object)["object"]["textures"][0]["text"] == \
        f"clouds ×{info.magnification:g}"


def test_cube_has_its_edges_and_iso_points():
    points = CUBE.test_points_m()
    assert list(points) == ["P1", "P2", "P3", "P4", "P5"]
    np.testing.assert_allclose(points["P1"], CUBE.centre_m)
    corners = CUBE.corners_m()
    assert np.ptp(corners, axis=0) == pytest.approx([0.3] * 3)
    half_diagonal = np.sqrt(3) * 0.15
    for name in ("P2", "P3", "P4", "P5"):
        assert np.linalg.norm(points[name] - points["P1"]) == pytest.approx(0.8 * half_diagonal)
    normal = np.cross(corners[3] - corners[0], corners[4] - corners[0])  # the diagonal plane
    for point in points.values():
        assert abs(np.dot(point - corners[0], normal)) < 1e-12


def test_scene_tree_holds_robot_cube_and_labels(drawn):
    vis, _, _ = drawn
    tribokin = node(vis, "tribokin")
    assert {"robot", "maps", "cube", "poses", "magnification"} <= set(tribokin)
    assert {"P1", "P2", "P3", "P4", "P5", "edges"} <= set(tribokin["cube"])
    edges = unpack(tribokin["cube"]["edges"].object)
    assert attribute(edges, "position").shape == (24, 3)
    assert tribokin["robot"]["visuals"]  # the slide and the segment


@pytest.mark.parametrize("points, values, label, key", [
    (np.zeros((4, 2)), np.zeros(4), "a", "points_m"),
    (np.zeros((4, 3)), np.zeros(3), "a", "values_um"),
    (np.zeros((4, 3)), np.zeros(4), "a/b", "label"),
])
def test_bad_map_layer_is_an_input_error(points, values, label, key):
    with pytest.raises(InputError, match=key):
        MapLayer(points, values, label)


def test_unknown_variant_is_refused(drawn):
    _, _, result = drawn
    with pytest.raises(InputError, match="--report"):
        build_scene(static_visualizer(), result.robot, result.poses[0].q, result.poses, variant="medium")


def test_cube_is_optional_and_light_variant_uses_collision_geometry(drawn):
    _, _, result = drawn
    vis = static_visualizer()
    build_scene(vis, result.robot, result.poses[0].q, result.poses, variant="light")
    tribokin = node(vis, "tribokin")
    assert "cube" not in tribokin and "maps" not in tribokin
    assert set(tribokin["robot"]["visuals"]) == {g.name for g in result.robot.collision_model.geometryObjects}


def test_scene_without_poses_writes_no_cloud_magnification(drawn):
    _, _, result = drawn
    vis = static_visualizer()
    build_scene(vis, result.robot, result.poses[0].q, [], grid_layers(), variant="light")
    assert {"robot", "maps"} <= set(node(vis, "tribokin")) and "magnification" not in node(vis, "tribokin")


def test_scene_objects_are_named_by_a_counter_with_their_links_kept(drawn):
    """No clock-based uuid1 reaches the page; every object still names its own geometry and material."""
    from meshcat.servers.tree import walk

    vis, _, _ = drawn
    objects = [unpack(n.object)["object"] for n in walk(vis.window.tree) if n.object is not None]
    declared = [entry["uuid"] for obj in objects for field in ("geometries", "materials", "textures", "images")
                for entry in obj.get(field, [])] + [obj["object"]["uuid"] for obj in objects]
    assert all(u.startswith("00000000-0000-0000-0000-") for u in declared) and len(set(declared)) == len(declared)
    meshes = [obj for obj in objects if "geometry" in obj["object"]]
    assert len(meshes) > 10
    for obj in meshes:
        assert obj["object"]["geometry"] == obj["geometries"][0]["uuid"]
        assert obj["object"]["material"] == obj["materials"][0]["uuid"]
    labels = [obj for obj in objects if "textures" in obj]  # text sprites: material -> texture
    assert labels and all(obj["materials"][0]["map"] == obj["textures"][0]["uuid"] for obj in labels)


def test_scene_info_says_what_it_drew_of_the_robot_and_what_meshcat_could_not(drawn, monkeypatch):
    """The axis is two boxes; one that meshcat fails to load is named, not counted as drawn."""
    from pinocchio.visualize import MeshcatVisualizer

    _, info, result = drawn
    assert (info.robot.geometry, info.robot.meshes, info.robot.shapes, info.robot.not_drawn) == (
        "visual", [], ["box", "box"], [])
    first = result.robot.visual_model.geometryObjects[0].name
    load = MeshcatVisualizer.loadPrimitive

    def failing(viewer, geometry_object):
        if geometry_object.name == first:
            raise RuntimeError("cannot load")
        return load(viewer, geometry_object)

    monkeypatch.setattr(MeshcatVisualizer, "loadPrimitive", failing)
    info = build_scene(static_visualizer(), result.robot, result.poses[0].q, result.poses)
    assert (info.robot.shapes, info.robot.not_drawn) == (["box"], [first])
    assert info.notes == [f"{result.robot.label}: 1 visual geometry objects not drawn (meshcat cannot load them): "
                          f"{first}"]


def test_framing_centres_the_box_and_fits_its_corners_tightly_in_the_view():
    """An independent check of the camera's place: every corner of the grown box within the field of view (its
    angle off the view's axis, up and sideways), and one of them on its edge."""
    low, high = np.array([-0.4, 1.0, 0.0]), np.array([1.6, 2.0, 0.5])
    points = np.vstack([low, high, (low + high) / 2])
    centre, eye = framing(points)
    np.testing.assert_allclose(centre, [0.6, 1.5, 0.25], rtol=0, atol=1e-15)
    np.testing.assert_allclose((eye - centre) / np.linalg.norm(eye - centre), VIEW_FROM, rtol=0, atol=1e-15)
    half = (high - low) / 2 + FRAME_MARGIN * np.linalg.norm(high - low)
    corners = centre + half * np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    forward = -VIEW_FROM
    right = np.cross(forward, [0, 0, 1]) / np.linalg.norm(np.cross(forward, [0, 0, 1]))
    up = np.cross(right, forward)
    seen = corners - eye
    vertical = np.degrees(np.arctan(np.abs(seen @ up) / (seen @ forward)))
    sideways = np.degrees(np.arctan(np.abs(seen @ right) / (seen @ forward)))
    half_height = FIELD_OF_VIEW_DEG / 2
    half_width = np.degrees(np.arctan(VIEW_ASPECT * np.tan(np.radians(half_height))))
    assert vertical.max() <= half_height + 1e-9 and sideways.max() <= half_width + 1e-9
    assert max(vertical.max() - half_height, sideways.max() - half_width) == pytest.approx(0, abs=1e-9)  # tight
    centre_2, eye_2 = framing(2 * points)  # twice the box: twice as far
    np.testing.assert_allclose(eye_2 - centre_2, 2 * (eye - centre), rtol=1e-12)


def test_the_camera_looks_at_the_centre_of_the_robot_and_results(drawn):
    """meshcat's camera looks at the origin: the drawing is moved there, the camera placed in its turned frame."""
    vis, _, result = drawn
    points = np.vstack([chain_placements(result.robot, result.poses[0].q)[0], result.poses[0].positions_m,
                        *[layer.points_m for layer in grid_layers().values()], CUBE.corners_m()])
    centre, eye = framing(points)
    moved = unpack(node(vis, "tribokin").transform)["matrix"]
    np.testing.assert_allclose(np.asarray(moved).reshape(4, 4).T, np.block([[np.eye(3), -centre[:, None]],
                                                                            [np.zeros((1, 3)), 1]]), atol=1e-7)
    camera = find_node(vis.window.tree, ["Cameras", "default", "rotated", "<object>"])
    position = next(unpack(p)["value"] for p in camera.properties if unpack(p)["property"] == "position")
    x, y, z = eye - centre
    np.testing.assert_allclose(position, [x, z, -y])


def test_a_robot_without_geometry_is_drawn_as_its_skeleton(drawn):
    _, _, result = drawn
    robot = load_urdf(AXIS_URDF, "tool", meshes=False)
    q = result.poses[0].q
    points, origins, axes = chain_placements(robot, q)  # a prismatic joint's frame moves with it
    np.testing.assert_allclose(points, [[0, 0, 0], [q[0], 0, 0], robot.tool_placement(q).translation], atol=1e-15)
    np.testing.assert_allclose(points[-1], [q[0] + 0.5, 0, 0], atol=1e-15)  # the segment's end
    np.testing.assert_allclose(origins, points[1:2], atol=0)
    np.testing.assert_allclose(axes, [[1, 0, 0]])
    vis = static_visualizer()
    info = build_scene(vis, robot, q, result.poses)
    assert (info.robot.geometry, info.robot.missing, info.notes) == ("skeleton", (), [])
    assert info.robot.skeleton_text().endswith(": it was loaded without its meshes")
    skeleton = node(vis, "tribokin/robot")
    assert sorted(skeleton) == ["joints", "links"] and list(skeleton["links"]) == ["0", "1"]
    for i, length in enumerate([q[0], 0.5]):  # the slide's travel, the segment
        link = np.asarray(unpack(skeleton["links"][str(i)].transform)["matrix"]).reshape(4, 4).T
        np.testing.assert_allclose(link[:3, 1], [1, 0, 0], atol=1e-15)  # a cylinder's axis is its y axis
        np.testing.assert_allclose(link[:3, 3], points[i:i + 2].mean(axis=0), atol=1e-15)
        cylinder = unpack(skeleton["links"][str(i)].object)["object"]["geometries"][0]
        assert cylinder["type"] == "CylinderGeometry" and cylinder["height"] == pytest.approx(length)
    joint = np.asarray(unpack(skeleton["joints"]["0"].transform)["matrix"]).reshape(4, 4).T
    np.testing.assert_allclose(joint[:3, :3] @ [0, 1, 0], [1, 0, 0], atol=1e-15)
    np.testing.assert_allclose(joint[:3, 3], origins[0], atol=1e-15)
