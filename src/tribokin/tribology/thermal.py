"""A joint's warm-up: a first-order thermal model driven by the friction power it dissipates, and mu's dependence on
its temperature.

The joint (its gear and bearing, lumped) has one temperature T [°C]:

    dT/dt = (ambient + R·P − T) / τ

with τ the time constant [s], R the thermal resistance to the surroundings [K/W] and P the friction power [W]: the
friction force [N] (torque [N·m]) times the joint's travel per cycle [m] ([rad]) over the cycle time [s]. P is held
over a cycle, so one cycle's step is exact: T ← T∞ + (T − T∞)·exp(−Δt/τ), T∞ = ambient + R·P. The friction law holds
at ``ambient_C``; at T, mu is the law's value times a factor: 1 + ``mu_per_K``·(T − ambient) (a relative change per
kelvin, so it applies alike to a law of mu, of a torque or of a force), or interpolated in ``mu_table`` (pairs of
temperature [°C] and factor, constant beyond its ends); never below 0. This is friction-induced change only: the
thermal expansion of links and gears is not modelled.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from tribokin.errors import LawError

#: Ambient temperature of an ISO 9283 test [°C]: ISO 9283:1998, §6.3 (operating and environmental
#: conditions): its test temperature, 20 °C.
ISO_AMBIENT_C = 20.0


@dataclass(frozen=True)
class Thermal:
    """A joint's first-order thermal model and mu's dependence on its temperature.

    Attributes:
        time_constant_s: τ [s], > 0.
        resistance_K_per_W: R [K/W], >= 0: the temperature rise per watt dissipated, once settled.
        ambient_C: the surroundings' temperature [°C], where the friction law holds.
        mu_per_K: relative change of mu per kelvin above ambient [1/K] (give this or ``mu_table``).
        mu_table: ``((temperature_C, factor), ...)``, temperatures strictly increasing, factors >= 0.
    """

    time_constant_s: float
    resistance_K_per_W: float
    ambient_C: float = ISO_AMBIENT_C
    mu_per_K: float | None = None
    mu_table: tuple[tuple[float, float], ...] | None = None

    def __post_init__(self):
        numbers = {"time_constant_s": self.time_constant_s, "resistance_K_per_W": self.resistance_K_per_W,
                   "ambient_C": self.ambient_C, "mu_per_K": 0.0 if self.mu_per_K is None else self.mu_per_K}
        for key, value in numbers.items():
            if not math.isfinite(value):
                raise LawError(f"must be a finite number (got {value})", f"thermal.{key}")
        if self.time_constant_s <= 0:
            raise LawError(f"must be > 0 s (got {self.time_constant_s:g}): a joint cannot change temperature "
                           "in no time", "thermal.time_constant_s")
        if self.resistance_K_per_W < 0:
            raise LawError(f"must be >= 0 K/W (got {self.resistance_K_per_W:g})", "thermal.resistance_K_per_W")
        if self.ambient_C < -273.15:
            raise LawError(f"is below absolute zero (got {self.ambient_C:g} °C)", "thermal.ambient_C")
        if (self.mu_per_K is None) == (self.mu_table is None):
            raise LawError("give mu's dependence on temperature: mu_per_K (relative change per kelvin) or mu_table "
                           "([[temperature_C, factor], ...]), one of them", "thermal.mu_per_K")
        if self.mu_table is not None:
            table = np.asarray(self.mu_table, dtype=float)
            if table.ndim != 2 or table.shape[1] != 2 or table.shape[0] < 2 or not np.all(np.isfinite(table)):
                raise LawError("must be at least two [temperature_C, factor] pairs of finite numbers",
                               "thermal.mu_table")
            out_of_order = np.flatnonzero(np.diff(table[:, 0]) <= 0)
            if out_of_order.size:
                i = int(out_of_order[0]) + 1
                raise LawError(f"temperatures must increase row by row: row {i} ({table[i, 0]:g} °C) is not above "
                               f"row {i - 1} ({table[i - 1, 0]:g} °C)", f"thermal.mu_table[{i}]")
            if np.any(table[:, 1] < 0):
                raise LawError("factors must be >= 0: friction is never negative", "thermal.mu_table")

    def factor(self, temperature_C: np.ndarray) -> np.ndarray:
        """mu's factor at ``temperature_C`` [°C] against its value at ambient [-], never below 0."""
        temperature_C = np.asarray(temperature_C, dtype=float)
        if self.mu_table is not None:
            table = np.asarray(self.mu_table, dtype=float)
            return np.interp(temperature_C, table[:, 0], table[:, 1])
        return np.maximum(1.0 + self.mu_per_K * (temperature_C - self.ambient_C), 0.0)

    def step(self, temperature_C: np.ndarray, power_W: np.ndarray, duration_s: float) -> np.ndarray:
        """The temperature [°C] after ``duration_s`` [s] of a constant dissipated ``power_W`` [W] (exact)."""
        settled = self.ambient_C + self.resistance_K_per_W * np.asarray(power_W, dtype=float)
        return settled + (temperature_C - settled) * math.exp(-duration_s / self.time_constant_s)

    def settled_C(self, power_per_value_W: float, value: float) -> float:
        """The temperature [°C] a joint settles at whose friction of ``value`` at ambient (times its factor at that
        temperature) dissipates ``power_per_value_W`` [W] per unit of it: T = ambient + R·P·value·factor(T), by
        fixed-point iteration from ambient (a contraction wherever the factor changes by less than 1/(R·P·value) per
        kelvin: for the warm-ups of friction alone, by orders of magnitude)."""
        gain, now = self.resistance_K_per_W * power_per_value_W * value, self.ambient_C
        for _ in range(1000):
            then, now = now, self.ambient_C + gain * float(self.factor(now))
            if abs(now - then) <= 1e-12 * max(1.0, abs(now)):
                break
        return now

    def after_C(self, power_per_value_W: float, value: float, duration_s: float, cycle_time_s: float) -> float:
        """The temperature [°C] a joint reaches from ambient after ``duration_s`` [s] of cycles of ``cycle_time_s``
        [s], whose friction of ``value`` at ambient (times its factor at the cycle's starting temperature) dissipates
        ``power_per_value_W`` [W] per unit of it: :meth:`step` cycle by cycle, the last cycle's part for the rest of
        the time, until the gap left to the settled temperature (a cycle's change over the share of the gap a cycle
        closes, 1 − exp(−Δt/τ)) is below 1e-13 of it; ``math.inf``: :meth:`settled_C`. Without a factor's change
        (``mu_per_K = 0``) this is :meth:`temperature`'s closed form. Kept per arguments (a map's every block asks
        again)."""
        return _after(self, power_per_value_W, value, duration_s, cycle_time_s)

    def temperature(self, time_s, power_W: float, start_C: float | None = None) -> np.ndarray:
        """Closed form of the temperature [°C] at ``time_s`` [s] under a constant ``power_W`` [W] from ``start_C``
        (``None``: ambient): T∞ + (T₀ − T∞)·exp(−t/τ)."""
        start = self.ambient_C if start_C is None else start_C
        settled = self.ambient_C + self.resistance_K_per_W * power_W
        return settled + (start - settled) * np.exp(-np.asarray(time_s, dtype=float) / self.time_constant_s)


@functools.lru_cache(maxsize=256)
def _after(thermal: Thermal, power_per_value_W: float, value: float, duration_s: float, cycle_time_s: float) -> float:
    """:meth:`Thermal.after_C`."""
    if math.isinf(duration_s):
        return thermal.settled_C(power_per_value_W, value)
    whole, rest = divmod(duration_s, cycle_time_s)
    now, rate = thermal.ambient_C, -math.expm1(-cycle_time_s / thermal.time_constant_s)  # a cycle's share of the gap
    for _ in range(int(whole)):
        then, now = now, float(thermal.step(now, power_per_value_W * value * float(thermal.factor(now)), cycle_time_s))
        if abs(now - then) / rate <= 1e-13 * max(1.0, abs(now)):  # the gap left to the settled temperature
            return now
    if rest > 0:
        now = float(thermal.step(now, power_per_value_W * value * float(thermal.factor(now)), rest))
    return now


def power_per_value(travel_per_cycle: float, cycle_time_s: float, lever: float = 1.0) -> float:
    """The friction power [W] one unit of a law's value dissipates: ``lever`` (the force or torque per unit of the
    value: N·r [N·m] for mu at a revolute joint, N [N] at a prismatic one, 1 for a law of the torque or force itself)
    times ``travel_per_cycle`` [rad or m] over ``cycle_time_s`` [s]."""
    if not cycle_time_s > 0:
        raise LawError(f"must be > 0 s (got {cycle_time_s})", "cycle_time_s")
    return lever * abs(travel_per_cycle) / cycle_time_s
