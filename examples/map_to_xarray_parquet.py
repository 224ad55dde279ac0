"""A map's figures as an xarray Dataset, a pandas DataFrame and a Parquet file.

A plane of 6 x 4 targets through the gantry's travel is mapped for two scenarios; ``to_xarray()`` puts every
figure on the plane's axes (``v``, ``u`` [m]) with a ``scenario`` dimension and the units in ``attrs``;
``to_pandas()`` is the tidy table (one row per scenario and target), written here as ``map.parquet`` and read back.
Needs the data extra: ``pip install 'tribokin[data]'``.
"""

from pathlib import Path

import numpy as np
import pandas as pd
import pinocchio as pin

import tribokin

URDF = Path(__file__).resolve().parent.parent / "urdf" / "cartesian_xyz.urdf"

robot = tribokin.Robot.from_pinocchio(pin.buildModelFromUrdf(str(URDF)), tool_frame="tool")
joints = tribokin.joint_models(robot, friction=tribokin.preset("42CD4-raw"), stiffness=2.0e7, bearing_span_m=0.2)
treated = tribokin.joint_models(robot, friction=tribokin.preset("42CD4-treated"), stiffness=2.0e7,
                                bearing_span_m=0.2)
plane = tribokin.PlaneMap(origin_m=(0.2, 0.0, 0.45), axis_u=(1, 0, 0), axis_v=(0, 1, 0), extent_u_m=(0.0, 0.6),
                          extent_v_m=(0.0, 0.6), resolution=(6, 4))
scenarios = [tribokin.MapScenario("raw"), tribokin.MapScenario("treated", joints=treated)]
workspace = tribokin.workspace_map(robot, joints, plane, scenarios=scenarios, seed=2, payload_kg=5.0)

dataset = workspace.to_xarray()
rp_l = dataset["RP_l_um"]
print(f"RP_l_um dims {rp_l.dims}, shape {rp_l.shape}, units {rp_l.attrs['units']}")
print(f"mean RP_l along v (raw), {rp_l.attrs['units']}: "
      + ", ".join(f"v = {v:.2f} m: {value:.3f}" for v, value in zip(dataset["v"].values,
                                                                   rp_l.sel(scenario="raw").mean("u").values,
                                                                   strict=True)))

frame = workspace.to_pandas()
frame.to_parquet("map.parquet")
back = pd.read_parquet("map.parquet")
medians = back.groupby("scenario", sort=False)["RP_l_um"].median()
print(f"map.parquet: {len(back)} rows x {back.shape[1]} columns; median RP_l: "
      + ", ".join(f"{name} {value:.3f} um" for name, value in medians.items()))
print(f"same numbers as the Dataset: {np.allclose(np.sort(back['RP_l_um']), np.sort(rp_l.values.ravel()))}")
