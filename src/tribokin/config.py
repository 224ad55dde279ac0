"""Study files: validation of the mapping into a :class:`Study`.

Every key is checked here, before anything runs; a bad one raises an
:class:`~tribokin.errors.InputError` naming the file and the key. The keys,
their units and defaults are documented in the README.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

from tribokin.errors import InputError, closest_hint
from tribokin.joints import APPROACH_MODES


# -- value checks: each takes (value, source, key) and returns the clean value ----------------------------------

def _number(value, source, key) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(f"must be a number (got {value!r})", source, key)
    if not math.isfinite(value):
        raise InputError(f"must be finite (got {value})", source, key)
    return float(value)


def finite(value, source, key) -> float:
    return _number(value, source, key)


def non_negative(value, source, key) -> float:
    value = _number(value, source, key)
    if value < 0:
        raise InputError(f"must be >= 0 (got {value:g})", source, key)
    return value


def positive(value, source, key) -> float:
    value = _number(value, source, key)
    if value <= 0:
        raise InputError(f"must be > 0 (got {value:g})", source, key)
    return value


def positive_int(value, source, key) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise InputError(f"must be a whole number >= 1 (got {value!r})", source, key)
    return value


def seed_int(value, source, key) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise InputError(f"must be a whole number >= 0 (got {value!r})", source, key)
    return value


def text(value, source, key) -> str:
    if not isinstance(value, str) or not value.strip():
        raise InputError(f"must be a non-empty string (got {value!r})", source, key)
    return value


def one_of(*choices):
    def check(value, source, key) -> str:
        if value not in choices:
            hint = closest_hint(str(value), list(choices))
            raise InputError(f"must be one of {', '.join(choices)} (got {value!r}){hint}", source, key)
        return value
    return check


def table(value, source, key) -> dict:
    if not isinstance(value, dict):
        raise InputError(f"must be a table (got {value!r})", source, key)
    return value


def number_list(value, source, key) -> list[float]:
    if not isinstance(value, list) or not value:
        raise InputError(f"must be a non-empty list of numbers (got {value!r})", source, key)
    return [_number(v, source, f"{key}[{i}]") for i, v in enumerate(value)]


def string_list(value, source, key) -> list[str]:
    if not isinstance(value, list):
        raise InputError(f"must be a list of strings (got {value!r})", source, key)
    return [text(v, source, f"{key}[{i}]") for i, v in enumerate(value)]


# -- schema: key -> (check, default); REQUIRED marks keys without a default -------------------------------------

REQUIRED = object()

STUDY_KEYS = {
    "name": (text, None),
    "cycles": (positive_int, 30),
    "seed": (seed_int, 0),
    "approach": (one_of(*APPROACH_MODES), "unidirectional"),
    "engine": (one_of("fast", "exact"), "fast"),
}
ROBOT_KEYS = {
    "urdf": (text, None),
    "name": (text, None),
    "tool_frame": (text, None),
    "package_dirs": (string_list, []),
    "payload_kg": (non_negative, 0.0),
}
JOINT_KEYS = {
    "friction": (table, None),
    "normal_force_N": (non_negative, None),
    "stiffness": (positive, None),
    "friction_radius_m": (positive, 0.02),
    "backlash": (non_negative, 0.0),
    "offset": (finite, 0.0),
    "noise_std": (non_negative, 0.0),
    "bearing_span_m": (positive, 0.1),
}
def vector3(value, source, key) -> list[float]:
    values = number_list(value, source, key)
    if len(values) != 3:
        raise InputError(f"needs 3 numbers (got {len(values)})", source, key)
    return values


ISO_CUBE_KEYS = {
    "center_m": (vector3, None),
    "side_m": (positive, None),
    "rpy_deg": (vector3, None),
}
POSE_KEYS = {
    "name": (text, None),
    "q": (number_list, REQUIRED),
    "normal_force_N": (non_negative, None),
    "friction": (table, None),
}
TOP_KEYS = ("study", "robot", "joints", "poses", "iso_cube")


def check_table(mapping: dict, schema: dict, source, prefix: str, extra_ok=()) -> dict:
    """Validate ``mapping`` against ``schema``; return every key with its value or default.

    Keys in ``extra_ok`` are left for the caller; any other unknown key is an error.
    """
    for key in mapping:
        if key not in schema and key not in extra_ok:
            valid = list(schema) + list(extra_ok)
            raise InputError(f"unknown key '{key}'{closest_hint(key, valid)}; valid keys: {', '.join(valid)}",
                             source, f"{prefix}.{key}")
    clean = {}
    for key, (check, default) in schema.items():
        if key in mapping:
            clean[key] = check(mapping[key], source, f"{prefix}.{key}")
        elif default is REQUIRED:
            raise InputError("missing: this key is required", source, f"{prefix}.{key}")
        else:
            clean[key] = default
    return clean


@dataclass
class PoseSpec:
    """A commanded configuration to test.

    ``q`` in [m or rad], one value per active joint; ``normal_force_N`` [N] and
    ``friction`` (a law spec), when set, apply to every joint at this pose (overriding ``[joints]``).
    """

    name: str
    q: list[float]
    normal_force_N: float | None = None
    friction: dict | None = None


@dataclass
class Study:
    """A validated study: what to load, how joints err, where to test.

    ``joints`` holds the defaults for every joint; ``joint_overrides`` the
    per-joint tables ``[joints.<name>]``, checked against the robot's joint
    names when it is loaded. ``source`` is the file (for messages) and
    ``base_dir`` what relative paths in it are resolved against.
    """

    name: str
    cycles: int
    seed: int
    approach: str
    robot: dict
    joints: dict
    joint_overrides: dict[str, dict]
    poses: list[PoseSpec]
    iso_cube: dict | None
    engine: str
    source: str
    base_dir: Path
    mapping: dict = field(repr=False, default_factory=dict)


def parse_study(mapping: dict, source: str = "<mapping>", base_dir: Path = Path(".")) -> Study:
    """Validate a study mapping (as read from TOML) into a :class:`Study`."""
    table(mapping, source, "study file")
    for key in mapping:
        if key not in TOP_KEYS:
            raise InputError(f"unknown section [{key}]{closest_hint(key, TOP_KEYS)}; valid sections: "
                             f"{', '.join(TOP_KEYS)}", source, key)
    for required in ("robot", "joints"):
        if required not in mapping:
            raise InputError(f"missing [{required}] section", source, required)
    if "poses" not in mapping and "iso_cube" not in mapping:
        raise InputError("nothing to test: add [[poses]] entries or an [iso_cube] section", source, "poses")
    study = check_table(table(mapping.get("study", {}), source, "study"), STUDY_KEYS, source, "study")
    robot = check_table(table(mapping["robot"], source, "robot"), ROBOT_KEYS, source, "robot")
    if (robot["urdf"] is None) == (robot["name"] is None):
        raise InputError("give exactly one of urdf = \"path/to/robot.urdf\" or name = \"ur5\"", source, "robot")
    joints_table = table(mapping["joints"], source, "joints")
    overrides = {k: v for k, v in joints_table.items() if k not in JOINT_KEYS and isinstance(v, dict)}
    joints = check_table(joints_table, JOINT_KEYS, source, "joints", extra_ok=tuple(overrides))
    joint_overrides = {}
    for joint, values in overrides.items():
        checked = check_table(values, {k: (c, None) for k, (c, _) in JOINT_KEYS.items()}, source, f"joints.{joint}")
        joint_overrides[joint] = {k: v for k, v in checked.items() if k in values}
    iso_cube = None
    if "iso_cube" in mapping:
        iso_cube = check_table(table(mapping["iso_cube"], source, "iso_cube"), ISO_CUBE_KEYS, source, "iso_cube")
    poses_list = mapping.get("poses", [])
    if not isinstance(poses_list, list) or (not poses_list and iso_cube is None):
        raise InputError("needs at least one [[poses]] entry with q = [...]", source, "poses")
    poses = []
    for i, pose in enumerate(poses_list):
        checked = check_table(table(pose, source, f"poses[{i}]"), POSE_KEYS, source, f"poses[{i}]")
        poses.append(PoseSpec(checked["name"] or f"P{i + 1}", checked["q"], checked["normal_force_N"],
                              checked["friction"]))
    names = [p.name for p in poses] + (["P1", "P2", "P3", "P4", "P5"] if iso_cube is not None else [])
    duplicate = next((n for n in names if names.count(n) > 1), None)
    if duplicate:
        raise InputError(f"pose name '{duplicate}' is used twice; names must be unique", source, "poses.name")
    return Study(
        name=study["name"] or Path(source).stem,
        cycles=study["cycles"],
        seed=study["seed"],
        approach=study["approach"],
        robot=robot,
        joints=joints,
        joint_overrides=joint_overrides,
        poses=poses,
        iso_cube=iso_cube,
        engine=study["engine"],
        source=source,
        base_dir=Path(base_dir),
        mapping=mapping,
    )
