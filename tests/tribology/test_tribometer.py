"""Tribometer logs: reading both layouts and detecting the running-in."""

import warnings

import numpy as np
import pytest

from tribokin.errors import InputError
from tribokin.tribology.synthetic import synthetic_log
from tribokin.tribology.tribometer import read_log, running_in_cycles, steady_state


def test_forces_give_mu_and_cycle_is_optional(tmp_path):
    path = tmp_path / "log.csv"
    rows = "\n".join(f"{f},{n}" for f, n in zip(np.linspace(10, 20, 30), np.full(30, 100.0), strict=True))
    path.write_text("# a comment\nfriction_force_N,normal_force_N\n" + rows + "\n")
    log = read_log(path)
    np.testing.assert_allclose(log.mu, np.linspace(0.1, 0.2, 30))
    np.testing.assert_array_equal(log.cycle, np.arange(1, 31))


def test_steady_log_keeps_almost_every_cycle():
    mu = np.random.default_rng(4).normal(0.12, 0.01, 2000)
    assert running_in_cycles(mu) < 40


@pytest.mark.parametrize("tau", [30.0, 100.0])
def test_running_in_detected_where_the_excess_fades(tau):
    log = synthetic_log(cycles=3000, running_in_cycles=tau, seed=1)
    mu = log["friction_force_N"] / log["normal_force_N"]
    trimmed = running_in_cycles(mu)
    # excess 0.04 exp(-c/tau) falls below one sigma (0.0075) at c = tau ln(5.3), below 0.1 sigma at tau ln(53)
    assert tau * np.log(0.04 / 0.0075) * 0.5 < trimmed < tau * np.log(0.04 / 0.00075) * 1.2
    assert abs(np.mean(mu[trimmed:]) - 0.1375) < 0.001


def test_override_and_too_short(tmp_path):
    path = tmp_path / "log.csv"
    path.write_text("cycle,mu\n" + "\n".join(f"{i},0.1" for i in range(30)) + "\n")
    log = read_log(path)
    assert steady_state(log, 5)[1] == 5
    with pytest.raises(InputError, match="running_in"):
        steady_state(log, 25)


@pytest.mark.parametrize("steady, last, key", [("mu\n" + "0.1\n" * 25, "1e308", "mu"),
                                              ("friction_force_N,normal_force_N\n" + "10,100\n" * 25, "5e300,1e-10",
                                               "friction_force_N")])
def test_mu_above_ten_or_overflowing_names_the_row_without_warnings(tmp_path, steady, last, key):
    path = tmp_path / "log.csv"
    path.write_text(f"{steady}{last}\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a warning would be a second line on stderr
        with pytest.raises(InputError, match="line 27 gives mu") as error:
            read_log(path)
    assert error.value.key == key and error.value.source == str(path)
