"""The engine-bound part of a map's change between two states (``map.compare``): each change's stated bound
(``ScenarioMap.change_bound``: the two states' figure-level errors from their engines' bounds, summed) holds the
change through the first-order model within it of the same change through exact FK on the same random numbers
(``study.engine = "exact"``), so no Monte Carlo error enters the comparison. Few sampled cycles keep it cheap."""

import numpy as np
import pytest

import tribokin.maps.expected_figures as expected
from tribokin import run_study
from tribokin.maps.schema import CHANGE_FIGURES

#: A UR5 posture away from singularities [rad]; the map moves its elbow.
START_Q = [0.3, -1.2, 1.4, -1.8, -1.5, 0.4]
START, COMPARE = {"age_cycles": 0}, {"age_cycles": 5000, "after_s": "warm"}


@pytest.fixture
def few_samples(monkeypatch):
    """Sampled tests of 1 500 cycles (150 tests of 10 cycles; the RP_l band's as many more)."""
    monkeypatch.setattr(expected, "SAMPLED_CYCLES", 1500)
    monkeypatch.setattr(expected, "MAX_BAND_FACTOR", 2)
    monkeypatch.setattr(expected, "MIN_TESTS", 20)


def ur5_map(engine: str, approach: str, state: dict, compare: dict | None = None):
    """Three UR5 targets, each joint's friction running in, correlated and warming up, from ``state`` (to
    ``compare``), through ``engine``."""
    study = {"study": {"name": "change-bound", "cycles": 10, "seed": 7, "engine": engine, "approach": approach,
                       "cycle_time_s": 10.0},
             "robot": {"name": "ur5", "payload_kg": 3.0},
             "joints": {"friction": {"preset": "42CD4-treated", "ar1": 0.9, "run_in": {"start": 0.2, "tau_cycles": 20},
                                     "thermal": {"mu_per_K": -0.005}},
                        "stiffness": 1.0e5, "friction_radius_m": 0.02, "bearing_span_m": 0.08,
                        "travel_per_cycle": 1.0},
             "map": {"kind": "joint", "joints": ["elbow_joint"], "ranges": [[1.0, 1.6]], "counts": [3],
                     "start_q": START_Q, "directional": False, "state": state,
                     **({} if compare is None else {"compare": compare})}}
    return run_study(study).map.reference


def maps_of(approach: str):
    """The change through the fast engine and through exact FK, and the fast engine's two states each on its own."""
    return (ur5_map("fast", approach, START, COMPARE), ur5_map("exact", approach, START, COMPARE),
            ur5_map("fast", approach, START), ur5_map("fast", approach, COMPARE))


def differences_within_bounds(fast, exact, start, end) -> dict:
    """Assert each change's bound (RP_l's, AP_p's) is the start state's figure error plus the end state's, greater
    than 0 (exact FK's: 0), and that the change lies within it of the same change through exact FK, and of rounding
    (1e-9 µm); the differences by change."""
    differences = {}
    for name in CHANGE_FIGURES:
        bound, figure = fast.change_bound(name), name.replace("_change", "")
        np.testing.assert_array_equal(bound, start.figure_error(figure) + end.figure_error(figure))
        assert np.all(bound > 0) and np.all(exact.change_bound(name) == 0)
        differences[name] = np.abs(fast.change_figure(name) - exact.change_figure(name))
        assert np.all(differences[name] <= bound * (1 + 1e-9) + 1e-9), (name, differences[name], bound)
    return differences


@pytest.mark.parametrize("approach", ["unidirectional", "bidirectional"])
def test_a_change_through_the_first_order_model_is_within_its_stated_bound_of_exact_fks(approach, few_samples):
    """New and cold to run in and warm, where the first-order model serves both states (engine first-order, no
    fallback): each change's bound is the start state's figure error plus the end state's (each state's map on its
    own, the same streams); the change lies within it of the same change through exact FK from the same numbers.
    Approached from both directions the changed figures are the larger direction's, their errors the larger too.
    The engines' changes do differ (the comparison could fail)."""
    fast, exact, start, end = maps_of(approach)
    assert np.all(fast.read("engine") == expected.FIRST_ORDER) and np.all(fast.read("fallbacks") == 0)
    assert np.all(end.read("engine") == expected.FIRST_ORDER)
    for name, difference in differences_within_bounds(fast, exact, start, end).items():
        assert np.all(difference > 0), name


@pytest.mark.parametrize("approach", ["unidirectional", "bidirectional"])
def test_a_change_whose_states_fall_back_to_the_fast_engine_states_its_bound_and_holds_it(approach, few_samples,
                                                                                          monkeypatch):
    """Tolerance 0 (every model of both states falls back, at these ordinary joints to the fast engine): the
    change's bound is still the two states' figure errors summed, now from the fast engine's own bound (greater than
    0, where a fallback once reported 0), and the change lies within it of the same change through exact FK."""
    monkeypatch.setattr(expected, "FIGURE_TOLERANCE", 0.0)
    monkeypatch.setattr(expected, "FIGURE_FLOOR", 0.0)
    fast, exact, start, end = maps_of(approach)
    fast_engines = {expected.TARGET_ENGINES.index(name) for name in ("fast-2", "fast-3")}
    for state in (fast, start, end):
        assert set(state.read("engine")) <= fast_engines and np.all(state.read("fallbacks") > 0)
    differences_within_bounds(fast, exact, start, end)
