"""Study files: validation of the mapping into a frozen :class:`Study` of frozen specs.

Every key is checked here, before anything runs; a bad one raises an :class:`~tribokin.errors.InputError` naming the
file and the key. The keys, their units and defaults are documented in docs/reference/study-file.md
(tools/study_reference.py). Overrides (the command line's ``cycles`` and ``seed``, scenarios) make new specs with
:func:`dataclasses.replace`.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, replace
from functools import partial
from pathlib import Path

from tribokin.checks import (
    boolean,
    distinct_strings,
    finite,
    non_negative,
    number_list,
    one_of,
    positive,
    positive_int,
    seed_int,
    string_list,
    table,
    text,
    whole_number,
    within,
)
from tribokin.errors import InputError, closest_hint
from tribokin.iso9283.cube import known_approach
from tribokin.kinematics.urdf_xacro import XACRO_SUFFIX, is_xacro
from tribokin.simulation.joint_errors import APPROACH_MODES
from tribokin.study.map_spec import MAP_SPECS, STATISTICS, MapSpec
from tribokin.study.placement_spec import OBJECTIVES, PlacementSpec
from tribokin.study.schema import REQUIRED, check_table
from tribokin.study.series_spec import (
    MAX_WARM_UP_CYCLES,
    cycle_time,
    friction_series,
    friction_state,
    law_and_time_keys,
    travel,
    without_time_keys,
)
from tribokin.tribology.friction_series import FrictionSeries
from tribokin.tribology.laws import coefficient

# -- ranges: physically meaningful bounds, each with the reason a value outside is refused ---------------------

cycle_count = within(whole_number, 2, 10 ** 15, "cycles", "ISO 9283 needs at least 2 (S_l divides by n - 1); "
                     "1e15 cycles at one a second would take 30 million years")
grid_count = within(positive_int, 1, 10 ** 7, "", "ten million points along one axis are 0.1 µm apart over a "
                    "metre, far finer than any figure varies")
payload = within(non_negative, 0.0, 1e4, "kg", "the heaviest industrial robots carry about 2.3 t")
normal_force = within(non_negative, 0.0, 1e7, "N", "1e7 N (1000 t) is beyond what any joint's bearing carries")
stiffness = within(positive, 1e-3, 1e12, "N/m or N·m/rad", "below, a newton of friction would move a joint a "
                   "kilometre; above, stiffer than any drive (for a rigid joint, set its friction to 0)")
chunk_count = within(positive_int, 1, 10 ** 7, "rows", "a chunk is held in memory, and ten million rows outgrow it")
friction_radius = within(positive, 1e-4, 10.0, "m", "bearing raceways run from 0.1 mm to the few metres of the "
                         "largest slewing rings")
_drive_fault = "m or rad", "more than 0.1 m or 0.1 rad (5.7°) is a broken drive, not an imprecise one"
backlash = within(non_negative, 0.0, 0.1, *_drive_fault)
offset = within(finite, -0.1, 0.1, *_drive_fault)
noise_std = within(non_negative, 0.0, 0.1, *_drive_fault)
friction_torque = within(non_negative, 0.0, 1e4, "N·m", "the largest robots' joints lose less than 10 kN·m to "
                         "friction")
friction_force = within(non_negative, 0.0, 1e5, "N", "a linear axis' guides lose less than 100 kN (10 t) to friction")
bearing_span = within(positive, 1e-3, 10.0, "m", "a joint's guide pads or bearings sit between 1 mm and a few "
                      "metres apart")
side = within(positive, 1e-3, 100.0, "m", "ISO 9283's cube spans the most-used part of a workspace; below 1 mm its "
              "poses are hardly distinct places")
coordinate = within(finite, -1e3, 1e3, "m", "no robot reaches a kilometre")
tool_reach = within(finite, -10.0, 10.0, "m", "the longest tools (welding lances, gantry grippers) reach a few "
                    "metres from the flange")
joint_value = within(finite, -1e3, 1e3, "m or rad", "no joint travels a kilometre or turns 160 times")
angle_deg = within(finite, -360.0, 360.0, "deg", "write each angle within one turn either way")


# -- schema: key -> (check, default); REQUIRED marks keys without a default (study.schema) ----------------------

STUDY_KEYS = {
    "name": (text, None),
    "cycles": (cycle_count, 30),
    "seed": (seed_int, 0),
    "approach": (one_of(*APPROACH_MODES), "unidirectional"),
    "engine": (one_of("fast", "exact"), "fast"),
    "data_dirs": (string_list, []),
    "cycle_time_s": (cycle_time, None),
}


def law_of(bound):
    """A ``{ law = ..., ... }`` table whose every number (and every one of its ``values``) passes ``bound``."""
    def check(value, source, key) -> dict:
        table(value, source, key)
        for name, number in value.items():
            if name == "values" and isinstance(number, list):
                for i, element in enumerate(number):
                    bound(element, source, f"{key}.values[{i}]")
            elif name != "law":
                bound(number, source, f"{key}.{name}")
        return value
    return check


#: The keys that give a joint's friction, one per joint: a law of mu, of the friction torque [N·m] of a revolute
#: joint or of the friction force [N] of a prismatic one.
FRICTION_KEYS = ("friction", "friction_torque_Nm", "friction_force_N")
#: Torque and force laws are held as these powers of two (exact) times a law of values within mu's range.
FRICTION_SCALE = {"friction_torque_Nm": 2 ** 10, "friction_force_N": 2 ** 14}
JOINT_KEYS = {
    "friction": (law_and_time_keys(table, coefficient), None),
    "friction_torque_Nm": (law_and_time_keys(law_of(friction_torque), friction_torque), None),
    "friction_force_N": (law_and_time_keys(law_of(friction_force), friction_force), None),
    "normal_force_N": (normal_force, None),
    "stiffness": (stiffness, None),
    "friction_radius_m": (friction_radius, 0.02),
    "backlash": (backlash, 0.0),
    "offset": (offset, 0.0),
    "noise_std": (noise_std, 0.0),
    "bearing_span_m": (bearing_span, 0.1),
    "travel_per_cycle": (travel, None),
}
def vector3(value, source, key, element=finite) -> list[float]:
    values = number_list(value, source, key, element)
    if len(values) != 3:
        raise InputError(f"needs 3 numbers (got {len(values)})", source, key)
    return values


def unit_vector3(value, source, key) -> list[float]:
    values = vector3(value, source, key)
    norm = math.sqrt(sum(v * v for v in values))
    if abs(norm - 1) > 1e-6:
        raise InputError(f"must be a unit vector (its norm is {norm:g}); divide it by its norm", source, key)
    return values


def interval(value, source, key, element=finite) -> list[float]:
    values = number_list(value, source, key, element)
    if len(values) != 2 or values[0] > values[1]:
        raise InputError(f"must be [low, high] with low <= high (got {value!r})", source, key)
    return values


def interval_list(value, source, key, element=finite) -> list[list[float]]:
    if not isinstance(value, list) or not value:
        raise InputError(f"must be a list of [low, high] pairs (got {value!r})", source, key)
    return [interval(v, source, f"{key}[{i}]", element) for i, v in enumerate(value)]


def count_list(value, source, key) -> list[int]:
    if not isinstance(value, list) or not value:
        raise InputError(f"must be a list of whole numbers >= 1 (got {value!r})", source, key)
    return [grid_count(v, source, f"{key}[{i}]") for i, v in enumerate(value)]


position3 = partial(vector3, element=coordinate)
angles3 = partial(vector3, element=angle_deg)


def xacro_arguments(value, source, key) -> dict[str, str]:
    """A table of a xacro's arguments by name, each a string (xacro substitutes text; it may be empty)."""
    for name, argument in table(value, source, key).items():
        if not isinstance(argument, str):
            quoted = str(argument).lower() if isinstance(argument, bool) else argument
            raise InputError(f"must be a string, as xacro substitutes text (got {argument!r}); write {name} = "
                             f"\"{quoted}\"", source, f"{key}.{name}")
    return dict(value)


ROBOT_KEYS = {
    "urdf": (text, None),
    "name": (text, None),
    "tool_frame": (text, None),
    "package_dirs": (string_list, []),
    "payload_kg": (payload, 0.0),
    "tool_offset_m": (partial(vector3, element=tool_reach), None),
    "tool_offset_rpy_deg": (angles3, None),
    "xacro_args": (xacro_arguments, None),
    "base_xyz_m": (position3, None),
    "base_rpy_deg": (angles3, None),
}

#: The names of the ISO cube's poses (:func:`~tribokin.iso9283.metrics.cube_test_positions`).
ISO_CUBE_POSES = ("P1", "P2", "P3", "P4", "P5")
ISO_CUBE_KEYS = {
    "center_m": (position3, None),
    "side_m": (side, None),
    "rpy_deg": (angles3, None),
}
def approach_labels(value, source, key) -> list[str]:
    """A non-empty list of distinct approach labels: ``+`` or ``-`` (every joint forwards or backwards), ``+x``,
    ``-y``, ... or a direction as three signed numbers (``+0.58+0.58+0.58``)."""
    labels = distinct_strings(value, source, key, "name at least one approach direction")
    for i, label in enumerate(labels):
        if not known_approach(label):
            raise InputError(f"'{label}' names no approach: write +, -, +x, -y, ... or a direction as three signed "
                             "numbers such as +0.58+0.58+0.58", source, f"{key}[{i}]")
    return labels


POSE_KEYS = {
    "name": (text, None),
    "q": (partial(number_list, element=joint_value), REQUIRED),
    "normal_force_N": (normal_force, None),
    "friction": (without_time_keys, None),
    "directions": (approach_labels, None),
}
MAP_KINDS = {
    "plane": {
        "origin_m": (position3, REQUIRED),
        "axis_u": (unit_vector3, REQUIRED),
        "axis_v": (unit_vector3, REQUIRED),
        "extent_u_m": (partial(interval, element=coordinate), REQUIRED),
        "extent_v_m": (partial(interval, element=coordinate), REQUIRED),
        "resolution": (count_list, REQUIRED),
        "rpy_deg": (angles3, None),
    },
    "box": {
        "min_m": (position3, REQUIRED),
        "max_m": (position3, REQUIRED),
        "resolution": (count_list, REQUIRED),
        "rpy_deg": (angles3, None),
    },
    "joint": {
        "joints": (string_list, REQUIRED),
        "ranges": (partial(interval_list, element=joint_value), REQUIRED),
        "counts": (count_list, REQUIRED),
    },
}
MAP_COMMON_KEYS = {
    "kind": (one_of(*MAP_KINDS), REQUIRED),
    "start_q": (partial(number_list, element=joint_value), None),
    "chunk_rows": (chunk_count, None),
    "statistic": (one_of(*STATISTICS), "expected"),
    "directional": (boolean, None),  # None: an expected map's default, on (check_map)
    "state": (friction_state, None),
    "compare": (friction_state, None),
}
#: What ``[calibration]`` may free (``fit``), and the instrument's noise floor range.
CALIBRATION_PARAMETERS = ("stiffness", "backlash", "noise_floor")
instrument_noise = within(positive, 1e-9, 1e-2, "m", "below a nanometre no instrument measures a robot; above a "
                          "centimetre it measures nothing about its repeatability")


def fitted_parameters(value, source, key) -> tuple[str, ...]:
    """A non-empty list of distinct :data:`CALIBRATION_PARAMETERS`."""
    names = distinct_strings(value, source, key, f"name at least one of {', '.join(CALIBRATION_PARAMETERS)}")
    for i, name in enumerate(names):
        one_of(*CALIBRATION_PARAMETERS)(name, source, f"{key}[{i}]")
    return tuple(names)


def joint_selection(value, source, key) -> str | tuple[str, ...]:
    """``"all"`` or a non-empty list of distinct joint names (checked against the robot when it is loaded)."""
    if value == "all":
        return value
    if not isinstance(value, list):
        raise InputError(f'must be "all" or a list of joint names (got {value!r})', source, key)
    return tuple(distinct_strings(value, source, key, 'must be "all" or a list of joint names (got [])'))


CALIBRATION_KEYS = {
    "fit": (fitted_parameters, REQUIRED),
    "joints": (joint_selection, "all"),
    "tie": (one_of("none", "all"), "none"),
    "noise_floor_m": (instrument_noise, None),
    "tool_rpy_deg": (angles3, None),
}
#: Study sections a scenario may override (the map, hence the targets, stays the same).
SCENARIO_SECTIONS = ("study", "robot", "joints")
candidate_count = within(positive_int, 1, 10 ** 4, "candidates (positions × yaw_deg values)",
                          "each candidate runs the whole [map]; ten thousand take hours: search coarsely, then finer "
                          "around the best")
fraction = within(finite, 0.0, 1.0, "", "a fraction of the task's targets")


def distinct(check, key=None, what: str = ""):
    """A non-empty list whose elements pass ``check`` and are all different (a candidate named twice), compared by
    ``key(element)`` when given (a yaw modulo 360°); ``what`` says what a repeat that is not the same value is
    (``{other}``: the earlier one)."""
    def checked(value, source, name) -> list:
        if not isinstance(value, list) or not value:
            raise InputError(f"must be a non-empty list (got {value!r})", source, name)
        values = [check(v, source, f"{name}[{i}]") for i, v in enumerate(value)]
        seen = [v if key is None else key(v) for v in values]
        twice = next((i for i, v in enumerate(seen) if v in seen[:i]), None)
        if twice is not None:
            first = seen.index(seen[twice])
            repeat = "given twice" if values[first] == values[twice] else what.format(other=f"{name}[{first}]")
            raise InputError(f"{value[twice]!r} is {repeat}; give each once", source, f"{name}[{twice}]")
        return values
    return checked


PLACEMENT_KEYS = {
    "candidates": (distinct(position3), None),
    "base_xyz_m_min": (position3, None),
    "base_xyz_m_max": (position3, None),
    "resolution": (count_list, None),
    "yaw_deg": (distinct(angle_deg, key=lambda yaw: yaw % 360.0, what="the same yaw as {other} (modulo 360°)"),
                [0.0]),
    "objective": (one_of(*OBJECTIVES), "p95"),
    "min_reachable": (fraction, 1.0),
}
#: The keys of a box of base positions, all given or none.
PLACEMENT_BOX_KEYS = ("base_xyz_m_min", "base_xyz_m_max", "resolution")
#: The ``[robot]`` keys that name the robot itself: a scenario giving ``urdf`` or ``name`` takes none of them from
#: the study's ``[robot]`` (another robot's frames, folders and arguments are its own); it keeps the others.
ROBOT_IDENTITY_KEYS = ("urdf", "name", "xacro_args", "package_dirs", "tool_frame")
TOP_KEYS = ("study", "robot", "joints", "poses", "iso_cube", "map", "scenarios", "calibration", "placement", "drift")
#: ``[drift]``: ISO 9283's drift test at the study's poses, simulated (:class:`DriftSpec`).
DRIFT_KEYS = {
    "duration_s": (within(positive, 1.0, 1e7, "s", "a drift test lasts from seconds to ISO's 8 hours, not four "
                          "months"), REQUIRED),
    "set_cycles": (cycle_count, None),
    "start": (one_of("cold", "warm"), "cold"),
}


def _frozen(values):
    """Lists (of lists) as tuples, for a frozen spec; any other value as it is."""
    return tuple(_frozen(v) for v in values) if isinstance(values, list) else values


def _spec(cls, checked: dict):
    """A ``cls`` spec of a checked table (:func:`check_table`), its lists as tuples."""
    return cls(**{key: _frozen(value) for key, value in checked.items()})


@dataclass(frozen=True)
class RobotSpec:
    """The ``[robot]`` table: a ``urdf`` file (its meshes under ``package_dirs``) or an example-robot-data ``name``, the
    ``tool_frame`` (``None``: the end of the longest chain, :mod:`tribokin.kinematics.tool_frames`), the ``payload_kg``
    [kg] and the tool point's offset in the tool frame, ``tool_offset_m`` [m] and ``tool_offset_rpy_deg`` (roll, pitch,
    yaw) [deg] (``None``: zero; both ``None``: no tool point; :func:`~tribokin.kinematics.robot.rigid_placement`),
    and the arguments of a ``.xacro`` ``urdf`` by name, ``xacro_args`` (strings; ``None``: none given), and the base's
    placement in the world, ``base_xyz_m`` [m] and ``base_rpy_deg`` [deg] (``None``: zero; both ``None``: the world is
    the base frame). The offsets, arguments and base default to ``None`` so that a ``summary.json`` written without
    them still gives its spec."""

    urdf: str | None
    name: str | None
    tool_frame: str | None
    package_dirs: tuple[str, ...]
    payload_kg: float
    tool_offset_m: tuple[float, float, float] | None = None
    tool_offset_rpy_deg: tuple[float, float, float] | None = None
    xacro_args: dict[str, str] | None = None
    base_xyz_m: tuple[float, float, float] | None = None
    base_rpy_deg: tuple[float, float, float] | None = None

    def absolute(self, base_dir: Path) -> RobotSpec:
        """The spec with its paths made absolute against ``base_dir``: it loads the same robot from any folder."""
        urdf = None if self.urdf is None else str((base_dir / self.urdf).absolute())
        return replace(self, urdf=urdf, package_dirs=tuple(str((base_dir / p).absolute()) for p in self.package_dirs))

    def as_settings(self) -> dict:
        """The spec as ``summary.json`` records it (``robot_spec``): tuples as lists, the offsets, the xacro's
        arguments and the base only when set."""
        return {key: list(value) if isinstance(value, tuple) else value for key, value in asdict(self).items()
                if value is not None or not key.startswith(("tool_offset", "xacro_args", "base_"))}


@dataclass(frozen=True)
class JointSpec:
    """One joint's keys of ``[joints]`` (see :class:`~tribokin.simulation.joint_errors.JointErrorModel`):
    its friction as one of ``friction`` (a law's table of mu), ``friction_torque_Nm`` (of the torque [N·m], revolute)
    or ``friction_force_N`` (of the force [N], prismatic), ``normal_force_N`` [N], ``stiffness`` [N/m or N·m/rad],
    ``friction_radius_m`` [m], ``backlash``, ``offset``, ``noise_std`` [m or rad], ``bearing_span_m`` [m],
    ``travel_per_cycle`` [m or rad] (what ``thermal`` heats by); ``None`` where not set. The friction's table holds
    its law and its time keys (:attr:`series`)."""

    friction: dict | None
    friction_torque_Nm: dict | None
    friction_force_N: dict | None
    normal_force_N: float | None
    stiffness: float | None
    friction_radius_m: float
    backlash: float
    offset: float
    noise_std: float
    bearing_span_m: float
    travel_per_cycle: float | None = None

    @property
    def friction_key(self) -> str | None:
        """Which of ``FRICTION_KEYS`` gives the joint's friction (``None``: none does)."""
        return next((key for key in FRICTION_KEYS if getattr(self, key) is not None), None)

    @property
    def series(self) -> FrictionSeries | None:
        """The time keys of the joint's friction as a :class:`FrictionSeries` (``None``: none given)."""
        key = self.friction_key
        return None if key is None else friction_series(getattr(self, key))


@dataclass(frozen=True)
class PoseSpec:
    """A commanded configuration to test.

    ``q`` in [m or rad], one value per active joint; ``normal_force_N`` [N] and
    ``friction`` (a law spec), when set, apply to every joint at this pose (overriding ``[joints]``);
    ``directions``: its approach labels (:func:`approach_labels`), each tested as a unidirectional series whatever
    the study's ``approach``, or ``None``: joint space, ``+`` (and ``-`` when the approach is not unidirectional).
    """

    name: str
    q: tuple[float, ...]
    normal_force_N: float | None
    friction: dict | None
    directions: tuple[str, ...] | None = None


@dataclass(frozen=True)
class IsoCubeSpec:
    """The ``[iso_cube]`` table: centre [m], side [m] and tool orientation (roll, pitch, yaw) [deg]; ``None``:
    chosen (:func:`~tribokin.iso9283.cube.place_cube`)."""

    center_m: tuple[float, float, float] | None
    side_m: float | None
    rpy_deg: tuple[float, float, float] | None


@dataclass(frozen=True)
class DriftSpec:
    """``[drift]``: ISO 9283's drift test at each of the study's poses and approach directions, simulated: the pose
    approached every ``study.cycle_time_s`` for ``duration_s`` [s], its first and last ``set_cycles`` cycles (``None``:
    the study's ``cycles``) measured; ``start``: ``"cold"`` (every joint at ambient) or ``"warm"`` (each joint with a
    ``thermal`` at the temperature its mean friction power settles it at)."""

    duration_s: float
    set_cycles: int | None
    start: str


@dataclass(frozen=True)
class CalibrationSpec:
    """The ``[calibration]`` table of ``tribokin calibrate``: what to fit (``fit``: of ``"stiffness"``,
    ``"backlash"``, ``"noise_floor"``), for which ``joints`` (``"all"`` or names), ``tie`` (``"all"``: one common
    stiffness factor for the fitted joints), the instrument's ``noise_floor_m`` [m] (its value when not fitted, the
    start when fitted; ``None``: not given), and ``tool_rpy_deg`` [deg], the tool's orientation (roll, pitch, yaw in
    the world frame) for solving configurations from commanded positions (``None``: position only)."""

    fit: tuple[str, ...]
    joints: str | tuple[str, ...]
    tie: str
    noise_floor_m: float | None
    tool_rpy_deg: tuple[float, float, float] | None


@dataclass(frozen=True)
class ScenarioSpec:
    """A what-if variant of a study's map: ``overrides`` (nested tables, as in the file) applied
    to the study, validated into ``study``."""

    name: str
    overrides: dict
    study: Study


@dataclass(frozen=True)
class Study:
    """A validated study: what to load, how joints err, where to test.

    ``joints`` holds the defaults for every joint; ``joint_overrides`` the keys each
    ``[joints.<name>]`` table sets, checked against the robot's joint names when it is loaded.
    ``source`` is the file (for messages) and ``base_dir`` what relative paths in it are resolved
    against; ``mapping`` the table it was parsed from (a map's chunk store is recognised by it).
    ``sha256`` is the hash of the file's bytes (``None`` for a study given as a mapping).
    """

    name: str
    cycles: int
    seed: int
    approach: str
    robot: RobotSpec
    joints: JointSpec
    joint_overrides: dict[str, dict]
    poses: tuple[PoseSpec, ...]
    iso_cube: IsoCubeSpec | None
    engine: str
    source: str
    base_dir: Path
    mapping: dict = field(repr=False, default_factory=dict)
    map: MapSpec | None = None
    scenarios: tuple[ScenarioSpec, ...] = ()
    sha256: str | None = None
    calibration: CalibrationSpec | None = None
    placement: PlacementSpec | None = None
    data_dirs: tuple[str, ...] = ()
    cycle_time_s: float | None = None
    drift: DriftSpec | None = None

    @property
    def has_tests(self) -> bool:
        """The study names something to run: poses, an ISO cube or a map."""
        return bool(self.poses) or self.iso_cube is not None or self.map is not None

    @property
    def data_roots(self) -> tuple[Path, ...]:
        """The folders the files it names (law files, logs, surface profiles) must lie in: its own folder, then its
        ``study.data_dirs`` (relative to its folder)."""
        return (self.base_dir, *(self.base_dir / folder for folder in self.data_dirs))

    @property
    def payload_kg(self) -> float:
        """The robot's payload [kg]."""
        return self.robot.payload_kg

    def joint(self, name: str) -> JointSpec:
        """Joint ``name``'s keys: the ``[joints]`` defaults with its ``[joints.<name>]`` overrides; a friction its
        own table gives (any of ``FRICTION_KEYS``) replaces whichever the defaults give."""
        overrides = self.joint_overrides.get(name, {})
        if overrides.keys() & set(FRICTION_KEYS):
            overrides = {**dict.fromkeys(FRICTION_KEYS), **overrides}
        return replace(self.joints, **overrides)

    def joint_key(self, name: str, part: str) -> str:
        """The study key that sets ``part`` (``"stiffness"``...) of joint ``name``: in its own table, else in
        ``[joints]``."""
        return f"joints.{name}.{part}" if part in self.joint_overrides.get(name, {}) else f"joints.{part}"


def _one_friction(values: dict, source, prefix: str) -> None:
    """Refuse a table that gives a joint's friction twice (two of ``FRICTION_KEYS``)."""
    given = [k for k in FRICTION_KEYS if values.get(k) is not None]
    if len(given) > 1:
        raise InputError(f"give one of {', '.join(FRICTION_KEYS)}, not {' and '.join(given)}", source,
                         f"{prefix}.{given[1]}")


def parse_study(mapping: dict, source: str = "<mapping>", base_dir: Path = Path("."), scenario: bool = False) -> Study:
    """Validate a study mapping (as read from TOML) into a :class:`Study`."""
    table(mapping, source, "study file")
    for key in mapping:
        if key not in TOP_KEYS:
            raise InputError(f"unknown section [{key}]{closest_hint(key, TOP_KEYS)}; valid sections: "
                             f"{', '.join(TOP_KEYS)}", source, key)
    for required in ("robot", "joints"):
        if required not in mapping:
            raise InputError(f"missing [{required}] section", source, required)
    if not {"poses", "iso_cube", "map", "calibration", "placement"} & set(mapping):
        raise InputError("nothing to test: add [[poses]] entries, an [iso_cube] or a [map] section", source, "poses")
    study = check_table(table(mapping.get("study", {}), source, "study"), STUDY_KEYS, source, "study")
    robot = check_table(table(mapping["robot"], source, "robot"), ROBOT_KEYS, source, "robot")
    if (robot["urdf"] is None) == (robot["name"] is None):
        raise InputError("give exactly one of urdf = \"path/to/robot.urdf\" or name = \"ur5\"", source, "robot")
    if robot["xacro_args"] is not None and (robot["urdf"] is None or not is_xacro(robot["urdf"])):
        given = f"robot.urdf is '{robot['urdf']}'" if robot["urdf"] else f"robot.name is '{robot['name']}'"
        raise InputError(f"only a xacro file (robot.urdf ending {XACRO_SUFFIX}) takes arguments, and {given}; remove "
                         "robot.xacro_args", source, "robot.xacro_args")
    joints_table = table(mapping["joints"], source, "joints")
    overrides = {k: v for k, v in joints_table.items() if k not in JOINT_KEYS and isinstance(v, dict)}
    joints = check_table(joints_table, JOINT_KEYS, source, "joints", extra_ok=tuple(overrides))
    _one_friction(joints, source, "joints")
    joint_overrides = {}
    for joint, values in overrides.items():
        checked = check_table(values, {k: (c, None) for k, (c, _) in JOINT_KEYS.items()}, source, f"joints.{joint}")
        joint_overrides[joint] = {k: v for k, v in checked.items() if k in values}
        _one_friction(joint_overrides[joint], source, f"joints.{joint}")
    iso_cube = None
    if "iso_cube" in mapping:
        cube = check_table(table(mapping["iso_cube"], source, "iso_cube"), ISO_CUBE_KEYS, source, "iso_cube")
        iso_cube = _spec(IsoCubeSpec, cube)
    map_spec = check_map(table(mapping["map"], source, "map"), source) if "map" in mapping else None
    placement = check_placement(mapping, map_spec, source) if "placement" in mapping else None
    calibration = None
    if "calibration" in mapping:
        checked = check_table(table(mapping["calibration"], source, "calibration"), CALIBRATION_KEYS, source,
                              "calibration")
        if "noise_floor" not in checked["fit"] and checked["noise_floor_m"] is None:
            raise InputError("the instrument's noise floor is neither fitted nor given: add \"noise_floor\" to "
                             "calibration.fit or set calibration.noise_floor_m [m]",
                             source, "calibration.noise_floor_m")
        calibration = _spec(CalibrationSpec, checked)
    poses_list = mapping.get("poses", [])
    if not isinstance(poses_list, list) or (not poses_list and iso_cube is None and map_spec is None
                                            and calibration is None):
        raise InputError("needs at least one [[poses]] entry with q = [...]", source, "poses")
    poses = []
    for i, pose in enumerate(poses_list):
        checked = check_table(table(pose, source, f"poses[{i}]"), POSE_KEYS, source, f"poses[{i}]")
        poses.append(PoseSpec(checked["name"] or f"P{i + 1}", _frozen(checked["q"]), checked["normal_force_N"],
                              checked["friction"], _frozen(checked["directions"])))
    names = [p.name for p in poses] + (list(ISO_CUBE_POSES) if iso_cube is not None else [])
    duplicate = next((n for n in names if names.count(n) > 1), None)
    if duplicate:
        raise InputError(f"pose name '{duplicate}' is used twice; names must be unique", source, "poses.name")
    if "scenarios" in mapping and map_spec is None:
        raise InputError("scenarios compare maps: add a [map] section", source, "scenarios")
    drift = None
    if "drift" in mapping:
        drift = _spec(DriftSpec, check_table(table(mapping["drift"], source, "drift"), DRIFT_KEYS, source, "drift"))
        check_drift(drift, study["cycles"], study["cycle_time_s"], bool(poses) or iso_cube is not None, source)
    parsed = Study(
        name=study["name"] or Path(source).stem,
        cycles=study["cycles"],
        seed=study["seed"],
        approach=study["approach"],
        robot=_spec(RobotSpec, robot),
        joints=JointSpec(**joints),
        joint_overrides=joint_overrides,
        poses=tuple(poses),
        iso_cube=iso_cube,
        engine=study["engine"],
        source=source,
        base_dir=Path(base_dir),
        mapping=mapping,
        map=map_spec,
        scenarios=parse_scenarios(mapping, source, base_dir),
        calibration=calibration,
        placement=placement,
        data_dirs=_frozen(study["data_dirs"]),
        cycle_time_s=study["cycle_time_s"],
        drift=drift,
    )
    check_motion(parsed, list(joint_overrides) or [None])  # a robot's every joint: study.assembly.joint_models
    if map_spec is not None and not scenario:  # a scenario's map is its study's, checked with every scenario's joints
        check_map_series(parsed)
    return parsed


def check_drift(drift: DriftSpec, cycles: int, cycle_time_s: float | None, has_poses: bool, source) -> None:
    """Refuse a ``[drift]`` that cannot run: without poses to test, without ``study.cycle_time_s``, or too short for
    its two sets of cycles (``drift.set_cycles``, else the study's ``cycles``)."""
    if not has_poses:
        raise InputError("simulates ISO 9283's drift test at the study's poses: add [[poses]] or an [iso_cube]", source,
                         "drift")
    if cycle_time_s is None:
        raise InputError("[drift] approaches each pose once a cycle for drift.duration_s: give the cycle's duration "
                         "as study.cycle_time_s [s]", source, "study.cycle_time_s")
    sets = 2 * (drift.set_cycles or cycles)
    if drift.duration_s < sets * cycle_time_s:
        raise InputError(f"{drift.duration_s:g} s hold {int(drift.duration_s // cycle_time_s)} cycles of "
                         f"{cycle_time_s:g} s, fewer than the first and last sets' {sets}: lengthen it, or lower "
                         "drift.set_cycles", source, "drift.duration_s")


def joint_series(study: Study, joints: list[str | None]) -> list[FrictionSeries]:
    """The time series of each joint of ``joints`` (``None``: the ``[joints]`` defaults) that gives time keys."""
    found = []
    for name in joints:
        spec = study.joints if name is None else study.joint(name)
        key = spec.friction_key
        if key is not None:
            at = "joints" if name is None else study.joint_key(name, key).rsplit(".", 1)[0]
            series = friction_series(getattr(spec, key), study.source, f"{at}.{key}")
            if series is not None and not series.independent:
                found.append(series)
    return found


def map_series(study: Study) -> list[FrictionSeries]:
    """The time series of the joints' friction in the study's map: its own joints' and every scenario's."""
    return [series for s in [study, *(c.study for c in study.scenarios)]
            for series in joint_series(s, [None, *s.joint_overrides])]


def check_map_series(study: Study) -> None:
    """Refuse a ``[map]`` whose ``state`` or ``compare`` changes nothing or cannot be reached: a state on a map whose
    joints' friction is no time series (in no scenario), a state's age without a running-in joint, its warm-up
    without a warming joint (or longer than ``MAX_WARM_UP_CYCLES`` cycles)."""
    series = map_series(study)
    for name in ("state", "compare"):
        state = getattr(study.map, name)
        if state is None:
            continue
        if not series:
            raise InputError("no joint's friction is a time series (ar1, run_in, steady_mean_std, thermal), so every "
                             f"state gives the same map: remove map.{name}", study.source, f"map.{name}")
        if state.age_cycles is not None and not any(s.run_in is not None for s in series):
            raise InputError("places the map's tests on a running-in, and no joint's friction has run_in: give one, "
                             f"or remove map.{name}.age_cycles", study.source, f"map.{name}.age_cycles")
        if state.after_s > 0 and not any(s.thermal is not None for s in series):
            raise InputError("warms the joints up, and no joint's friction has thermal: give one, or make the state "
                             "\"cold\"", study.source, f"map.{name}.after_s")
        cycle_time = min(s.cycle_time_s or math.inf for s in [study, *(c.study for c in study.scenarios)])
        if math.isfinite(state.after_s) and state.after_s > MAX_WARM_UP_CYCLES * cycle_time:
            raise InputError(f"{state.after_s:g} s are more than {MAX_WARM_UP_CYCLES:,} cycles of {cycle_time:g} s, "
                             "stepped one by one: give \"warm\" (settled) instead", study.source,
                             f"map.{name}.after_s")


def check_motion(study: Study, joints: list[str | None]) -> None:
    """Refuse a joint friction's time keys that do not fit together (``thermal`` without the joints' motion:
    ``study.cycle_time_s`` and the joint's ``travel_per_cycle``), for each joint of ``joints`` (``None``: the
    ``[joints]`` defaults)."""
    for name in joints:
        spec = study.joints if name is None else study.joint(name)
        key = spec.friction_key
        if key is None:
            continue
        at = "joints" if name is None else study.joint_key(name, key).rsplit(".", 1)[0]
        series = friction_series(getattr(spec, key), study.source, f"{at}.{key}")
        if series is None or series.thermal is None:
            continue
        if study.cycle_time_s is None:
            raise InputError(f"{at}.{key}.thermal heats the joint by its friction power every cycle: give the "
                             "cycle's duration as study.cycle_time_s [s]", study.source, "study.cycle_time_s")
        if spec.travel_per_cycle is None:
            where = "joints" if name is None else f"joints.{name}"
            raise InputError(f"{at}.{key}.thermal heats the joint by its friction power every cycle: give the "
                             f"joint's travel per cycle as {where}.travel_per_cycle [m or rad]", study.source,
                             f"{where}.travel_per_cycle")


def check_map(mapping: dict, source) -> MapSpec:
    """Validate the ``[map]`` table into the spec of its ``kind``: its keys, and how they fit together."""
    if "kind" not in mapping:
        raise InputError(f"missing: this key is required ({', '.join(MAP_KINDS)})", source, "map.kind")
    kind = one_of(*MAP_KINDS)(mapping["kind"], source, "map.kind")
    spec = check_table(mapping, {**MAP_COMMON_KEYS, **MAP_KINDS[kind]}, source, "map")
    if spec["directional"] is None:
        spec["directional"] = spec["statistic"] == "expected"
    elif spec["directional"] and spec["statistic"] == "one-test":
        raise InputError("a one-test map has no directional figures (vAP_p and RP_l_multi are expected figures): "
                         "remove map.directional, or set map.statistic = \"expected\"", source, "map.directional")
    if kind == "plane":
        _check_counts(spec["resolution"], 2, "[nu, nv]", source)
        dot = sum(a * b for a, b in zip(spec["axis_u"], spec["axis_v"], strict=True))
        if abs(dot) > 1e-6:
            raise InputError(f"must be perpendicular to map.axis_u (their dot product is {dot:g})", source,
                             "map.axis_v")
        for name, count in zip(("extent_u_m", "extent_v_m"), spec["resolution"], strict=True):
            _check_width(spec[name], count, source, f"map.{name}")
    elif kind == "box":
        _check_counts(spec["resolution"], 3, "[nx, ny, nz]", source)
        for axis, (low, high, count) in enumerate(zip(spec["min_m"], spec["max_m"], spec["resolution"], strict=True)):
            _check_width([low, high], count, source, f"map.max_m[{axis}]")
    else:
        joints, ranges, counts = spec["joints"], spec["ranges"], spec["counts"]
        if not 1 <= len(joints) <= 3 or len(set(joints)) != len(joints):
            raise InputError(f"must name 1 to 3 different joints (got {joints!r})", source, "map.joints")
        for key, values in (("ranges", ranges), ("counts", counts)):
            if len(values) != len(joints):
                raise InputError(f"needs one entry per joint in map.joints ({len(joints)}); got {len(values)}",
                                 source, f"map.{key}")
        for i, (bounds, count) in enumerate(zip(ranges, counts, strict=True)):
            _check_width(bounds, count, source, f"map.ranges[{i}]")
    return _spec(MAP_SPECS[kind], {key: value for key, value in spec.items() if key != "kind"})


def check_placement(mapping: dict, map_spec: MapSpec | None, source) -> PlacementSpec:
    """Validate ``[placement]``: its keys, one way of giving the base positions, and a ``[map]`` of world positions
    (the task region) without ``[[scenarios]]``."""
    if map_spec is None or map_spec.kind == "joint":
        raise InputError("a placement search needs the task region as a [map] of kind \"plane\" or \"box\" (targets in "
                         "the world frame)" + ("" if map_spec is None else ", not \"joint\""), source,
                         "placement" if map_spec is None else "map.kind")
    if "scenarios" in mapping:
        raise InputError("[placement] ranks base positions with the study's own joints and cannot be combined with "
                         "[[scenarios]]: search with one scenario's joints at a time, or remove [[scenarios]]", source,
                         "scenarios")
    spec = check_table(table(mapping["placement"], source, "placement"), PLACEMENT_KEYS, source, "placement")
    box = [key for key in PLACEMENT_BOX_KEYS if spec[key] is not None]
    if spec["candidates"] is not None and box:
        raise InputError("give the base positions as candidates = [[x, y, z], ...] or as a box (base_xyz_m_min, "
                         "base_xyz_m_max, resolution), not both", source, f"placement.{box[0]}")
    if spec["candidates"] is None:
        missing = next((key for key in PLACEMENT_BOX_KEYS if spec[key] is None), None)
        if missing is not None:
            raise InputError("missing: give the base positions as a box (base_xyz_m_min, base_xyz_m_max, resolution "
                             "[nx, ny, nz]) or as candidates = [[x, y, z], ...]", source, f"placement.{missing}")
        if len(spec["resolution"]) != 3:
            raise InputError(f"needs 3 whole numbers [nx, ny, nz] (got {len(spec['resolution'])})", source,
                             "placement.resolution")
        for axis, (low, high, count) in enumerate(zip(spec["base_xyz_m_min"], spec["base_xyz_m_max"],
                                                     spec["resolution"], strict=True)):
            if low > high:
                raise InputError(f"is below base_xyz_m_min[{axis}] ({high:g} < {low:g}): swap them", source,
                                 f"placement.base_xyz_m_max[{axis}]")
            _check_width([low, high], count, source, f"placement.base_xyz_m_max[{axis}]")
    placement = _spec(PlacementSpec, spec)
    candidate_count(placement.candidate_count, source,
                    "placement.resolution" if spec["candidates"] is None else "placement.candidates")
    return placement


def _check_counts(counts: list[int], length: int, shape: str, source) -> None:
    if len(counts) != length:
        raise InputError(f"needs {length} whole numbers {shape} (got {len(counts)})", source, "map.resolution")


def _check_width(bounds: list[float], count: int, source, key: str) -> None:
    if count > 1 and not bounds[0] < bounds[1]:
        raise InputError(f"spans nothing ({bounds[0]:g} to {bounds[1]:g}) but {count} points are asked for; "
                         "widen it or ask for 1 point", source, key)


def _check_robot_overrides(robot: dict, number: int, mapping: dict, source) -> None:
    """Refuse what a scenario's ``robot`` table may not change besides the payload: the reference's (the first
    scenario's) robot, which is the study's, and a joint map's, whose targets are the study robot's joint values."""
    changed = [key for key in robot if key != "payload_kg"]
    if not changed:
        return
    key = f"scenarios[{number}].robot.{changed[0]}"
    if number == 0:
        raise InputError("the first scenario is the reference, measured with the study's robot: it may change "
                         "robot.payload_kg only; give [robot] this robot, or put this scenario after the first",
                         source, key)
    if isinstance(mapping.get("map"), dict) and mapping["map"].get("kind") == "joint":
        raise InputError("a joint map's targets are the study robot's joint values: its scenarios may change "
                         "robot.payload_kg only (a plane or box map compares robots at the same points)", source, key)


def parse_scenarios(mapping: dict, source, base_dir) -> tuple[ScenarioSpec, ...]:
    """Validate ``[[scenarios]]``: each a ``name`` and overrides of ``[study]``, ``[joints]`` and ``[robot]``, merged
    into the study (:func:`merge_overrides`); a scenario's study is checked as a study is."""
    entries = mapping.get("scenarios", [])
    if not isinstance(entries, list):
        raise InputError("must be a list of tables: write [[scenarios]]", source, "scenarios")
    base = {key: value for key, value in mapping.items() if key != "scenarios"}
    scenarios = []
    for i, entry in enumerate(entries):
        key = f"scenarios[{i}]"
        entry = table(entry, source, key)
        name = text(entry.get("name"), source, f"{key}.name")
        if not all(c.isalnum() or c in "-_." for c in name):
            raise InputError(f"'{name}' must use letters, digits, '-', '_' or '.' only (it names files)", source,
                             f"{key}.name")
        if name in [s.name for s in scenarios]:
            raise InputError(f"scenario name '{name}' is used twice; names must be unique", source, f"{key}.name")
        overrides = {k: v for k, v in entry.items() if k != "name"}
        for section, values in overrides.items():
            if section not in SCENARIO_SECTIONS:
                raise InputError(f"a scenario may override {', '.join(SCENARIO_SECTIONS)} only (the targets stay "
                                 f"the same){closest_hint(section, SCENARIO_SECTIONS)}", source, f"{key}.{section}")
            table(values, source, f"{key}.{section}")
        _check_robot_overrides(overrides.get("robot", {}), i, mapping, source)
        try:
            study = parse_study(merge_overrides(base, overrides), source, base_dir, scenario=True)
        except InputError as error:
            raise InputError(error.message, error.source, f"{key}.{error.key}") from None
        scenarios.append(ScenarioSpec(name, overrides, study))
    return tuple(scenarios)


def merge_overrides(mapping: dict, overrides: dict) -> dict:
    """``mapping`` with each section's keys replaced by ``overrides``; ``joints.<joint>`` tables and
    ``robot.xacro_args`` merge key by key; a ``robot`` override naming a robot (``urdf`` or ``name``) drops the
    study's ``ROBOT_IDENTITY_KEYS``."""
    merged = {**mapping}
    for section, values in overrides.items():
        merged[section] = {**mapping.get(section, {})}
        if section == "robot" and {"urdf", "name"} & set(values):
            merged[section] = {k: v for k, v in merged[section].items() if k not in ROBOT_IDENTITY_KEYS}
        for key, value in values.items():
            by_key = isinstance(value, dict) and ((section == "joints" and key not in JOINT_KEYS)
                                                  or (section == "robot" and key == "xacro_args"))
            merged[section][key] = {**merged[section].get(key, {}), **value} if by_key else value
    return merged
