"""The joint's warm-up (tribology.thermal, through friction_series.draw_series) against its closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tribokin.errors import LawError
from tribokin.tribology.friction_series import FrictionSeries, draw_series
from tribokin.tribology.laws import Constant, Scaled, Uniform
from tribokin.tribology.thermal import Thermal, power_per_value

#: A UR5-sized elbow (estimated): 150 N at r = 0.02 m (3 N·m per unit of mu), 1.5 rad per 4 s cycle.
LEVER, TRAVEL, CYCLE_S = 150.0 * 0.02, 1.5, 4.0


def test_temperature_under_constant_friction_is_the_closed_form():
    """Constant mu and no dependence on temperature: T(t) = T∞ + (T₀ − T∞)·exp(−t/τ) at the start of every cycle,
    T∞ = ambient + R·P, P = mu·N·r·travel/cycle time."""
    thermal = Thermal(600.0, 2.5, 22.0, mu_per_K=0.0)
    per_value = power_per_value(TRAVEL, CYCLE_S, LEVER)
    drawn = draw_series(Constant(0.12), FrictionSeries(thermal=thermal), 2, 900, np.random.default_rng(0),
                        per_value, CYCLE_S)
    power = 0.12 * LEVER * TRAVEL / CYCLE_S
    time_s = CYCLE_S * np.arange(900)
    closed = 22.0 + 2.5 * power * (1 - np.exp(-time_s / 600.0))
    assert drawn.temperature_C == pytest.approx(np.broadcast_to(closed, (2, 900)), abs=1e-9)
    assert thermal.temperature(time_s, power) == pytest.approx(closed, abs=1e-12)
    assert np.all(drawn.values == 0.12)


def test_temperature_coupled_to_friction_is_its_recurrence():
    """mu = mu₀·(1 + a·ΔT): each cycle ΔT ← e·ΔT + (1 − e)·R·P₀·(1 + a·ΔT), e = exp(−Δt/τ), a linear recurrence
    ΔT_k = d·(1 − c^k)/(1 − c), c = e + (1 − e)·a·R·P₀, d = (1 − e)·R·P₀; it tends to the continuous model's
    R·P₀/(1 − a·R·P₀)."""
    a, resistance, tau = -0.01, 3.0, 300.0
    thermal = Thermal(tau, resistance, 20.0, mu_per_K=a)
    drawn = draw_series(Constant(0.2), FrictionSeries(thermal=thermal), 1, 2000, np.random.default_rng(0),
                        power_per_value(TRAVEL, CYCLE_S, LEVER), CYCLE_S)
    rise = resistance * 0.2 * LEVER * TRAVEL / CYCLE_S
    e = math.exp(-CYCLE_S / tau)
    c, d = e + (1 - e) * a * rise, (1 - e) * rise
    k = np.arange(2000)
    assert drawn.temperature_C[0] - 20.0 == pytest.approx(d * (1 - c ** k) / (1 - c), abs=1e-9)
    assert drawn.values[0] == pytest.approx(0.2 * (1 + a * (drawn.temperature_C[0] - 20.0)), abs=1e-15)
    assert drawn.temperature_C[0, -1] - 20.0 == pytest.approx(rise / (1 - a * rise), rel=1e-6)


def test_table_of_factors_and_a_torque_law():
    """A table is interpolated, constant beyond its ends; a law of the torque heats by torque × travel / time."""
    thermal = Thermal(100.0, 4.0, 20.0, mu_table=((20.0, 1.0), (30.0, 0.5)))
    assert thermal.factor(np.array([10.0, 20.0, 25.0, 30.0, 90.0])) == pytest.approx([1, 1, 0.75, 0.5, 0.5])
    torque = Scaled(Uniform(2.0 / 1024, 2.0 / 1024), 1024.0, "friction_torque_Nm")  # 2 N·m every cycle
    drawn = draw_series(torque, FrictionSeries(thermal=thermal), 1, 3, np.random.default_rng(0),
                        power_per_value(TRAVEL, CYCLE_S), CYCLE_S, start_C=25.0)
    assert drawn.temperature_C[0, 0] == 25.0 and drawn.values[0, 0] == pytest.approx(1.5)
    settled = 20.0 + 4.0 * 1.5 * TRAVEL / CYCLE_S
    assert drawn.temperature_C[0, 1] == pytest.approx(settled + (25.0 - settled) * math.exp(-CYCLE_S / 100.0))


@pytest.mark.parametrize("values, parameter", [
    ({"time_constant_s": 0.0}, "thermal.time_constant_s"),
    ({"resistance_K_per_W": -1.0}, "thermal.resistance_K_per_W"),
    ({"mu_per_K": None}, "thermal.mu_per_K"),
    ({"mu_per_K": None, "mu_table": ((20.0, 1.0), (20.0, 0.9))}, "thermal.mu_table[1]"),
])
def test_bad_thermal_values_are_refused_naming_them(values, parameter):
    with pytest.raises(LawError) as error:
        Thermal(**{"time_constant_s": 60.0, "resistance_K_per_W": 1.0, "mu_per_K": -0.01, **values})
    assert error.value.parameter == parameter


def test_thermal_needs_the_motion():
    with pytest.raises(LawError, match="travel per cycle") as error:
        draw_series(Constant(0.1), FrictionSeries(thermal=Thermal(60.0, 1.0, mu_per_K=0.0)), 1, 2,
                    np.random.default_rng(0))
    assert error.value.parameter == "thermal"


def test_the_settled_temperature_is_the_fixed_point_s_closed_form():
    """Thermal.settled_C ([drift] start = "warm"): T = ambient + R·P·v·(1 + k (T − ambient)), so
    T − ambient = R P v / (1 − k R P v) for a rate k per kelvin; a table's is where its factor holds it; a constant
    friction stepped from there stays there."""
    thermal = Thermal(600.0, 2.0, ambient_C=25.0, mu_per_K=-0.01)
    gain = 2.0 * 3.0 * 0.5  # R [K/W] × P [W per unit] × v
    assert thermal.settled_C(3.0, 0.5) == pytest.approx(25.0 + gain / (1 + 0.01 * gain), rel=1e-12)
    table = Thermal(600.0, 2.0, ambient_C=20.0, mu_table=((20.0, 1.0), (40.0, 0.5)))
    settled = table.settled_C(3.0, 0.5)  # ΔT = 3 (1 − ΔT / 40): 120/43 K
    assert settled == pytest.approx(20.0 + 120.0 / 43.0, rel=1e-12)
    drawn = draw_series(Constant(0.5), FrictionSeries(thermal=thermal), 1, 50, np.random.default_rng(0), 3.0,
                        CYCLE_S, thermal.settled_C(3.0, 0.5))
    assert np.allclose(drawn.temperature_C, thermal.settled_C(3.0, 0.5), rtol=1e-12, atol=0)
