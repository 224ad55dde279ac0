"""The ISO 9283 cube: positions where the standard puts them, IK to < 1 µm, approach signs."""

import numpy as np
import pinocchio as pin
import pytest

from conftest import ROOT
from tribokin.iso9283.cube import (
    APPROACH_DIRECTIONS,
    RANK_TOLERANCE,
    STILL_RTOL,
    UnreachableCube,
    joint_approach_signs,
    place_cube,
    surely_full_rank,
)
from tribokin.iso9283.metrics import cube_test_positions
from tribokin.kinematics.ik import solve_ik
from tribokin.kinematics.robot import load_example_robot, load_urdf


def test_cube_points_follow_the_standard():
    center, side = np.array([0.4, -0.1, 0.5]), 0.3
    points = cube_test_positions(center, side)
    assert points["P1"] == pytest.approx(center)
    diagonal = side * np.sqrt(3)
    corners = [center + side / 2 * np.array(c) for c in [(-1, -1, 1), (1, 1, 1), (1, 1, -1), (-1, -1, -1)]]
    for name, corner in zip(["P2", "P3", "P4", "P5"], corners, strict=True):
        assert np.linalg.norm(points[name] - corner) == pytest.approx(0.1 * diagonal)  # 10 % of the diagonal
        assert np.linalg.norm(points[name] - center) == pytest.approx(0.4 * diagonal)
    # P2-P5 are coplanar, on the plane x = y through the centre (a diagonal plane of the cube)
    for name in ["P2", "P3", "P4", "P5"]:
        offset = points[name] - center
        assert offset[0] == pytest.approx(offset[1])


@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_ik_reaches_cube_points_to_below_a_micrometre(name):
    robot = load_example_robot(name)
    poses, cube = place_cube(robot, side_m=0.1)
    rotation = pin.rpy.rpyToMatrix(*np.radians(cube["rpy_deg"]))
    for pose in poses:
        placement = robot.tool_placement(pose.q)
        assert np.linalg.norm(placement.translation - pose.position_m) < 1e-6
        assert np.linalg.norm(pin.log3(placement.rotation.T @ rotation)) < 1e-6
        assert np.all(pose.q >= robot.lower_limits) and np.all(pose.q <= robot.upper_limits)


def test_unreachable_cube_is_an_error_naming_the_pose():
    gantry = load_urdf(ROOT / "urdf" / "cartesian_xyz.urdf")
    with pytest.raises(UnreachableCube, match=r"ISO pose P1 at \[3.0, 0.3, 0.4\] m is unreachable"):
        place_cube(gantry, center_m=[3.0, 0.3, 0.4], side_m=0.1)


def test_ik_respects_joint_limits():
    gantry = load_urdf(ROOT / "urdf" / "cartesian_xyz.urdf")
    target = pin.SE3(np.eye(3), np.array([0.5, 0.3, 0.4]))
    assert solve_ik(gantry, target, np.zeros(3)).q == pytest.approx([0.3, 0.3, 0.2], abs=1e-9)
    outside = pin.SE3(np.eye(3), np.array([0.5, 0.3, 0.9]))  # would need q_z = 0.7 > 0.5
    result = solve_ik(gantry, outside, np.zeros(3))
    assert not result.success and result.q[2] == pytest.approx(0.5)


def test_gantry_approach_signs_follow_the_axes():
    gantry = load_urdf(ROOT / "urdf" / "cartesian_xyz.urdf")
    signs = joint_approach_signs(gantry, [0.3, 0.3, 0.2], -np.eye(3))
    assert signs.tolist() == [[-1, 1, 1], [1, -1, 1], [1, 1, -1]]


def test_cube_poses_carry_signs_for_each_labelled_direction_and_its_opposite():
    """Rows in the order of APPROACH_DIRECTIONS: each axis both ways; a joint that does not move keeps +."""
    gantry = load_urdf(ROOT / "urdf" / "cartesian_xyz.urdf")
    poses, _ = place_cube(gantry, [0.3, 0.3, 0.25], 0.1)
    assert list(APPROACH_DIRECTIONS) == ["+x", "-x", "+y", "-y", "+z", "-z"]
    for pose in poses:
        assert pose.approach_signs.tolist() == [[1, 1, 1], [-1, 1, 1], [1, 1, 1], [1, -1, 1], [1, 1, 1], [1, 1, -1]]



def test_held_approach_signs_move_the_tool_along_the_direction_with_its_orientation_held():
    from tribokin.iso9283.cube import held_approach_signs

    robot = load_example_robot("ur5")
    q = np.array([0.1, -1.0, 1.2, -0.8, 1.3, 0.1])  # away from singularities
    directions = np.array([[1.0, 0, 0], [0, 1, 0], [0.6, 0, 0.8]])  # each needs every joint here
    signs = held_approach_signs(robot, q, directions)
    jacobian = robot.tool_jacobian(q)
    for d, row in zip(directions, signs, strict=True):
        speeds = np.linalg.solve(jacobian, np.concatenate([d, np.zeros(3)]))  # independent: a 6x6 solve
        assert np.all(np.abs(speeds) > 1e-6) and np.array_equal(row, np.sign(speeds))



def test_a_joint_that_does_not_move_on_an_approach_has_sign_zero():
    from tribokin.iso9283.cube import held_approach_signs

    robot = load_example_robot("ur5")
    q = np.array([0.1, -1.0, 1.2, -0.8, 1.3, 0.1])
    # a vertical approach lies in the arm's plane: the parallel lift, elbow and wrist_1 axes move the tool there
    # and hold its orientation, so pan, wrist_2 and wrist_3 stay still
    signs = held_approach_signs(robot, q, [0.0, 0.0, 1.0])[0]
    assert signs[[0, 4, 5]].tolist() == [0.0, 0.0, 0.0] and np.all(signs[1:4] != 0)
    step = 1e-7 * signs * np.abs(np.linalg.pinv(robot.tool_jacobian(q)) @ [0.0, 0, 1, 0, 0, 0])
    before, after = robot.tool_placement(q), robot.tool_placement(q + step)
    moved = after.translation - before.translation
    assert moved[2] > 0 and np.hypot(*moved[:2]) < 1e-6 * moved[2]
    assert np.allclose(after.rotation, before.rotation, atol=1e-12)


def near_singular_jacobians(rng: np.random.Generator, nv: int) -> np.ndarray:
    """(4000, 6, nv) random Jacobians of singular values from 0.05 to 2, the smallest of the first 3000 from 1e-9 to
    1e-3."""
    u, _, vt = np.linalg.svd(rng.normal(size=(4000, 6, nv)))
    values = np.sort(rng.uniform(0.05, 2.0, size=(4000, 6)), axis=1)[:, ::-1]
    values[:, -1] = np.where(np.arange(4000) < 3000, 10.0 ** rng.uniform(-9, -3, 4000), values[:, -1])
    return u @ (values[..., None] * vt[:, :6])


@pytest.mark.parametrize("nv", [6, 7])
def test_full_rank_is_sure_only_where_the_svd_finds_it(nv):
    """The determinant's bound claims full rank only where the SVD's smallest singular value exceeds the tolerance
    (every claim checked, near-singular Jacobians included: σ_6 from 1e-9 to 1e-3) and claims it for well-conditioned
    ones, so the SVD is left to the few near a singularity."""
    jacobians = near_singular_jacobians(np.random.default_rng(37), nv)
    smallest = np.linalg.svd(jacobians, compute_uv=False)[:, -1]
    sure = surely_full_rank(jacobians)
    assert not np.any(sure & (smallest <= RANK_TOLERANCE))
    assert sure[3000:].all()  # σ_6 >= 0.05: sure
    assert sure[:3000].any() and not sure[:3000].all()


@pytest.mark.parametrize("nv", [6, 7])
def test_the_compiled_approach_signs_are_numpys(nv, monkeypatch):
    """Approach signs along +x, +y, +z and three random directions, compiled against NumPy: the same on random
    Jacobians (near-singular ones and ones of rank 5 included: the SVD decides those) and at 2000 random
    configurations of a UR5 (nv = 6) or a Panda (7), joints that do not move (sign 0) included."""
    from tribokin.iso9283.cube import approach_signs_from_jacobians
    from tribokin.iso9283.cube_kernels import held_signs

    rng = np.random.default_rng(41)
    robot = load_example_robot("ur5" if nv == 6 else "panda")
    qs = [robot.random_configuration(rng) for _ in range(2000)]
    if nv == 6:
        qs.append(np.array([0.1, -1.0, 1.2, -0.8, 1.3, 0.1]))  # +z moves three joints only
    near = near_singular_jacobians(rng, nv)
    rank_five = near[:200] - near[:200] @ np.einsum("ki,kj->kij", *(np.linalg.svd(near[:200])[2][:, 5],) * 2)
    jacobians = np.concatenate([near, rank_five, [robot.tool_jacobian(q) for q in qs]])
    directions = np.vstack([np.eye(3), rng.normal(size=(3, 3))])
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    signs = {}
    for path in ("numpy", "compiled"):
        monkeypatch.setenv("TRIBOKIN_KERNELS", path)
        signs[path] = approach_signs_from_jacobians(jacobians, directions)
    np.testing.assert_array_equal(signs["compiled"], signs["numpy"])
    sure = held_signs(jacobians, directions, (2 * RANK_TOLERANCE) ** 2, STILL_RTOL)[1]
    assert sure.mean() > 0.5 and not sure[4000:4200].any()  # most compiled; rank 5 left to the SVD
    assert nv == 7 or (signs["compiled"][-1, 2] == 0).sum() == 3
