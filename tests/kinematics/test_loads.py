"""Bearing loads from Pinocchio statics against hand statics of the gantry."""

import numpy as np
import pytest

from conftest import ROOT
from tribokin.kinematics.loads import BearingLoads
from tribokin.kinematics.robot import load_urdf

G = 9.81
# masses [kg] and centres of mass from urdf/cartesian_xyz.urdf
M_BEAM, M_CARRIAGE, M_RAM = 40.0, 15.0, 8.0
SPAN = np.array([0.2, 0.25, 0.3])


@pytest.fixture(scope="module")
def gantry():
    return load_urdf(ROOT / "urdf" / "cartesian_xyz.urdf")


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
    n_x = np.linalg.norm(force - force[0] * np.array([1, 0, 0])) + np.linalg.norm(moment) / SPAN[0]
    force, moment = wrench(bodies_x[1:], np.array([qx + 0.1, qy, 0.9]))
    n_y = np.linalg.norm(force - force[1] * np.array([0, 1, 0])) + np.linalg.norm(moment) / SPAN[1]
    force, moment = wrench(bodies_x[2:], np.array([qx + 0.2, qy, 0.8 + qz]))
    n_z = np.linalg.norm(force - force[2] * np.array([0, 0, 1])) + np.linalg.norm(moment) / SPAN[2]
    return np.array([n_x, n_y, n_z])


@pytest.mark.parametrize("q", [(0.0, 0.0, 0.0), (0.3, 0.5, 0.2), (0.6, 0.1, 0.5)])
@pytest.mark.parametrize("payload", [0.0, 5.0])
def test_gantry_loads_match_hand_statics(gantry, q, payload):
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


def test_loads_of_several_configurations_match_hand_statics_each(gantry):
    configurations = np.array([(0.0, 0.0, 0.0), (0.3, 0.5, 0.2), (0.6, 0.1, 0.5)])
    loads = BearingLoads(gantry, 5.0, SPAN)(configurations)
    assert loads.shape == (3, 3)
    for q, row in zip(configurations, loads):
        assert row == pytest.approx(hand_loads(*q, 5.0), rel=1e-9, abs=1e-9)
    assert BearingLoads(gantry, 5.0, SPAN)(np.zeros((0, 3))).shape == (0, 3)
