"""Where to place a robot: the base positions and yaws that serve a task region most repeatably.

The gantry of ``urdf/cartesian_xyz.urdf`` must serve a 0.2 x 0.2 m tray at z = 0.4 m of its cell. A study given as
a mapping (the same structure as a TOML study file) names the tray as its ``map`` and the candidate bases as its
``placement``: 4 x 3 base positions, each facing +x or -x. ``tribokin.run_study`` maps the tray from every candidate
and ranks them (those reaching the whole tray first, then by the p95 of the expected RP_l over the tray). The script
prints the three best candidates and the map of the tray from the best base.
"""

from pathlib import Path

import numpy as np

import tribokin

URDF = Path(__file__).resolve().parent.parent / "urdf" / "cartesian_xyz.urdf"

study = {
    "study": {"name": "tray", "cycles": 30, "seed": 9283},
    "robot": {"urdf": str(URDF), "tool_frame": "tool", "payload_kg": 5.0},
    "joints": {"friction": {"preset": "42CD4-raw"}, "stiffness": 2.0e7, "bearing_span_m": 0.2},  # N/m, m
    "map": {"kind": "plane", "origin_m": [0.5, 0.3, 0.4], "axis_u": [1, 0, 0], "axis_v": [0, 1, 0],
            "extent_u_m": [0.0, 0.2], "extent_v_m": [0.0, 0.2], "resolution": [3, 3]},  # the tray, world frame
    "placement": {"base_xyz_m_min": [0.0, -0.1, 0.0], "base_xyz_m_max": [1.2, 0.5, 0.0], "resolution": [4, 3, 1],
                  "yaw_deg": [0, 180], "objective": "p95", "min_reachable": 1.0},
}
placement = tribokin.run_study(study, meshes=False).placement

print(f"{len(placement.candidates)} candidates, {int(placement.meets_min_reachable.sum())} reach the whole tray")
for rank, i in enumerate(placement.order[:3], 1):
    found = placement.describe(placement.candidates[i])
    x, y, z = found["base_xyz_m"]
    print(f"#{rank}: base at ({x:.2f}, {y:.2f}, {z:.2f}) m, yaw {found['yaw_deg']:g} deg: "
          f"p95 RP_l = {found['RP_l_um']['p95']:.3f} um over {found['reachable_targets']} targets")

best = placement.best
placed = {**study, "robot": {**study["robot"], "base_xyz_m": list(best.base_xyz_m),
                             "base_rpy_deg": list(placement.rpy_deg(best))}}
del placed["placement"]
tray = tribokin.run_study(placed, meshes=False).map.scenarios
rp_l = next(iter(tray.values())).figure("RP_l_um")
print(f"the tray from the best base: RP_l {np.nanmin(rp_l):.3f} to {np.nanmax(rp_l):.3f} um")
