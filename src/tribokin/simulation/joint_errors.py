"""Per-joint error model: the joint's lost motion in each cycle (docs/concepts.md, "The joint model").

For joint i and cycle j::

    dq_ij = offset_i + s_ij * (mu_ij * N_i * r_i / k_i + backlash_i / 2) + noise_ij

or, for a joint whose friction torque [N·m] (force [N], prismatic) tau_ij is given as a law,
``tau_ij / k_i`` in place of ``mu_ij * N_i * r_i / k_i``. The drive is a spring of stiffness k
pushing a segment that rubs on its slide or bearing; the encoder sits on the motor side, so the segment stops short
when the spring force equals friction, in the direction of travel s_ij.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, fields
from typing import NamedTuple

import numpy as np

from tribokin.errors import JointModelError, JointRangeError, SettingsError, closest_hint
from tribokin.kinematics.robot import Robot
from tribokin.tribology.friction_series import COLD, FrictionSeries, FrictionState, draw_series
from tribokin.tribology.laws import FrictionLaw
from tribokin.tribology.thermal import power_per_value

APPROACH_MODES = ("unidirectional", "bidirectional", "random")


@dataclass(frozen=True)
class JointErrorModel:
    """Error sources of one joint.

    Attributes:
        friction: law of the friction coefficient mu [-], or of the friction torque [N·m] (force [N], prismatic)
            itself when its ``quantity`` says so (:attr:`friction_is_torque`).
        stiffness: transmission stiffness k [N/m] (prismatic) or [N·m/rad] (revolute).
        normal_force_N: load carried by the slide or bearing [N]; ``None`` to compute it from statics.
        friction_radius_m: effective friction radius r [m] of a revolute joint (ignored, taken as 1, for prismatic).
        backlash: total backlash [m or rad]; each approach lands half of it short.
        offset: constant displacement of the transmission elements, epsilon_t [m or rad].
        noise_std: standard deviation of extra Gaussian noise per cycle [m or rad].
        bearing_span_m: span between the joint's guide pads or bearings [m], for loads from statics.
        series: how the friction moves from cycle to cycle (:class:`~tribokin.tribology.friction_series.
            FrictionSeries`: ``ar1``, running-in, warm-up); ``None``: every cycle an independent draw.
        travel_per_cycle: the joint's travel in one cycle [m or rad], both ways summed: what its ``thermal`` heats
            by (required with it).
    """

    friction: FrictionLaw
    stiffness: float
    normal_force_N: float | None = None
    friction_radius_m: float = 1.0
    backlash: float = 0.0
    offset: float = 0.0
    noise_std: float = 0.0
    bearing_span_m: float = 0.1
    series: FrictionSeries | None = None
    travel_per_cycle: float | None = None

    def __post_init__(self):
        if not isinstance(self.friction, FrictionLaw):
            raise JointModelError(f"friction must be a friction law (tribokin.tribology.laws: Constant, Gaussian...; "
                                  f"got {type(self.friction).__name__})", None, "friction")
        for name, low, strict in (("stiffness", 0.0, True), ("normal_force_N", 0.0, False),
                                  ("friction_radius_m", 0.0, True), ("backlash", 0.0, False),
                                  ("offset", -math.inf, False), ("noise_std", 0.0, False),
                                  ("bearing_span_m", 0.0, True)):
            value = getattr(self, name)
            if value is None and name == "normal_force_N":
                continue
            number = isinstance(value, (int, float, np.number)) and not isinstance(value, bool)
            if not number or not math.isfinite(value) or value < low or (strict and value == low):
                bound = "" if low == -math.inf else f" {'>' if strict else '>='} {low:g}"
                raise JointModelError(f"{name} must be a finite number{bound} (got {value!r})", None, name)
        if self.series is not None and not isinstance(self.series, FrictionSeries):
            raise JointModelError(f"series must be a FrictionSeries (tribokin.tribology.friction_series; got "
                                  f"{type(self.series).__name__})", None, "series")
        travel = self.travel_per_cycle
        if travel is not None and not (isinstance(travel, (int, float, np.number)) and math.isfinite(travel)
                                       and travel >= 0):
            raise JointModelError(f"travel_per_cycle must be a finite number >= 0 (got {travel!r})", None,
                                  "travel_per_cycle")
        if self.series is not None and self.series.thermal is not None and travel is None:
            raise JointModelError("series.thermal heats the joint by its friction power every cycle: give its "
                                  "travel_per_cycle [m or rad]", None, "travel_per_cycle")

    @property
    def correlated(self) -> bool:
        """The joint's friction is a time series (:attr:`series`), not an independent draw every cycle."""
        return self.series is not None and not self.series.independent

    @property
    def friction_is_torque(self) -> bool:
        """``friction`` is a law of the friction torque or force itself, not of mu: lost motion = its value / k,
        with no load or radius."""
        return self.friction.quantity != "mu"


def joint_models(robot: Robot, *, friction: FrictionLaw | None = None, stiffness: float | None = None,
                 joints: Mapping[str, Mapping] | None = None, **shared) -> list[JointErrorModel]:
    """One error model per joint of ``robot``, in its joint order: the values every joint shares, each joint's own
    (``joints``) over them. What a study's ``[joints]`` gives, in code
    (:func:`tribokin.study.assembly.joint_models` reads a study's tables into this).

    Args:
        robot: the robot.
        friction: every joint's friction law: of mu [-] (:mod:`tribokin.tribology.laws`, ``preset(...)``), or of the
            friction torque [N·m] (force [N], prismatic) itself (a law whose ``quantity`` says so).
        stiffness: every joint's transmission stiffness [N·m/rad] (revolute) or [N/m] (prismatic).
        joints: per joint name, its own values (any field of :class:`JointErrorModel`), e.g.
            ``{"shoulder_pan_joint": {"stiffness": 2e5}}``.
        **shared: any other field of :class:`JointErrorModel`, shared by every joint: ``normal_force_N`` [N] (``None``:
            from statics), ``friction_radius_m`` [m], ``backlash``, ``offset``, ``noise_std`` [m or rad],
            ``bearing_span_m`` [m].

    Raises:
        JointModelError: an unknown joint or field, a joint without a stiffness or friction, a value out of range;
            naming the joint and the field.
    """
    valid = [f.name for f in fields(JointErrorModel)]
    names = robot.joint_names
    for joint, values in (("every joint", shared), *(joints or {}).items()):
        if joint != "every joint" and joint not in names:
            raise JointModelError(f"unknown joint '{joint}'{closest_hint(joint, names)}; joints of {robot.label}: "
                                  f"{', '.join(names)}", joint, None)
        for key in values:
            if key not in valid:
                raise JointModelError(f"unknown joint model value '{key}' ({joint}){closest_hint(key, valid)}; "
                                      f"valid: {', '.join(valid)}", None if joint == "every joint" else joint, key)
    models = []
    for name in names:
        values = {"friction": friction, "stiffness": stiffness, **shared, **(joints or {}).get(name, {})}
        for part in ("stiffness", "friction"):
            if values[part] is None:
                raise JointModelError(f"joint '{name}' has no {part}: give {part}= (every joint's) or its own in "
                                      f"joints['{name}']", name, part)
        try:
            models.append(JointErrorModel(**values))
        except JointModelError as error:
            raise JointModelError(f"joint '{name}': {error.message}", name, error.part) from None
    return models


def friction_lever(models: list[JointErrorModel], prismatic: np.ndarray) -> np.ndarray:
    """r_i / k_i for each joint: lost motion per newton of normal load per unit mu [m/N or rad/N]; 1 / k_i
    per unit of friction force or torque for a joint whose law gives it (r = 1 for both)."""
    radius = np.array([1.0 if p or m.friction_is_torque else m.friction_radius_m
                       for m, p in zip(models, prismatic, strict=True)])
    return radius / np.array([m.stiffness for m in models])


def friction_loads(models: list[JointErrorModel], forces_N: np.ndarray) -> np.ndarray:
    """Bearing loads ``forces_N`` (..., nv) [N], 1 for a joint whose friction law gives its torque or force."""
    return np.where([m.friction_is_torque for m in models], 1.0, forces_N)


def torque_per_value(models: list[JointErrorModel], prismatic: np.ndarray, forces_N: np.ndarray) -> np.ndarray:
    """(..., nv) each joint's friction torque [N·m] (force [N], prismatic) per unit of its law's value under bearing
    loads ``forces_N`` (..., nv) [N]: N·r for a law of mu (N at a prismatic joint), 1 for a law of the torque or
    force."""
    return friction_loads(models, np.asarray(forces_N, dtype=float)) * friction_lever(models, prismatic) * \
        np.array([m.stiffness for m in models])


def friction_torque_moments(models: list[JointErrorModel], prismatic: np.ndarray, forces_N: np.ndarray
                            ) -> tuple[np.ndarray, np.ndarray]:
    """Mean and standard deviation (..., nv) of each joint's friction torque [N·m] (force [N], prismatic) under
    bearing loads ``forces_N`` (..., nv) [N]: mu·N·r of a law of mu, the law itself for a law of the torque or force.
    Lost motion is this over the stiffness (:func:`sample_joint_deviations` draws it)."""
    torque_per_unit = torque_per_value(models, prismatic, forces_N)
    return (np.array([m.friction.mean() for m in models]) * torque_per_unit,
            np.array([m.friction.std() for m in models]) * torque_per_unit)


def joint_travel(lower: np.ndarray, upper: np.ndarray, prismatic: np.ndarray) -> np.ndarray:
    """Range of each joint [m or rad]: upper - lower limit, at most a full turn for a revolute joint."""
    return np.where(prismatic, upper - lower, np.minimum(upper - lower, 2 * math.pi))


#: The parts of a joint's largest deviation, each named by the key that sets it, and what to do when it is too large.
DEVIATION_PARTS = {"stiffness": "raise stiffness (or lower the friction or the load)", "backlash": "lower backlash",
                   "offset": "lower offset", "noise_std": "lower noise_std"}
#: A law without an upper bound reaches at most its mean plus this many standard deviations (and noise this many).
TAIL_STDS = 6


def largest_mu(law: FrictionLaw) -> float:
    """The law's upper bound [-], else its mean + ``TAIL_STDS`` standard deviations."""
    high = law.support()[1]
    return high if math.isfinite(high) else law.mean() + TAIL_STDS * law.std()


def deviation_parts(models: list[JointErrorModel], prismatic: np.ndarray, forces_N: np.ndarray) -> np.ndarray:
    """(nv, 4) largest size [m or rad] of each part of every joint's deviation, in the order of ``DEVIATION_PARTS``:
    lost motion mu_max N r / k at the largest load of ``forces_N`` (..., nv) [N] (tau_max / k for a law of the friction
    torque or force), backlash / 2, |offset| and ``TAIL_STDS`` noise_std."""
    load = np.max(np.reshape(friction_loads(models, forces_N), (-1, len(models))), axis=0, initial=0.0)
    lost = np.array([largest_mu(m.friction) for m in models]) * load * friction_lever(models, prismatic)
    return np.column_stack([lost, *(np.array([[m.backlash / 2, abs(m.offset), TAIL_STDS * m.noise_std]
                                              for m in models]).T)])


def check_travel(models: list[JointErrorModel], prismatic: np.ndarray, forces_N: np.ndarray, travel: np.ndarray,
                 names: list[str]) -> None:
    """Refuse a joint whose deviation could exceed its range ``travel`` [m or rad], with the figures.

    Args:
        models: the joints' error models (nv,).
        prismatic: (nv,) which joints are prismatic.
        forces_N: (..., nv) bearing loads [N] the joints will carry.
        travel: (nv,) each joint's range [m or rad].
        names: the joints' names, for the error.

    Raises:
        JointRangeError: naming the first such joint and its largest part (a key of ``DEVIATION_PARTS``).
    """
    parts = deviation_parts(models, prismatic, forces_N)
    for i in np.flatnonzero(parts.sum(axis=1) > travel):
        unit = "m" if prismatic[i] else "rad"
        part = list(DEVIATION_PARTS)[int(np.argmax(parts[i]))]
        labels = ("lost motion", "backlash/2", "offset", f"{TAIL_STDS} noise_std")
        shown = [f"{label} {value:.3g} {unit}" for label, value in zip(labels, parts[i], strict=True) if value]
        what = labels[int(np.argmax(parts[i]))] if len(shown) == 1 else f"deviation ({', '.join(shown)})"
        raise JointRangeError(f"joint '{names[i]}': {what} up to {parts[i].sum():.3g} {unit} exceeds the joint's "
                              f"range {travel[i]:.3g} {unit}; {DEVIATION_PARTS[part]}", names[i], part)


def approach_signs(mode: str, cycles: int, directions: np.ndarray, rng: np.random.Generator):
    """Direction of travel of each joint in each cycle.

    Args:
        mode: ``"unidirectional"`` (every cycle from ``directions[0]``, ISO's default),
            ``"bidirectional"`` (cycling through ``directions`` in turn) or
            ``"random"`` (a direction drawn at random each cycle).
        cycles: number of cycles n.
        directions: (m, nv) array of +1/-1, the joint-space directions of travel
            of the m approach directions (m >= 2 for multi-directional modes).
        rng: random generator (used by ``"random"`` only).

    Returns:
        signs (n, nv) of +1/-1 and the approach-direction index (n,) of each cycle.
    """
    if mode == "unidirectional":
        group = np.zeros(cycles, dtype=int)
        return np.broadcast_to(directions[0].astype(float), (cycles, directions.shape[1])), group
    if mode == "bidirectional":
        group = np.arange(cycles) % len(directions)
    elif mode == "random":
        group = rng.integers(len(directions), size=cycles)
    else:
        raise ValueError(f"unknown approach mode {mode!r}; valid: {APPROACH_MODES}")
    return directions[group].astype(float), group


def require_cycle_time(models: list[JointErrorModel], cycle_time_s: float | None) -> None:
    """Refuse a joint whose friction heats it every cycle (its series' ``thermal``) without ``cycle_time_s``."""
    if cycle_time_s is None and any(m.series is not None and m.series.thermal is not None for m in models):
        raise SettingsError("a joint's friction heats it every cycle (its series' thermal): give cycle_time_s, "
                            "one cycle's duration [s]", "cycle_time_s")


def thermal_drive(model: JointErrorModel, torque_per_unit: float, cycle_time_s: float, state: FrictionState = COLD
                  ) -> tuple[float, float | None]:
    """A warming joint's (its series' ``thermal``) friction power per unit of its law's value [W]
    (:func:`~tribokin.tribology.thermal.power_per_value` of its ``travel_per_cycle``, ``torque_per_unit`` [N·m or N]
    and ``cycle_time_s`` [s]) and its temperature at a test's first cycle from ``state`` [°C]
    (:meth:`~tribokin.tribology.friction_series.FrictionState.start`: where the law's mean settles it when warm,
    :meth:`~tribokin.tribology.thermal.Thermal.settled_C`; after a time of warming up; ``None`` cold: ambient)."""
    power = power_per_value(model.travel_per_cycle, cycle_time_s, float(torque_per_unit))
    return power, state.start(model.friction, model.series, power, cycle_time_s)[1]


def warming_joints(models: list[JointErrorModel]) -> list[int]:
    """The indices of the joints whose friction heats them (their series' ``thermal``), in order."""
    return [i for i, m in enumerate(models) if m.series is not None and m.series.thermal is not None]


class FrictionDraws(NamedTuple):
    """The joints' friction draws of n cycles, ``tests`` tests one after another (:func:`draw_friction`).

    Attributes:
        values: (n, nv) each law's value: mu [-], or a torque [N·m] (force [N]) for a joint whose law gives it; a
            view of (nv, n) memory, so each joint's cycles are contiguous.
        temperature_C: (tests, n / ``tests``, j) each warming joint's (:func:`warming_joints`, in order) temperature
            at every cycle's start [°C], the one its draw was taken at; ``None`` unless asked for.
    """

    values: np.ndarray
    temperature_C: np.ndarray | None = None


def draw_friction(models: list[JointErrorModel], cycles: int, rng: np.random.Generator, tests: int = 1,
                  torque_per_unit: np.ndarray | None = None, cycle_time_s: float | None = None,
                  state: FrictionState = COLD, temperatures: bool = False) -> FrictionDraws:
    """The joints' friction draws (:class:`FrictionDraws`): coefficients mu (cycles, nv) [-], drawn joint by joint
    (all cycles of the first joint, then of the second...): in one call when all joints share one law, the usual case.

    A joint whose friction is a time series (:attr:`JointErrorModel.correlated`) draws its cycles as ``tests``
    consecutive tests of ``cycles / tests`` cycles each, every one from the series' start: ``state``'s
    (:class:`~tribokin.tribology.friction_series.FrictionState`: its age, else the series' ``age_cycles``; cold,
    warm, or after a time of warming up), by :func:`~tribokin.tribology.friction_series.draw_series`; then every joint
    draws so, the independent ones ``law.rvs((tests, cycles / tests))``. Its ``thermal`` heats it by the friction
    power :func:`~tribokin.tribology.thermal.power_per_value` gives from ``torque_per_unit`` (nv,) [N·m or N per
    unit of the law's value: :func:`sample_joint_deviations`'), its ``travel_per_cycle`` and ``cycle_time_s`` [s].
    With ``temperatures``, the warming joints' temperatures the draws were taken at, kept (:class:`FrictionDraws`).
    """
    laws, warming = [m.friction for m in models], warming_joints(models)
    temperature = np.empty((tests, cycles // tests, len(warming))) if temperatures else None
    if not any(m.correlated for m in models):
        if all(law is laws[0] or law == laws[0] for law in laws):
            return FrictionDraws(laws[0].rvs(size=(len(laws), cycles), random_state=rng).T, temperature)
        return FrictionDraws(np.array([law.rvs(size=cycles, random_state=rng) for law in laws]).T, temperature)
    if cycles % tests:
        raise ValueError(f"{cycles} cycles do not split into {tests} tests")
    require_cycle_time(models, cycle_time_s)
    drawn = []
    for i, model in enumerate(models):
        series, power = model.series or FrictionSeries(), None
        if series.thermal is not None:
            power = thermal_drive(model, torque_per_unit[i], cycle_time_s)[0]
        series, start = state.start(model.friction, series, power, cycle_time_s)
        joint = draw_series(model.friction, series, tests, cycles // tests, rng, power, cycle_time_s, start)
        drawn.append(joint.values)
        if temperature is not None and i in warming:  # joint by joint into one array: no stacked copy
            temperature[:, :, warming.index(i)] = joint.temperature_C
    return FrictionDraws(np.array(drawn).reshape(len(models), cycles).T, temperature)


def sample_joint_deviations(models: list[JointErrorModel], prismatic: np.ndarray, normal_forces_N: np.ndarray,
                            signs: np.ndarray, rng: np.random.Generator, tests: int = 1,
                            cycle_time_s: float | None = None, state: FrictionState = COLD,
                            warm_up_loads_N: np.ndarray | None = None, temperatures: bool = False
                            ) -> tuple[np.ndarray, FrictionDraws]:
    """Draw the joint deviations dq of every cycle.

    A joint's friction time series (:attr:`JointErrorModel.series`) runs through each of ``tests`` consecutive
    tests of n / ``tests`` cycles from its start (:func:`draw_friction`). Its ``thermal`` power rests on the bearing
    load ``normal_forces_N`` at the tested pose (or ``warm_up_loads_N``, a map's), held over the joint's whole
    ``travel_per_cycle``: a cycle dissipates
    the friction torque (force) mu·N·r (the law's own torque or force) times that travel, spread over
    ``cycle_time_s`` (the joint's motion to and from the pose, its dwell included); the loads of the path between
    are not computed.

    Args:
        models: one error model per active joint.
        prismatic: (nv,) True for prismatic joints.
        normal_forces_N: (nv,) load on each joint's bearing [N].
        signs: (n, nv) direction of travel of each joint in each cycle.
        rng: random generator; draws mu (:func:`draw_friction`), then the noise.
        tests: the tests the n cycles are, one after another (each n / ``tests`` cycles long).
        cycle_time_s: one cycle's duration [s], required by a joint's ``thermal``.
        state: where each test's series start (:class:`~tribokin.tribology.friction_series.FrictionState`: cold
            at each joint's own age, warm, after a time warming up, at another age).
        warm_up_loads_N: (nv,) the bearing loads [N] the warm-up's power rests on (``None``: ``normal_forces_N``).
        temperatures: keep each warming joint's temperature at every cycle's start (:class:`FrictionDraws`).

    Returns:
        dq (n, nv) [m or rad] and the draws of the friction laws (:class:`FrictionDraws`: their values (n, nv),
        coefficients mu [-], or torques [N·m] (forces [N]) for a joint whose law gives them).
    """
    torque = None
    if any(m.correlated for m in models):  # the friction torque (force) per unit of the law's value, for thermal
        torque = torque_per_value(models, prismatic, normal_forces_N if warm_up_loads_N is None else warm_up_loads_N)
    drawn = draw_friction(models, signs.shape[0], rng, tests, torque, cycle_time_s, state, temperatures)
    dq = drawn.values * (friction_loads(models, np.asarray(normal_forces_N, dtype=float))
                         * friction_lever(models, prismatic))
    if any(m.backlash for m in models):
        dq += np.array([m.backlash / 2 for m in models])
    dq *= signs
    if any(m.offset for m in models):
        dq += np.array([m.offset for m in models])
    if any(m.noise_std > 0 for m in models):
        dq += rng.standard_normal(dq.shape) * np.array([m.noise_std for m in models])
    return dq, drawn
