"""Synthetic profiles: rms, randomness range, and the shipped reference data."""

import numpy as np
import pytest

from conftest import ROOT
from tribokin.errors import InputError
from tribokin.tribology.surfaces import read_profile
from tribokin.tribology.synthetic import REFERENCE_PROFILES, ProfileRecipe, synthetic_log, synthetic_profile
from tribokin.tribology.tribometer import read_log


@pytest.mark.parametrize("randomness", [0.0, 0.5, 1.0])
def test_rms_is_rq_for_every_randomness(randomness):
    _, z = synthetic_profile(ProfileRecipe(randomness, points=200_000, seed=5))
    assert np.sqrt(np.mean(z ** 2)) == pytest.approx(0.8e-6, rel=0.03)


def test_randomness_outside_unit_interval_refused():
    with pytest.raises(InputError, match="randomness"):
        synthetic_profile(ProfileRecipe(1.5))


@pytest.mark.parametrize("name", list(REFERENCE_PROFILES))
def test_shipped_profiles_are_what_the_generator_makes(name):
    x, z = read_profile(ROOT / "src/tribokin/data/profiles" / f"{name}.csv")
    x_expected, z_expected = synthetic_profile(REFERENCE_PROFILES[name])
    np.testing.assert_allclose(x, x_expected, rtol=1e-6, atol=1e-12)
    np.testing.assert_allclose(z, z_expected, rtol=1e-6, atol=1e-13)


def test_shipped_log_is_what_the_generator_makes():
    log = read_log(ROOT / "studies/data/tribometer-42CD4-treated-150N.csv")
    expected = synthetic_log()
    np.testing.assert_allclose(log.mu, expected["friction_force_N"] / expected["normal_force_N"], rtol=1e-6)
