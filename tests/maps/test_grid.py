"""Map grids: neighbours, positions and thinning, and values that are the decimals written."""

import numpy as np
import pytest

from conftest import ROOT, STUDIES
from helpers.map_studies import ur5_plane
from tribokin.kinematics.robot import load_urdf
from tribokin.maps.grid import GridError, grid_neighbours, make_grid
from tribokin.study.assembly import load_robot
from tribokin.study.map_spec import BoxMap, JointMap
from tribokin.study.reading import load_study


def test_neighbours_along_each_axis():
    class Box:  # only the shape matters: 2 layers x 3 rows x 4 columns
        shape = (2, 3, 4)

    assert grid_neighbours(Box, 0) == [1, 4, 12]
    assert grid_neighbours(Box, 17) == [5, 13, 16, 18, 21]
    assert grid_neighbours(Box, 23) == [11, 19, 22]


def test_grid_positions_coordinates_and_thinning():
    study = ur5_plane([5, 4])
    # 4 rows (v) x 5 columns (u), origin (0, -0.5, 0.2), u along x, v along y
    grid = make_grid(load_robot(study), study.map)
    np.testing.assert_allclose(grid.positions_m([0, 7]), [[-0.1, -0.5, 0.2], [0.0, -0.5 + 0.1 / 3, 0.2]])
    coordinates = grid.coordinates([7])
    np.testing.assert_allclose([coordinates["u_m"][0], coordinates["v_m"][0]], [0.0, 0.1 / 3])
    np.testing.assert_array_equal(grid.every((1, 2, 3)), [[[0, 3], [10, 13]]])
    shown, stride = grid.thinned(6)
    assert stride == 2 and shown.size <= 6
    np.testing.assert_array_equal(shown, grid.every((2, 2, 2)))
    assert grid.thinned(20) == (pytest.approx(np.arange(20).reshape(1, 4, 5)), 1)


def _short(values) -> bool:
    return all(v == float(f"{v:.9g}") for v in np.ravel(values))


@pytest.mark.parametrize("name", sorted(p.stem for p in STUDIES.glob("*.toml") if "[map]" in p.read_text()))
def test_shipped_map_grids_are_the_decimals_written(name):
    study = load_study(STUDIES / f"{name}.toml")
    grid = make_grid(load_robot(study), study.map)
    positions = grid.positions_m(np.arange(grid.size))
    values = grid.axis_values(np.arange(grid.size))
    assert _short(positions) and _short(values)
    assert not np.signbit(positions[positions == 0]).any() and not np.signbit(values[values == 0]).any()
    spec = study.map
    if spec.kind == "plane":
        lows, highs = [spec.extent_u_m[0], spec.extent_v_m[0]], [spec.extent_u_m[1], spec.extent_v_m[1]]
        assert values[0, :2].tolist() == lows and values[-1, :2].tolist() == highs
        directions = np.array([spec.axis_u, spec.axis_v])
        corners = [np.asarray(spec.origin_m) + np.array(b) @ directions for b in (lows, highs)]
        assert positions[[0, -1]].tolist() == np.round(corners, 12).tolist()
    else:
        assert positions[0].tolist() == list(spec.min_m) and positions[-1].tolist() == list(spec.max_m)


def test_joint_and_line_grids_are_the_decimals_written():
    study = load_study({
        "study": {"cycles": 10},
        "robot": {"name": "ur5"},
        "joints": {"friction": {"preset": "42CD4-raw"}, "stiffness": 1.0e5},
        "map": {"kind": "joint", "joints": ["shoulder_pan_joint", "elbow_joint"],
                "ranges": [[-0.55, 0.45], [-2.0, 0.4]], "counts": [21, 7]},
    })
    grid = make_grid(load_robot(study), study.map)
    values = grid.axis_values(np.arange(grid.size))[:, :2]
    assert _short(values) and values[0].tolist() == [-0.55, -2.0] and values[-1].tolist() == [0.45, 0.4]
    assert 0.0 in values[:, 1] and not np.signbit(values[values == 0]).any()  # -2 + 5 · 0.4 rounds to -0.0
    line = make_grid(load_robot(study), ur5_plane([21, 1]).map)
    assert _short(line.positions_m(np.arange(line.size))) and line.axes[1].values.tolist() == [0.0]


@pytest.mark.parametrize("spec, key, message", [
    (BoxMap(min_m=(0.2, 0.0, 0.2), max_m=(0.8, 0.6, 0.7), resolution=(2, 2, 2), rpy_deg=(180.0, 0.0, 0.0)), "rpy_deg",
     "cannot hold the tool's orientation"),
    (BoxMap(min_m=(0.2, 0.0, 0.2), max_m=(0.8, 0.6, 0.7), resolution=(2, 2, 2), start_q=(0.1, 0.1)), "start_q",
     "needs 3 values"),
    (JointMap(joints=("x", "w"), ranges=((0.0, 0.5), (0.0, 0.5)), counts=(2, 2)), "joints[1]", "unknown joint 'w'"),
    (JointMap(joints=("x",), ranges=((0.0, 9.0),), counts=(2,)), "ranges[0]", "leaves the limits of joint 'x'"),
])
def test_a_map_that_does_not_fit_the_robot_is_refused_naming_the_field(spec, key, message):
    """The study adds its file and ``map.`` (tests/integration/test_bad_input.py)."""
    gantry = load_urdf(ROOT / "urdf" / "cartesian_xyz.urdf", "tool")
    with pytest.raises(GridError, match=message) as error:
        make_grid(gantry, spec)
    assert error.value.key == key


def test_the_last_joints_bound_only_where_the_orientation_is_held():
    ur5 = ur5_plane([5, 4])
    held = make_grid(load_robot(ur5), ur5.map)
    gantry = make_grid(load_urdf(ROOT / "urdf" / "cartesian_xyz.urdf", "tool"),
                       BoxMap(min_m=(0.2, 0.0, 0.2), max_m=(0.8, 0.6, 0.7), resolution=(2, 2, 2)))
    assert held.rotation is not None and [sphere.point for sphere in held.reach] == [
        "the tool point", "the origin of joint 'wrist_3_joint'"]
    assert gantry.rotation is None and [sphere.point for sphere in gantry.reach] == ["the tool point"]
