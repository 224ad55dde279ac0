"""Seeds: the same seed gives the same numbers, run after run; another seed other numbers."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import axis_study
from tribokin import run_study

seeds = st.integers(0, 2 ** 63 - 1)


def _study(seed: int, approach: str) -> dict:
    study = axis_study(friction={"law": "gaussian", "mean": 0.1, "std": 0.02}, noise_std=1e-7)
    study["study"].update(seed=seed, approach=approach, cycles=15)
    return study


@settings(max_examples=5)
@given(seeds, st.sampled_from(["unidirectional", "random"]))
def test_same_seed_same_numbers_other_seed_other_numbers(seed, approach):
    first, again = run_study(_study(seed, approach)), run_study(_study(seed, approach))
    for name in ("positions_m", "mu", "dq", "approach"):
        np.testing.assert_array_equal(getattr(first.poses[0], name), getattr(again.poses[0], name))
    assert first.summary() == again.summary()
    other = run_study(_study(seed + 1, approach))
    assert not np.array_equal(first.poses[0].mu, other.poses[0].mu)
