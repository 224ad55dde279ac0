"""One line per study-file key: what it means, beside the schema's own check and default in :mod:`~tribokin.study.spec`.

``tools/study_reference.py`` writes the docs' study-file reference (``docs/reference/study-file.md``) from the
schema's tables (each key's default, and the range, unit and reason its check holds) and these lines;
``tests/tools/test_study_reference.py`` fails when a key of the schema has no line here, a line names no key, or the
committed page is not what the script writes. Keys are written as in error messages: ``section.key``,
``poses[].key`` for a pose's.
"""

from __future__ import annotations

#: Study-file key -> its meaning, one line (Markdown). Units, defaults and ranges come from the schema.
KEY_DOCS = {
    # [study]
    "study.name": "name used in reports and figure titles (shown as written: `$` is no math); default: the file's "
                  "name; at most 100 printable characters, no `/`",
    "study.cycles": "cycles per pose and approach direction (ISO 9283 uses 30); `--cycles` overrides it",
    "study.seed": "random seed; pose *i* draws from the stream (seed, *i*) and map target *i* from (seed, *i*, 2), so "
                  "results do not depend on the other poses or targets; `--seed` overrides it",
    "study.approach": "the approach directions of each pose: `unidirectional` (`+` for a `[[poses]]` pose; `+x`, "
                      "`+y`, `+z` for a cube pose), `bidirectional` (`+` and `-`; the six axis directions) or "
                      "`random` (`+` or `-` drawn for each cycle); ISO's figures per direction (a map's in "
                      "`<figure>_plus_<unit>`, `<figure>_minus_<unit>` columns, the unsuffixed the larger); see "
                      "[approach directions](../study-files.md#approach-directions)",
    "study.engine": "`fast`: vectorised truncated product of exponentials, exact FK wherever its error bound "
                    "exceeds 0.1 nm ([engines](../concepts.md#forward-kinematics-and-the-engines)); an expected "
                    "map's figures from the first-order model where its bound serves them, else that engine; "
                    "`exact`: exact forward kinematics for every cycle (Pinocchio's, batched for a serial chain), and "
                    "every expected figure (a map's, a pose's) sampled through exact FK, Gaussian laws too: slow "
                    "([maps](../maps.md#per-target-expected-figures))",
    "study.data_dirs": "folders, relative to the study file, from which the files its friction laws name (`file`, "
                       "`log`, `surface`) may also be read (else only the study file's folder), symlinks followed; "
                       "never under `/proc`, `/sys` or `/dev`, nor FIFOs, sockets or devices",
    "study.cycle_time_s": "duration of one ISO cycle (one approach to a pose) [s]: with each joint's "
                          "`travel_per_cycle`, the friction power that `thermal` heats the joint by",
    # [robot]
    "robot.urdf": "URDF file, relative to the study file (give this or `robot.name`); one ending `.xacro` is "
                  "expanded by xacro first, under the checks of the [security model](../security.md)",
    "robot.name": "a robot of example-robot-data, e.g. `\"ur5\"` (`tribokin robots` lists them)",
    "robot.tool_frame": "the frame whose pose is measured; default: the end of the model's longest chain of joints "
                        "([the default tool frame](../your-robot.md#the-default-tool-frame))",
    "robot.package_dirs": "folders that `package://` meshes and `$(find pkg)` resolve against, and the only folders "
                          "meshes and xacro files may lie in; a mesh not found there leaves the robot drawn as a "
                          "skeleton; default: the URDF's folder and its parent",
    "robot.payload_kg": "point mass at the tool frame (or tool point), for bearing loads from statics",
    "robot.tool_offset_m": "`[x, y, z]` of a tool point (a probe's tip, a tracker's reflector) fixed to `tool_frame`, "
                           "in that frame's axes; when set, the "
                           "frame `<tool_frame>_tool_point` is measured and carries the payload",
    "robot.tool_offset_rpy_deg": "the tool point's orientation in `tool_frame` (roll, pitch, yaw; R = R_z R_y R_x); "
                                 "it turns the measured orientation, not the position; default 0, 0, 0",
    "robot.xacro_args": "the xacro's arguments, `{ name = \"value\" }`, each a string as `name:=value` on xacro's "
                        "command line; only with a `.xacro` `robot.urdf`, each one it declares or reads; a number "
                        "no double holds (e.g. 400 digits) is refused",
    "robot.base_xyz_m": "where the robot's base sits in the world frame (the cell's); map grids, cube centres, "
                        "commanded positions, approach directions and heat maps' axes are the world's; default: the "
                        "origin",
    "robot.base_rpy_deg": "the base's orientation in the world (roll, pitch, yaw about the world's x, y, z); gravity "
                          "stays along the world's −z, so a wall or ceiling mount changes the loads; default 0, 0, 0",
    # [joints] and [joints.<joint>]
    "joints.friction": "law of the friction coefficient μ (a preset, a law, a law file, a tribometer log or a "
                       "surface: [friction laws](../study-files.md#friction-laws)); lost motion μ·N·r/k",
    "joints.friction_torque_Nm": "instead of `friction`, for revolute joints: a law of the friction torque τ itself; "
                                 "lost motion τ/k",
    "joints.friction_force_N": "instead of `friction`, for prismatic joints: a law of the friction force itself; lost "
                               "motion force/k",
    "joints.normal_force_N": "load N carried by the joint's slide or bearing; default: computed at each pose from "
                             "statics ([bearing loads](../concepts.md#bearing-loads))",
    "joints.stiffness": "transmission stiffness k, N/m (prismatic) or N·m/rad (revolute); required for every joint",
    "joints.friction_radius_m": "effective friction radius r of a revolute joint (prismatic joints use r = 1)",
    "joints.backlash": "total backlash (m or rad); each approach stops half of it short",
    "joints.offset": "ε_t, the transmission's constant displacement (m or rad): it moves AP, not RP",
    "joints.noise_std": "standard deviation of extra Gaussian noise per cycle (m or rad)",
    "joints.bearing_span_m": "span L between the joint's guide pads or bearings, for the tilting-moment part of the "
                             "load",
    "joints.travel_per_cycle": "the joint's travel in one cycle, both ways summed (m or rad): the friction power is "
                               "the friction force (torque) × this / `study.cycle_time_s`; required with `thermal`",
    # time keys of a joint's friction (friction, friction_torque_Nm, friction_force_N)
    "friction.ar1": "lag-one autocorrelation of the friction's values from cycle to cycle (what a log shows), in "
                    "(−1, 1): a Gaussian-copula AR(1) whose marginal is the law; one the law cannot reach (a "
                    "lognormal's most negative) is refused; [time series](../tribology.md#friction-as-a-time-series)",
    "friction.run_in": "the running-in: the steady mean approached from `start`, μ∞ + (start − μ∞)·exp(−cycle/τ)",
    "friction.age_cycles": "cycles the joint has run before a test's first cycle (a tribometer cycle counts as one "
                           "robot cycle): where on the running-in the test starts",
    "friction.steady_mean_std": "standard deviation of each test's steady mean about the law's (the test-to-test "
                                "spread of the source paper's Fig. 6), in the law's quantity",
    "friction.thermal": "the joint's warm-up by its own friction power (first-order model) and the friction's "
                        "dependence on its temperature; needs `study.cycle_time_s` and `joints.travel_per_cycle`",
    "friction.run_in.start": "the friction at the running-in's first cycle, in the law's quantity (μ; N·m or N for "
                             "a torque or force law)",
    "friction.run_in.tau_cycles": "cycles over which the excess over the steady mean falls by e",
    "friction.thermal.time_constant_s": "τ of the joint's temperature; default estimated: R·C with C ≈ 2 kg of "
                                        "aluminium × 900 J/(kg·K) (a size-25 gear unit's housing)",
    "friction.thermal.resistance_K_per_W": "the temperature rise per watt once settled; default estimated: "
                                           "1/(h·A), natural convection h ≈ 10 W/(m²·K) over A ≈ 0.1 m²",
    "friction.thermal.ambient_C": "the surroundings' temperature, where the law holds (the cold start); default: "
                                  "ISO 9283:1998 §6.3's test temperature",
    "friction.thermal.mu_per_K": "relative change of the friction per kelvin above ambient (−0.005: 0.5 % less "
                                 "per kelvin); give this or `mu_table`",
    "friction.thermal.mu_table": "`[[temperature_C, factor], ...]`: the friction's factor against its value at "
                                 "ambient, linear between rows, constant beyond; temperatures increasing",
    # [[poses]]
    "poses[].name": "pose name, which names files (`field_<pose>.png`, folders of `samples.npz`); default `P1`, `P2`, "
                    "…; at most 100 printable characters, no `/`, no leading `.`, no two differing only in case",
    "poses[].q": "commanded configuration, one value per joint of the tool's chain (a continuous joint's angle), "
                 "within the joint limits",
    "poses[].normal_force_N": "bearing load of every joint at this pose (overrides `joints.normal_force_N`)",
    "poses[].friction": "friction law of every joint at this pose (overrides `joints.friction`)",
    "poses[].directions": "approach directions, each one unidirectional series of `cycles` cycles: `+`, `-` (every "
                          "joint forwards or backwards), `+x`, `-y`, … or a world direction as three signed numbers "
                          "(`+0.58+0.58+0.58`), the tool approaching along it with its orientation held; default "
                          "from `study.approach`",
    # [iso_cube]
    "iso_cube.center_m": "centre of the ISO 9283 test cube, world frame (the section adds poses P1–P5); default: "
                         "the tool position of a well-conditioned posture",
    "iso_cube.side_m": "cube side, edges parallel to the world axes; default: the largest of 0.4, 0.3, 0.2, 0.1, "
                       "0.05 m that fits",
    "iso_cube.rpy_deg": "tool orientation held at P1–P5 (roll, pitch, yaw about the world's x, y, z); default: the "
                        "tool's at the start posture",
    # [map]
    "map.kind": "the grid of targets: `plane`, `box` (tool positions) or `joint` (joint values)",
    "map.start_q": "start posture of the IK (plane, box) or posture of the joints not swept (joint); default: the "
                   "most manipulable of the reference posture and 256 seeded random postures",
    "map.chunk_rows": "grid rows per chunk of work; default: the rows split evenly into chunks of about 131 072 "
                      "targets, at least 4; changes how work is split and saved, never the numbers",
    "map.statistic": "`expected`: each figure's mean over ISO tests of `cycles` cycles; `one-test`: one simulated "
                     "test per target",
    "map.directional": "an expected map's vAP_p and RP_l_multi too; default: on for an expected map (`false` turns "
                       "them off), off for a one-test map, which has none",
    "map.state": "where every test's friction time series start: `\"cold\"` (each joint at its own `age_cycles`, "
                 "ambient), `\"warm\"` (settled) or `{ age_cycles, after_s }`; only with a joint's time keys "
                 "([maps over time](../maps.md#maps-over-time-friction-time-keys))",
    "map.state.age_cycles": "cycles every running-in joint has run before the tests (replacing its own "
                            "`age_cycles`); default: each joint's own; `map.compare`'s likewise",
    "map.state.after_s": "how long the joints have run the study's cycle from cold [s], the warm-up stepped cycle by "
                         "cycle on the law's mean, or `\"warm\"` (settled); at most 1 000 000 cycles",
    "map.compare": "a second state, same forms as `map.state`: each target's `RP_l_change_um` and `AP_p_change_um` "
                   "(compare's minus state's, signed) and their heat maps",
    "map.origin_m": "a point of the plane, world frame",
    "map.axis_u": "unit vector along the plane; targets are `origin + u·axis_u + v·axis_v`",
    "map.axis_v": "unit vector along the plane, perpendicular to `axis_u`",
    "map.extent_u_m": "`[low, high]` of u along `axis_u` from the origin",
    "map.extent_v_m": "`[low, high]` of v along `axis_v` from the origin",
    "map.resolution": "targets along each axis, end points included: `[nu, nv]` (plane), `[nx, ny, nz]` (box)",
    "map.rpy_deg": "tool orientation held at every target (not for robots that cannot hold it); default: the tool's "
                   "at the start posture",
    "map.min_m": "one corner of the box of targets, world frame, edges along the world axes",
    "map.max_m": "the opposite corner of the box of targets",
    "map.joints": "1 to 3 joint names swept by a joint-space map",
    "map.ranges": "`[[low, high], ...]`, one per swept joint, within its limits",
    "map.counts": "values per swept joint, end points included",
    # [calibration]
    "calibration.fit": "what `tribokin calibrate` fits: any of `stiffness`, `backlash`, `noise_floor`",
    "calibration.joints": "`\"all\"` or the joints whose parameters are fitted",
    "calibration.tie": "`none`: one stiffness per fitted joint; `all`: one common stiffness factor for them",
    "calibration.noise_floor_m": "the instrument's noise: its value when `noise_floor` is not fitted (then required)",
    "calibration.tool_rpy_deg": "tool orientation held by the IK of commanded positions when the measurement file "
                                "has no `q_` columns (else position only)",
    # [placement]
    "placement.candidates": "base positions to try, `[[x, y, z], ...]` in the world frame, each once (give these or "
                            "the box of the next three keys)",
    "placement.base_xyz_m_min": "one corner of a box of base positions, world frame",
    "placement.base_xyz_m_max": "the opposite corner of the box of base positions",
    "placement.resolution": "positions along x, y, z of the box `[nx, ny, nz]`, end points included",
    "placement.yaw_deg": "turns about the world's vertical tried at every position, each added to "
                         "`robot.base_rpy_deg`'s yaw (the sum brought within ±360°); each once: two equal modulo 360° "
                         "(`0`, `360`, `-360`) are refused",
    "placement.objective": "the statistic of the expected RP_l over the targets a candidate reaches that ranks it: "
                           "`p95` (95th percentile, linear between order statistics as `numpy.percentile`), `max`, "
                           "`mean`",
    "placement.min_reachable": "share of the task's targets a candidate must reach; one reaching fewer ranks after "
                               "every one that does",
    # [drift]
    "drift.duration_s": "how long ISO 9283's drift test approaches each pose, once every `study.cycle_time_s` (both "
                        "required); [drift](../tribology.md#iso-9283-drift-drift)",
    "drift.set_cycles": "cycles of the first and last sets measured (default: the study's `cycles`); both must fit "
                        "in the duration",
    "drift.start": "`cold` (every joint at ambient) or `warm` (a joint with `thermal` settled where its mean "
                   "friction's power holds it)",
}
