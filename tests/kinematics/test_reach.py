"""The reach of a robot's chain: a sphere the tool point never leaves within the joint limits, and one the last
joint's origin never leaves (placed by the tool pose), checked against forward kinematics at random configurations."""

import numpy as np
import pytest

from conftest import AXIS_URDF, GEN3_URDF, ROOT
from tribokin.kinematics.reach import REACH_MARGIN_M, last_joint_sphere, reach_sphere
from tribokin.kinematics.robot import load_example_robot, load_urdf, rigid_placement

ROBOTS = {
    "ur5": lambda: load_example_robot("ur5"),
    "panda": lambda: load_example_robot("panda"),
    "gantry": lambda: load_urdf(ROOT / "urdf" / "cartesian_xyz.urdf", "tool"),
    "axis": lambda: load_urdf(AXIS_URDF, "tool"),
    "gen3": lambda: load_urdf(GEN3_URDF),  # continuous joints: no limits
    "ur5 with a tool offset": lambda: load_example_robot(
        "ur5", tool_offset=rigid_placement([0.05, -0.1, 0.2], [10, 20, 30])),
}


def sampled_q(robot, count: int = 10_000) -> np.ndarray:
    """(count, nv) random configurations [m or rad] within the limits (a continuous joint's within ±4 rad), the limits'
    corners included."""
    rng = np.random.default_rng(5)
    lower, upper = np.maximum(robot.lower_limits, -4.0), np.minimum(robot.upper_limits, 4.0)
    q = rng.uniform(lower, upper, (count, robot.model.nv))
    corners = rng.integers(0, 2, q.shape).astype(bool)
    q[: count // 10] = np.where(corners, lower, upper)[: count // 10]
    return q


def sampled_distances_m(robot, sphere) -> np.ndarray:
    """Distances [m] of the tool point from the sphere's centre at the configurations of :func:`sampled_q`."""
    return sphere.distances_m([robot.tool_placement(qi).translation for qi in sampled_q(robot)])


@pytest.mark.parametrize("name", ROBOTS)
def test_the_tool_point_never_leaves_the_sphere(name):
    robot = ROBOTS[name]()
    sphere = reach_sphere(robot)
    distances = sampled_distances_m(robot, sphere)
    assert distances.max() <= sphere.radius_m + 1e-12  # rounding, where the bound is exact; far below the margin
    assert np.all(np.isnan(sphere.beyond_m(robot.tool_placement(robot.reference_q).translation)))


@pytest.mark.parametrize("name", ROBOTS)
def test_the_tool_pose_places_the_last_joint_within_its_sphere(name):
    robot = ROBOTS[name]()
    sphere = last_joint_sphere(robot)
    joint = robot.model.frames[robot.tool_frame_id].parentJoint
    implied, origins = [], []
    for q in sampled_q(robot):
        tool = robot.tool_placement(q)  # forward kinematics of every joint too
        implied.append(sphere.bounded_points_m(tool.translation, tool.rotation)[0])
        origins.append(robot.data.oMi[joint].translation.copy())
    np.testing.assert_allclose(implied, origins, rtol=0, atol=1e-12)
    assert sphere.distances_m(origins).max() <= sphere.radius_m + 1e-12
    with pytest.raises(ValueError, match="none is held"):
        sphere.bounded_points_m(tool.translation, None)


@pytest.mark.parametrize("name, slack", [("ur5", 0.05), ("panda", 0.1), ("gantry", 0.05), ("axis", 0.0),
                                         ("gen3", 0.05)])
def test_the_sphere_is_not_much_larger_than_the_reach(name, slack):
    robot = ROBOTS[name]()
    sphere = reach_sphere(robot)
    assert sphere.radius_m <= (1 + slack) * sampled_distances_m(robot, sphere).max()


def test_the_ur5_sphere_is_centred_on_its_first_joint():
    robot = load_example_robot("ur5")
    sphere = reach_sphere(robot)
    np.testing.assert_allclose(sphere.centre_m, robot.model.jointPlacements[1].translation, atol=1e-15)
    assert 0.95 < sphere.radius_m < 0.97  # the stretched arm: about 0.95 m


def test_how_far_beyond_counts_only_past_the_margin():
    sphere = reach_sphere(load_urdf(AXIS_URDF, "tool"))  # the slide: the tool point on a 0.4 m segment
    direction = np.array([1.0, 0.0, 0.0])
    points = sphere.centre_m + np.outer([0.0, sphere.radius_m + REACH_MARGIN_M / 2, sphere.radius_m + 0.25],
                                        direction)
    gaps = sphere.beyond_m(points)
    assert np.isnan(gaps[:2]).all() and gaps[2] == pytest.approx(0.25)
