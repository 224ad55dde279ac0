"""Write a synthetic ISO 9283 laser-tracker measurement of a UR5, made from known parameters (issue 21).

    python tools/ur5_tracker_data.py --out studies/data/ur5-tracker.csv [--seed 9283] [--force]

The committed ``studies/data/ur5-tracker.csv`` is this command with the default seed. Five ISO cube poses
P1-P5 (:data:`CUBE`, solved by ``tribokin.iso9283.cube.place_cube`` on example-robot-data's ``ur5``, tool
frame ``tool0``), each approached :data:`CYCLES` times from each of ``+x, +y, +z`` (along the base axes,
the tool's orientation held). Per pose the joints carry a constant offset eps_i (its geometric error);
per cycle j the joints stop short by their lost motion (:func:`simulate`):

    dq_ij = eps_i + s_ij * (tau_ij / k_i + b_i / 2)

s_ij the joint's direction of travel on the approach (``held_approach_signs``: +1, -1, or 0 for a joint
that does not move, which then loses no motion), tau_ij its friction torque (Gaussian, truncated at 0),
k_i its stiffness, b_i its backlash. The tool point is Pinocchio's exact forward kinematics of q + dq,
plus isotropic Gaussian instrument noise, moved into the tracker frame: p_tracker = R p_base + t.

Columns (tribokin's measurement contract): ``pose, cycle, direction``; measured tool point
``x_m, y_m, z_m`` in the TRACKER frame; commanded position ``cx_m, cy_m, cz_m`` in the base frame
(the forward kinematics of the commanded configuration); commanded ``q_<joint>`` [rad]. ``#`` lines
state that the data are synthetic, the command, the seed and every true value (:class:`Truth`).
Values are written as ``repr`` of the floats: reading them back gives the same numbers. The same seed
gives the same bytes. An existing ``--out`` is replaced only with ``--force``; bad input is one line
``ur5_tracker_data: error: <file>: <what to fix>``, exit status 2, no file written.
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import dataclass, fields
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pinocchio as pin
from output_file import check_out, write_atomically

from tribokin.errors import InputError
from tribokin.iso9283.cube import APPROACH_DIRECTIONS, CubePose, held_approach_signs, place_cube
from tribokin.kinematics.robot import Robot, load_example_robot
from tribokin.output.provenance import software_versions
from tribokin.tribology.laws import Gaussian

ROBOT = "ur5"
JOINTS = ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint",
          "wrist_3_joint")
#: The ISO cube: centre [m] and side [m] in the base frame, tool orientation (fixed-axis x-y-z, [deg]); chosen
#: reachable, with Jacobian condition numbers 7-9 at P1-P5, every joint moving on some approach.
CUBE = {"center_m": (0.4, -0.2, 0.35), "side_m": 0.3, "rpy_deg": (150.0, -20.0, 45.0)}
DIRECTIONS = {label: APPROACH_DIRECTIONS[label] for label in ("+x", "+y", "+z")}
CYCLES = 30
SEED = 9283


@dataclass(frozen=True)
class Truth:
    """What the data are made of; per-joint tuples in the order of :data:`JOINTS`.

    Attributes:
        stiffness_Nm_per_rad: joint stiffness k [N·m/rad] (the project's field notes).
        friction_torque_mean_Nm: mean friction torque tau [N·m] (estimates in the range identified on similar
            arms, not published UR5 values; at most 10 N·m, the range of tribokin's Gaussian law that draws it).
        friction_torque_std_Nm: its cycle-to-cycle standard deviation [N·m] (25 % of the mean).
        backlash_rad: backlash b [rad], half of it lost on each approach (small, assumed).
        joint_offset_std_rad: standard deviation of the per-pose joint offsets eps [rad] (assumed).
        noise_std_m: the instrument's noise per axis [m] (field notes).
        tracker_rpy_deg: rotation R of p_tracker = R p_base + t, fixed-axis x-y-z angles [deg]
            (R = Rz(yaw) Ry(pitch) Rx(roll)).
        tracker_translation_m: translation t [m].
    """

    stiffness_Nm_per_rad: tuple[float, ...] = (6.0e4, 3.5e4, 5.0e4, 1.2e4, 1.2e4, 1.0e4)
    friction_torque_mean_Nm: tuple[float, ...] = (1.6, 1.6, 1.2, 0.45, 0.45, 0.45)
    friction_torque_std_Nm: tuple[float, ...] = (0.4, 0.4, 0.3, 0.1125, 0.1125, 0.1125)
    backlash_rad: tuple[float, ...] = (2e-5, 2e-5, 2e-5, 3e-5, 3e-5, 3e-5)
    joint_offset_std_rad: float = 1e-4
    noise_std_m: float = 3e-6
    tracker_rpy_deg: tuple[float, float, float] = (3.0, -2.0, 130.0)
    tracker_translation_m: tuple[float, float, float] = (2.1, -0.7, 0.4)

    def tracker_rotation(self) -> np.ndarray:
        """(3, 3) rotation R taking base-frame vectors into the tracker frame."""
        return pin.rpy.rpyToMatrix(*np.radians(self.tracker_rpy_deg))


class Row(NamedTuple):
    """One measured cycle.

    Attributes:
        pose, cycle, direction: its labels.
        measured_m: (3,) measured tool point in the tracker frame [m].
        commanded_m: (3,) commanded tool point in the base frame [m].
        q: (6,) commanded configuration [rad].
        joint_offset_rad: (6,) the pose's joint offsets eps [rad].
        approach_signs: (6,) the joints' directions of travel s on its approach (+1, -1, 0).
    """

    pose: str
    cycle: int
    direction: str
    measured_m: np.ndarray
    commanded_m: np.ndarray
    q: np.ndarray
    joint_offset_rad: np.ndarray
    approach_signs: np.ndarray


def ur5() -> Robot:
    """example-robot-data's UR5 with tribokin's default tool frame."""
    return load_example_robot(ROBOT)


def cube_poses(robot: Robot) -> list[CubePose]:
    """P1-P5 of :data:`CUBE` on ``robot``."""
    return place_cube(robot, **CUBE)[0]


def simulate(truth: Truth, seed: int = SEED, cycles: int = CYCLES, poses: list[CubePose] | None = None) -> list[Row]:
    """The measured cycles, pose by pose, direction by direction (:data:`DIRECTIONS`), cycle by cycle.

    Random numbers from ``numpy.random.default_rng(seed)``, drawn in this order: per pose its joint offsets,
    then per direction the friction torques (joint by joint, ``cycles`` each) and the noise (cycles, 3).
    """
    robot = ur5()
    poses = cube_poses(robot) if poses is None else poses
    rng = np.random.default_rng(seed)
    stiffness = np.array(truth.stiffness_Nm_per_rad)
    half_backlash_rad = np.array(truth.backlash_rad) / 2
    laws = [Gaussian(mean, std)
            for mean, std in zip(truth.friction_torque_mean_Nm, truth.friction_torque_std_Nm, strict=True)]
    rotation, translation = truth.tracker_rotation(), np.array(truth.tracker_translation_m)
    rows = []
    for pose in poses:
        offset_rad = rng.normal(0.0, truth.joint_offset_std_rad, len(JOINTS))
        commanded_m = robot.tool_placement(pose.q).translation
        signs = held_approach_signs(robot, pose.q, list(DIRECTIONS.values()))
        for label, sign in zip(DIRECTIONS, signs, strict=True):
            torque_Nm = np.column_stack([law.rvs(cycles, rng) for law in laws])
            noise_m = rng.normal(0.0, truth.noise_std_m, (cycles, 3))
            for cycle in range(cycles):
                dq = offset_rad + sign * (torque_Nm[cycle] / stiffness + half_backlash_rad)
                base_m = robot.tool_placement(pose.q + dq).translation + noise_m[cycle]
                rows.append(Row(pose.name, cycle + 1, label, rotation @ base_m + translation, commanded_m, pose.q,
                                offset_rad, sign))
    return rows


def _numbers(values) -> str:
    """``[a, b, ...]`` with each float's ``repr``."""
    return f"[{', '.join(repr(float(v)) for v in values)}]"


def header(truth: Truth, seed: int, rows: list[Row]) -> list[str]:
    """The comment lines: provenance, model, true values and this seed's draws."""
    by_pose = {row.pose: row for row in rows}
    by_series = {(row.pose, row.direction): row for row in rows}
    units = {"stiffness_Nm_per_rad": "N*m/rad", "friction_torque_mean_Nm": "N*m", "friction_torque_std_Nm": "N*m",
             "backlash_rad": "rad", "joint_offset_std_rad": "rad", "noise_std_m": "m", "tracker_rpy_deg": "deg",
             "tracker_translation_m": "m"}
    values = {f.name: getattr(truth, f.name) for f in fields(truth)}
    truth_lines = [f"  {name} = {_numbers(v) if isinstance(v, tuple) else repr(float(v))}  [{units[name]}]"
                   for name, v in values.items()]
    versions = ", ".join(f"{k} {v}" for k, v in software_versions().items() if k != "python")
    return [
        "SYNTHETIC DATA, not measured: an ISO 9283 pose-repeatability test of a UR5 simulated from known",
        "parameters (the truth below) by tools/ur5_tracker_data.py (tribokin), to test calibration on.",
        f"Command: python tools/ur5_tracker_data.py --seed {seed} --out <this file>",
        f"Seed: {seed} (numpy.random.default_rng); {versions}.",
        f"Robot: example-robot-data '{ROBOT}', tool frame '{ur5().tool_frame}'; joints {', '.join(JOINTS)}.",
        f"Cube: tribokin.iso9283.cube.place_cube(robot, center_m={list(CUBE['center_m'])}, "
        f"side_m={CUBE['side_m']}, rpy_deg={list(CUBE['rpy_deg'])}): P1-P5, tool orientation held.",
        f"Series: {max(row.cycle for row in rows)} cycles per pose and direction; directions +x, +y, +z = approach "
        "along the base axes.",
        "Model, per cycle j and joint i: dq_ij = eps_i + s_ij * (tau_ij / k_i + b_i / 2); tool point =",
        "Pinocchio forward kinematics of q + dq, plus Gaussian noise (noise_std_m per axis), then",
        "p_tracker = R p_base + t, so p_base = R^T (p_tracker - t): a registration of the tracker frame",
        "to the base frame (tribokin's p_base = R_reg p_measured + t_reg) should find R_reg = R^T, t_reg = -R^T t.",
        "tau_ij: friction torque, Gaussian (mean, std) truncated at 0 (tribokin.tribology.laws.Gaussian), drawn",
        "anew every cycle; eps_i: joint offsets, Gaussian (0, joint_offset_std_rad), drawn once per pose (the",
        "geometric error: it moves the pose's barycentre, not its spread); s_ij: direction of travel of the joint",
        "on the approach (tribokin.iso9283.cube.held_approach_signs; 0: the joint does not move, no lost motion).",
        "Truth (per joint in the order above; k and noise from the project's field notes; tau: estimates in the",
        "range identified on similar arms, not published UR5 values; backlash and offsets: small, assumed):",
        *truth_lines,
        f"  R = {_numbers(truth.tracker_rotation().ravel())}  (row by row)",
        "Joint offsets eps drawn with this seed [rad]:",
        *(f"  {name}: {_numbers(row.joint_offset_rad)}" for name, row in by_pose.items()),
        "Approach signs s per pose and direction:",
        *(f"  {pose} {label}: {_numbers(row.approach_signs)}" for (pose, label), row in by_series.items()),
        "Columns: x_m, y_m, z_m = measured tool point in the TRACKER frame; cx_m, cy_m, cz_m = commanded tool",
        "point in the robot BASE frame (forward kinematics of q); q_<joint> = commanded configuration [rad].",
    ]


def render(truth: Truth, seed: int = SEED, poses: list[CubePose] | None = None) -> str:
    """The whole measurement file of ``truth`` and ``seed``; ``poses``: :func:`cube_poses` of :func:`ur5` if given
    (a caller writing many files solves them once)."""
    rows = simulate(truth, seed, poses=poses)
    body = [",".join(["pose", "cycle", "direction", "x_m", "y_m", "z_m", "cx_m", "cy_m", "cz_m",
                      *(f"q_{joint}" for joint in JOINTS)])]
    body += [",".join([row.pose, str(row.cycle), row.direction,
                       *(repr(float(v)) for v in (*row.measured_m, *row.commanded_m, *row.q))]) for row in rows]
    return "".join(f"# {line}\n" for line in header(truth, seed, rows)) + "\n".join(body) + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, required=True, help="the measurement CSV to write")
    parser.add_argument("--seed", type=int, default=SEED, help=f"random seed (default {SEED})")
    parser.add_argument("--force", action="store_true", help="replace --out if it exists")
    args = parser.parse_args(argv)
    try:
        check_out(args.out, args.force)
        write_atomically(args.out, render(Truth(), args.seed))
    except InputError as error:
        print(f"ur5_tracker_data: error: {error.one_line()}", file=sys.stderr)
        return 2
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
