"""Bearing loads: the two supports' forces against equilibrium and hand cases, Pinocchio statics against hand
statics of the gantry."""

import numpy as np
import pinocchio as pin
import pytest

from conftest import ROOT
from tribokin.kinematics.loads import BearingLoads, support_forces, support_loads
from tribokin.kinematics.robot import load_example_robot, load_urdf

G = 9.81
# masses [kg] and centres of mass from urdf/cartesian_xyz.urdf
M_BEAM, M_CARRIAGE, M_RAM = 40.0, 15.0, 8.0
SPAN = np.array([0.2, 0.25, 0.3])


@pytest.fixture(scope="module")
def gantry():
    return load_urdf(ROOT / "urdf" / "cartesian_xyz.urdf")


def carriages(force, moment, axis, span):
    """Hand free body of two carriages at +-span/2 along ``axis``: R+ and R- (each normal to the axis) solved from
    R+ + R- = F_r and (span/2) axis x (R+ - R-) = M_t by least squares, and the roll moment about the axis."""
    cross = np.cross(np.eye(3), axis).T  # cross @ v = axis x v
    equations = np.block([[np.eye(3), np.eye(3)], [cross * span / 2, -cross * span / 2],
                          [axis[None], np.zeros((1, 3))], [np.zeros((1, 3)), axis[None]]])
    radial, tilting = force - force @ axis * axis, moment - moment @ axis * axis
    solution = np.linalg.lstsq(equations, np.concatenate([radial, tilting, [0, 0]]), rcond=None)[0]
    return np.linalg.norm(solution[:3]) + np.linalg.norm(solution[3:]) + 2 * abs(moment @ axis) / span


def hand_loads(qx, qy, qz, payload=0.0):
    """Hand statics. X joint origin at (qx, 0, 1.0): it carries everything; Y at (qx+0.1, qy, 0.9):
    carriage, ram and payload; Z (vertical) carries the ram's weight along its own axis (drive)."""
    g = np.array([0, 0, -G])
    bodies_x = [(M_BEAM, np.array([qx, 0.35, 1.0])), (M_CARRIAGE, np.array([qx + 0.1, qy, 0.9])),
                (M_RAM, np.array([qx + 0.2, qy, 0.5 + qz])), (payload, np.array([qx + 0.2, qy, 0.2 + qz]))]

    def wrench(bodies, origin):
        force = sum(m * g for m, _ in bodies)
        moment = sum(np.cross(p - origin, m * g) for m, p in bodies)
        return force, moment

    force, moment = wrench(bodies_x, np.array([qx, 0, 1.0]))
    n_x = carriages(force, moment, np.array([1, 0, 0], dtype=float), SPAN[0])
    force, moment = wrench(bodies_x[1:], np.array([qx + 0.1, qy, 0.9]))
    n_y = carriages(force, moment, np.array([0, 1, 0], dtype=float), SPAN[1])
    force, moment = wrench(bodies_x[2:], np.array([qx + 0.2, qy, 0.8 + qz]))
    n_z = carriages(force, moment, np.array([0, 0, 1], dtype=float), SPAN[2])
    return np.array([n_x, n_y, n_z])


def test_support_forces_balance_the_wrench():
    """R+ at +(L/2)a and R- at -(L/2)a sum to F_r, their moments about the origin sum to M_t; batched."""
    rng = np.random.default_rng(1)
    force, moment, axes = rng.normal(size=(3, 4, 5, 3))
    axes /= np.linalg.norm(axes, axis=-1, keepdims=True)
    span = rng.uniform(0.05, 0.5, size=5)
    plus, minus = support_forces(force, moment, axes, span)
    along = lambda v: np.sum(v * axes, axis=-1, keepdims=True) * axes  # noqa: E731
    lever = span[:, None] / 2 * axes
    assert plus + minus == pytest.approx(force - along(force), abs=1e-12)
    assert np.cross(lever, plus) + np.cross(-lever, minus) == pytest.approx(moment - along(moment), abs=1e-12)
    assert np.sum(plus * axes, axis=-1) == pytest.approx(0, abs=1e-12)


def test_revolute_and_prismatic_loads_by_hand():
    """F = (3, 0, 4) N, M = (0, 0.2, 0.05) N·m about a = z, L = 0.1 m: F_a = 4, F_r = (3, 0, 0),
    (M_t x a) / L = (2, 0, 0), so R+ = (3.5, 0, 0), R- = (-0.5, 0, 0): revolute 4 + 3.5 + 0.5 = 8 N (the former
    |F| + |M_t| / L gave 7 N); prismatic 3.5 + 0.5 + roll 2 * 0.05 / 0.1 = 5 N."""
    force, moment = np.array([[3.0, 0, 4]] * 2), np.array([[0, 0.2, 0.05]] * 2)
    loads = support_loads(force, moment, np.array([0, 0, 1.0]), np.array([False, True]), np.array([0.1, 0.1]))
    assert loads == pytest.approx([8.0, 5.0], rel=1e-12)


def test_radial_force_across_the_couple_loads_less_than_the_former_sum():
    """F_r = 10 N along x and M_t = (0.1, 0, 0) N·m with L = 0.1 m, so M_t x a = (0, -1, 0) N at right angles
    to F_r: R+- = (5, -+1, 0), N = 2 sqrt(26) = 10.2 N against the former |F| + |M_t| / L = 11 N."""
    load = support_loads([10.0, 0, 0], [0.1, 0, 0], [0, 0, 1.0], False, 0.1)
    assert load == pytest.approx(2 * np.sqrt(26), rel=1e-12)
    assert load < 11.0


@pytest.mark.parametrize("q", [(0.0, 0.0, 0.0), (0.3, 0.5, 0.2), (0.6, 0.1, 0.5)])
@pytest.mark.parametrize("payload", [0.0, 5.0])
def test_gantry_loads_match_hand_statics(gantry, q, payload, kernel_path):
    loads = BearingLoads(gantry, payload, SPAN)
    assert loads(q) == pytest.approx(hand_loads(*q, payload), rel=1e-9, abs=1e-9)


def test_x_bearings_carry_the_weight_of_everything_above(gantry):
    force = BearingLoads(gantry, 0.0, SPAN).wrenches([0.1, 0.2, 0.3])[0, :3]
    assert force[2] == pytest.approx((M_BEAM + M_CARRIAGE + M_RAM) * G)


def test_loads_change_with_the_y_position_not_with_x(gantry):
    loads = BearingLoads(gantry, 0.0, SPAN)
    near, far = loads([0.3, 0.0, 0.2]), loads([0.3, 0.6, 0.2])
    assert far[0] > near[0] + 100  # the carriage's moment on the X guide grows with its reach
    assert loads([0.0, 0.6, 0.2]) == pytest.approx(far)  # moving along X changes nothing
    assert near[2] == pytest.approx(0.0, abs=1e-9)  # the vertical ram's weight goes to its drive


def test_loads_of_several_configurations_match_hand_statics_each(gantry, kernel_path):
    configurations = np.array([(0.0, 0.0, 0.0), (0.3, 0.5, 0.2), (0.6, 0.1, 0.5)])
    loads = BearingLoads(gantry, 5.0, SPAN)(configurations)
    assert loads.shape == (3, 3)
    for q, row in zip(configurations, loads, strict=True):
        assert row == pytest.approx(hand_loads(*q, 5.0), rel=1e-9, abs=1e-9)
    assert BearingLoads(gantry, 5.0, SPAN)(np.zeros((0, 3))).shape == (0, 3)


@pytest.mark.parametrize("name", ["ur5", "panda", "xarm7"])
def test_the_batched_statics_of_a_serial_chain_match_rnea(name, kernel_path):
    """One statics pass over many configurations (the chain's placements, the bodies' weights summed from the tool
    down) gives RNEA's wrenches, and so its loads, to rounding (on either kernel path)."""
    robot = load_example_robot(name)
    loads = BearingLoads(robot, 2.5, np.full(robot.model.nv, 0.08))
    q = np.random.default_rng(7).uniform(robot.lower_limits, robot.upper_limits, (40, robot.model.nv))
    wrenches = loads.chain_wrenches(q)
    for qi, wrench in zip(q, wrenches, strict=True):
        np.testing.assert_allclose(wrench, loads.wrenches(qi), rtol=0, atol=1e-11)
    batched = loads(q)
    loads.chain = None  # RNEA at each configuration
    np.testing.assert_allclose(batched, loads(q), rtol=1e-13)


@pytest.mark.parametrize("name", ["ur5", "panda", "gantry"])
def test_the_compiled_loads_agree_with_numpy(name, gantry, monkeypatch):
    """The compiled statics (:mod:`tribokin.kinematics.loads_kernels`) against the NumPy path at 300 configurations,
    to 1e-12 of each load or of the loads' scale (a load near zero, the gantry's vertical ram, is rounding), from the
    chain's placements or without them; a tilted base (gravity across every axis) too."""
    tilted = pin.SE3(pin.rpy.rpyToMatrix(0.3, -0.2, 0.5), np.array([0.4, -1.0, 0.2]))
    robot = gantry if name == "gantry" else load_example_robot(name, base=tilted)
    loads = BearingLoads(robot, 3.0, np.linspace(0.05, 0.3, robot.model.nv))
    q = np.random.default_rng(11).uniform(robot.lower_limits, robot.upper_limits, (300, robot.model.nv))
    placements = loads.chain.tool_in_joint(q)
    monkeypatch.setenv("TRIBOKIN_KERNELS", "numpy")
    reference = loads(q, placements)
    monkeypatch.setenv("TRIBOKIN_KERNELS", "compiled")
    compiled, without = loads(q, placements), loads(q)
    scale = np.abs(reference).max()
    np.testing.assert_allclose(compiled, reference, rtol=1e-12, atol=1e-12 * scale)
    np.testing.assert_allclose(without, reference, rtol=1e-12, atol=1e-12 * scale)
    assert loads(q[7]) == pytest.approx(reference[7], rel=1e-12, abs=1e-12 * scale)
