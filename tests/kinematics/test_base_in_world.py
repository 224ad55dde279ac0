"""A base placed in the world moves every placement and Jacobian with it; gravity stays the world's."""

import numpy as np
import pinocchio as pin
import pytest

from tribokin.kinematics.chain import serial_chain
from tribokin.kinematics.loads import BearingLoads, support_loads
from tribokin.kinematics.reach import reach_sphere
from tribokin.kinematics.robot import load_example_robot, rigid_placement

BASE = rigid_placement([0.7, -0.4, 0.25], [20.0, -35.0, 110.0])


@pytest.mark.parametrize("name", ["ur5", "panda", "kinova"])
def test_placements_and_jacobians_are_the_base_frames_moved_by_the_base(name):
    plain, placed = load_example_robot(name), load_example_robot(name, base=BASE)
    rotation = np.kron(np.eye(2), BASE.rotation)  # a twist's linear and angular parts turn alike
    chain = serial_chain(placed)
    rng = np.random.default_rng(3)
    qs = [placed.random_configuration(rng) for _ in range(20)]
    for q in qs:
        assert np.allclose((BASE * plain.tool_placement(q)).homogeneous, placed.tool_placement(q).homogeneous,
                           rtol=0, atol=1e-14)
        assert np.allclose(rotation @ plain.tool_jacobian(q), placed.tool_jacobian(q), rtol=0, atol=1e-14)
    batched = chain.tool_in_joint(np.array(qs))[:, 0]
    assert np.allclose(batched, [placed.tool_placement(q).homogeneous for q in qs], rtol=0, atol=1e-14)


def test_geometry_hanging_from_the_world_moves_with_the_base_and_the_cached_models_do_not():
    placed = load_example_robot("ur5", base=BASE)
    plain = load_example_robot("ur5")
    for moved, kept in zip(placed.visual_model.geometryObjects, plain.visual_model.geometryObjects, strict=True):
        expected = BASE * kept.placement if kept.parentJoint == 0 else kept.placement
        assert np.allclose(moved.placement.homogeneous, expected.homogeneous, rtol=0, atol=1e-15)
    assert any(item.parentJoint == 0 for item in plain.visual_model.geometryObjects)
    assert np.array_equal(load_example_robot("ur5").visual_model.geometryObjects[0].placement.homogeneous,
                          plain.visual_model.geometryObjects[0].placement.homogeneous)


def test_loads_of_a_tilted_base_are_those_of_gravity_turned_into_the_base_frame():
    """Independent of the batched statics: RNEA on the unplaced robot with gravity g expressed in its base frame."""
    tilted = rigid_placement([0.0, 0.0, 0.0], [90.0, 0.0, 30.0])  # a wall mount
    placed = load_example_robot("ur5", base=tilted)
    plain = load_example_robot("ur5")
    plain.model.gravity = pin.Motion(np.concatenate([tilted.rotation.T @ np.array([0, 0, -9.81]), np.zeros(3)]))
    rng = np.random.default_rng(4)
    qs = np.array([placed.random_configuration(rng) for _ in range(10)])
    spans = np.full(placed.model.nv, 0.08)
    turned = BearingLoads(plain, 3.0, spans)
    wrenches = np.array([turned.wrenches(q) for q in qs])  # RNEA at each
    by_rnea = support_loads(wrenches[..., :3], wrenches[..., 3:], plain.motion_axes, plain.joint_is_prismatic, spans)
    assert np.allclose(BearingLoads(placed, 3.0, spans)(qs), by_rnea, rtol=1e-12, atol=1e-9)
    upright = BearingLoads(load_example_robot("ur5"), 3.0, spans)(qs)
    assert np.abs(by_rnea - upright).max() > 1.0  # the tilt matters: this test could fail


def test_reach_spheres_hold_for_a_placed_base():
    placed = load_example_robot("ur5", base=BASE)
    sphere = reach_sphere(placed)
    rng = np.random.default_rng(5)
    points = np.array([placed.tool_placement(placed.random_configuration(rng)).translation for _ in range(2000)])
    assert np.all(sphere.distances_m(points) <= sphere.radius_m + 1e-12)
    assert np.linalg.norm(sphere.centre_m - BASE.translation) < sphere.radius_m  # the sphere came with the base


def test_a_placed_robot_knows_where_its_base_is_pickled_too():
    import pickle

    placed, plain = load_example_robot("ur5", base=BASE), load_example_robot("ur5")
    assert placed.base_m.tolist() == [0.7, -0.4, 0.25] and plain.base is None and plain.base_m.tolist() == [0.0] * 3
    copy = pickle.loads(pickle.dumps(placed))
    assert np.array_equal(copy.base.homogeneous, BASE.homogeneous) and pickle.loads(pickle.dumps(plain)).base is None
