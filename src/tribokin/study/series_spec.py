"""The time keys of a joint's friction (``ar1``, ``run_in``, ``age_cycles``, ``steady_mean_std``, ``thermal``) and the
joints' motion they need (``[study] cycle_time_s``, ``[joints] travel_per_cycle``): checked, each with its range,
and made into a :class:`~tribokin.tribology.friction_series.FrictionSeries`; a map's ``state`` and ``compare``
(where its tests' series start) into a :class:`~tribokin.tribology.friction_series.FrictionState`.

``run_in.start`` and ``steady_mean_std`` are in the law's quantity: mu for ``friction``, N·m for
``friction_torque_Nm``, N for ``friction_force_N`` (each checked against that quantity's range).
"""

from __future__ import annotations

import math
from functools import partial

from tribokin.checks import finite, non_negative, number_list, positive, table, within
from tribokin.errors import InputError, LawError
from tribokin.study.schema import REQUIRED, check_table
from tribokin.tribology.friction_series import COLD, TIME_KEYS, WARM, FrictionSeries, FrictionState, RunIn
from tribokin.tribology.laws import coefficient
from tribokin.tribology.thermal import ISO_AMBIENT_C, Thermal

correlation = within(finite, -1.0, 1.0, "", "a correlation; at ±1 exactly the values never change (or only flip), "
                     "so it must lie strictly between")
age = within(non_negative, 0.0, 1e12, "cycles", "a trillion cycles, one a second, take 30 000 years")
tau = within(positive, 1e-3, 1e12, "cycles", "a running-in over a trillion cycles never ends")
cycle_time = within(positive, 1e-3, 1e6, "s", "one approach to a pose takes more than a millisecond and less than "
                    "eleven days")
travel = within(non_negative, 0.0, 1e3, "m or rad", "no joint travels a kilometre or turns 160 times in one cycle")
time_constant = within(positive, 1.0, 1e7, "s", "no lumped joint settles within a second (a motor's winding does, "
                       "the gear around it does not), nor takes four months")
resistance = within(non_negative, 0.0, 100.0, "K/W", "at 100 K per watt a joint would melt its grease on a few watts")
ambient = within(finite, -60.0, 200.0, "°C", "robots work from freezers to ovens")
relative_per_K = within(finite, -0.1, 0.1, "1/K", "beyond ±10 % per kelvin a few kelvin would double or cancel "
                        "friction")
temperature = within(finite, -60.0, 400.0, "°C", "greased joints run from freezers to a few hundred °C")
factor = within(non_negative, 0.0, 100.0, "", "a factor of mu, never negative; a hundredfold change is no warm-up")


warm_up_time = within(non_negative, 0.0, 1e8, "s", "three years of warming up: use \"warm\", the settled state")
#: A map's maximum warm-up in cycles (``after_s`` over ``cycle_time_s``): the warm-up is stepped cycle by cycle.
MAX_WARM_UP_CYCLES = 1_000_000


def after_time(value, source, key) -> float:
    """Seconds of warming up >= 0, or ``"warm"``: settled (``math.inf``)."""
    return math.inf if value == "warm" else warm_up_time(value, source, key)


#: ``state = { age_cycles, after_s }`` of a map (or ``"cold"``, ``"warm"``).
STATE_KEYS = {"age_cycles": (age, None), "after_s": (after_time, 0.0)}


def friction_state(value, source, key) -> FrictionState:
    """A map's ``state`` (or ``compare``): ``"cold"`` (each joint's own age, ambient), ``"warm"`` (settled), or
    ``{ age_cycles = ..., after_s = ... }`` (every running-in joint's age; seconds of the study's cycle from cold, or
    ``"warm"``)."""
    if isinstance(value, str):
        if value not in ("cold", "warm"):
            raise InputError(f'must be "cold", "warm" or a table {{ age_cycles = ..., after_s = ... }} (got '
                             f'{value!r})', source, key)
        return COLD if value == "cold" else WARM
    checked = check_table(table(value, source, key), STATE_KEYS, source, key)
    return FrictionState(checked["age_cycles"], checked["after_s"])


def ar1(value, source, key) -> float:
    """A lag-one autocorrelation, strictly between −1 and 1."""
    value = correlation(value, source, key)
    if abs(value) == 1:
        raise InputError(f"must lie strictly between -1 and 1 (got {value:g}): a series of lag-one correlation ±1 "
                         "never changes (or only flips)", source, key)
    return value


def temperature_table(value, source, key) -> tuple[tuple[float, float], ...]:
    """``[[temperature_C, factor], ...]``: at least two pairs, temperatures strictly increasing."""
    if not isinstance(value, list) or len(value) < 2:
        raise InputError(f"must be at least two [temperature_C, factor] pairs (got {value!r})", source, key)
    rows = []
    for i, row in enumerate(value):
        pair = number_list(row, source, f"{key}[{i}]")
        if len(pair) != 2:
            raise InputError(f"must be a [temperature_C, factor] pair (got {len(pair)} numbers)", source, f"{key}[{i}]")
        rows.append((temperature(pair[0], source, f"{key}[{i}]"), factor(pair[1], source, f"{key}[{i}]")))
        if i and rows[i][0] <= rows[i - 1][0]:
            raise InputError(f"temperatures must increase row by row: {rows[i][0]:g} °C is not above the row before's "
                             f"{rows[i - 1][0]:g} °C; sort the table", source, f"{key}[{i}]")
    return tuple(rows)


#: ``run_in = { start, tau_cycles }`` of a law of mu (``start``: a friction coefficient).
RUN_IN_KEYS = {"start": (coefficient, REQUIRED), "tau_cycles": (tau, REQUIRED)}
#: ``thermal = { ... }``: the defaults of its model. τ = R·C with C ≈ 2 kg of aluminium × 900 J/(kg·K) = 1800 J/K
#: (estimated: a size-25 gear unit's housing) and R = 1/(h·A) ≈ 1 K/W (estimated: natural convection,
#: h ≈ 10 W/(m²·K) over A ≈ 0.1 m²); ambient: ISO 9283's test temperature.
THERMAL_KEYS = {
    "time_constant_s": (time_constant, 1800.0),
    "resistance_K_per_W": (resistance, 1.0),
    "ambient_C": (ambient, ISO_AMBIENT_C),
    "mu_per_K": (relative_per_K, None),
    "mu_table": (temperature_table, None),
}


def run_in_table(value, source, key, bound=coefficient) -> dict:
    """``{ start, tau_cycles }``, ``start`` within the law's quantity's range ``bound``."""
    return check_table(table(value, source, key), {**RUN_IN_KEYS, "start": (bound, REQUIRED)}, source, key)


def thermal_table(value, source, key) -> dict:
    """``{ time_constant_s, resistance_K_per_W, ambient_C, mu_per_K | mu_table }``: one of mu's dependences."""
    checked = check_table(table(value, source, key), THERMAL_KEYS, source, key)
    if (checked["mu_per_K"] is None) == (checked["mu_table"] is None):
        which = "mu_table" if checked["mu_table"] is not None else "mu_per_K"
        raise InputError("give mu's dependence on the joint's temperature as one of mu_per_K (relative change per "
                         "kelvin) or mu_table ([[temperature_C, factor], ...])" +
                         (", not both" if checked["mu_table"] is not None else ""), source, f"{key}.{which}")
    return checked


def series_keys(bound) -> dict:
    """The time keys' schema for a law whose values ``bound`` checks (mu, a torque [N·m] or a force [N])."""
    return {
        "ar1": (ar1, 0.0),
        "run_in": (partial(run_in_table, bound=bound), None),
        "age_cycles": (age, 0.0),
        "steady_mean_std": (bound, 0.0),
        "thermal": (thermal_table, None),
    }


#: The time keys of a law of mu (the study-file reference's table).
SERIES_KEYS = series_keys(coefficient)


def law_and_time_keys(law_check, bound):
    """A friction table's check: its law's keys by ``law_check``, its time keys (:data:`TIME_KEYS`) by
    :func:`series_keys` of ``bound``; the table returned whole."""
    def check(value, source, key) -> dict:
        table(value, source, key)
        law_check({name: v for name, v in value.items() if name not in TIME_KEYS}, source, key)
        check_table({name: v for name, v in value.items() if name in TIME_KEYS}, series_keys(bound), source, key)
        return value
    return check


def without_time_keys(value, source, key) -> dict:
    """A pose's friction table: a law only (a series runs across a joint's cycles, not a pose's)."""
    given = next((name for name in table(value, source, key) if name in TIME_KEYS), None)
    if given is not None:
        raise InputError("a pose's friction is a law only: give time keys on a joint's friction ([joints] or "
                         "[joints.<joint>])", source, f"{key}.{given}")
    return value


def law_table(friction: dict) -> dict:
    """A friction table without its time keys: the law's own."""
    return {name: value for name, value in friction.items() if name not in TIME_KEYS}


def friction_series(friction: dict, source=None, key: str = "friction") -> FrictionSeries | None:
    """The :class:`FrictionSeries` of a friction table's time keys (checked: :func:`law_and_time_keys`), ``None``
    when it gives none; a combination the spec refuses names ``key``'s part."""
    given = {name: friction[name] for name in TIME_KEYS if name in friction}
    if not given:
        return None
    try:
        run_in = given.get("run_in")
        thermal = given.get("thermal")
        return FrictionSeries(
            ar1=float(given.get("ar1", 0.0)),
            run_in=None if run_in is None else RunIn(float(run_in["start"]), float(run_in["tau_cycles"])),
            age_cycles=float(given.get("age_cycles", 0.0)),
            steady_mean_std=float(given.get("steady_mean_std", 0.0)),
            thermal=None if thermal is None else Thermal(**{**{k: d for k, (_, d) in THERMAL_KEYS.items()},
                                                          **thermal_table(thermal, source, f"{key}.thermal")}),
        )
    except LawError as error:
        raise InputError(error.message, source, f"{key}.{error.parameter}") from None
