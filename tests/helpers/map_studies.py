"""Map studies several test files use: the gantry's plane with its hand statics, small UR5 planes."""

from __future__ import annotations

import numpy as np

from conftest import ROOT
from tribokin.study.reading import load_study

GANTRY = str(ROOT / "urdf" / "cartesian_xyz.urdf")
G = 9.81  # Pinocchio's default gravity [m/s^2]
MU, K, SPAN, PAYLOAD = 0.12, 2.0e7, 0.2, 5.0


def gantry_map_study(**joints) -> dict:
    """Gantry, constant mu, bidirectional cycles: each cycle lands at x_c +/- (dx, dy, dz), dq_i = mu N_i / k.

    The plane spans x = 0.2 .. 0.9 m; the tool reaches x <= 0.8 m (q_x <= 0.6), so the last column is unreachable.
    """
    return {
        "study": {"cycles": 10, "seed": 3, "approach": "bidirectional"},
        "robot": {"urdf": GANTRY, "tool_frame": "tool", "payload_kg": PAYLOAD},
        "joints": {"friction": {"law": "constant", "mu": MU}, "stiffness": K, "bearing_span_m": SPAN, **joints},
        "map": {"kind": "plane", "origin_m": [0.2, 0.0, 0.3], "axis_u": [1, 0, 0], "axis_v": [0, 1, 0],
                "extent_u_m": [0.0, 0.7], "extent_v_m": [0.0, 0.6], "resolution": [8, 4]},
    }


def gantry_loads_by_hand(y):
    """Bearing loads [N] of the gantry's joints by hand statics (urdf/cartesian_xyz.urdf), tool at y = q_y.

    X guide: carries everything (40 + 15 + 8 + 5 kg) perpendicular to x; the weights' pitch moment about y,
    g sum m r_x = g (15*0.1 + (8 + 5)*0.2), loads one carriage up and the other down by pitch / SPAN along the
    weight, so the carriages carry max(weight, 2 pitch / SPAN); their roll moment about x,
    g sum m r_y = g (40*0.35 + 28 y), adds 2 roll / SPAN (the carriages' width taken as SPAN).
    Y guide: carriage, ram, payload (28 kg), and the roll about y of ram and payload 0.1 m out in x.
    Z guide: the weights are along its axis and act on it: no load.
    """
    weight = (40 + 15 + 8 + PAYLOAD) * G
    pitch, roll = G * (15 * 0.1 + 13 * 0.2), G * np.abs(40 * 0.35 + 28 * y)
    return np.maximum(weight, 2 * pitch / SPAN) + 2 * roll / SPAN, 28 * G + 2 * G * 13 * 0.1 / SPAN, 0.0


#: A small UR5 plane (tool pointing down) whose far edge lies beyond the UR5's reach, not the UR10's.
UR5_PLANE = {
    "study": {"name": "robots", "cycles": 30, "seed": 3},
    "robot": {"name": "ur5", "payload_kg": 2.0},
    "joints": {"friction": {"preset": "42CD4-treated"}, "stiffness": 1.0e5, "bearing_span_m": 0.08},
    "map": {"kind": "plane", "origin_m": [0.0, -0.6, 0.1], "axis_u": [1, 0, 0], "axis_v": [0, 1, 0],
            "extent_u_m": [-0.3, 0.3], "extent_v_m": [-0.45, 0.3], "resolution": [5, 6], "rpy_deg": [180, 0, 90]},
}


def ur5_plane(resolution):
    return load_study({
        "study": {"cycles": 10},
        "robot": {"name": "ur5"},
        "joints": {"friction": {"preset": "42CD4-raw"}, "stiffness": 1.0e5},
        "map": {"kind": "plane", "origin_m": [0.0, -0.5, 0.2], "axis_u": [1, 0, 0], "axis_v": [0, 1, 0],
                "extent_u_m": [-0.1, 0.1], "extent_v_m": [0.0, 0.1], "resolution": resolution, "rpy_deg": [180, 0, 90]},
    })
