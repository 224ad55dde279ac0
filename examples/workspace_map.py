"""A workspace map with what-if scenarios, without a study file.

A gantry's box of 4 x 4 x 2 targets is mapped three times: with raw 42CD4 bearings (the reference), with treated
ones, and with ten times stiffer joints (``tribokin.MapScenario``: each changes the joint models). Each target's
expected RP_l is computed from the first-order model; the script prints, per scenario, the targets reached and the
median RP_l in µm, and the ratios to the reference (ten times the stiffness: a tenth of the lost motion).
"""

from pathlib import Path

import numpy as np
import pinocchio as pin

import tribokin

URDF = Path(__file__).resolve().parent.parent / "urdf" / "cartesian_xyz.urdf"

robot = tribokin.Robot.from_pinocchio(pin.buildModelFromUrdf(str(URDF)), tool_frame="tool")


def joints(friction: str, stiffness: float = 2.0e7):
    """Every joint with the preset friction law ``friction`` and ``stiffness`` [N/m]."""
    return tribokin.joint_models(robot, friction=tribokin.preset(friction), stiffness=stiffness, bearing_span_m=0.2)


box = tribokin.BoxMap(min_m=(0.2, 0.0, 0.2), max_m=(0.8, 0.6, 0.7), resolution=(4, 4, 2))
scenarios = [tribokin.MapScenario("raw"),
             tribokin.MapScenario("treated", joints=joints("42CD4-treated")),
             tribokin.MapScenario("stiff", joints=joints("42CD4-raw", stiffness=2.0e8))]
workspace = tribokin.workspace_map(robot, joints("42CD4-raw"), box, scenarios=scenarios, cycles=30, seed=1,
                                   payload_kg=5.0)

print(f"targets: {workspace.grid.size}, reached: {int(workspace.reachable.sum())}")
raw = workspace.scenarios["raw"]
for name, scenario in workspace.scenarios.items():
    rp_l = scenario.figure("RP_l_um")
    print(f"{name}: median RP_l = {np.nanmedian(rp_l):.3f} um (min {np.nanmin(rp_l):.3f}, max {np.nanmax(rp_l):.3f})")
for name in ("treated", "stiff"):
    ratio = workspace.ratio_RP_l(workspace.scenarios[name])
    print(f"{name} / raw: RP_l ratio {np.nanmin(ratio):.3f} to {np.nanmax(ratio):.3f} over the targets")
