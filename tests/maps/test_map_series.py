"""Maps with friction time keys (issue 38, deliverable 4): the state a map's tests start in (its start temperature
against the thermal model's closed form), a map target's sampled figures against a pose test at the same
configuration in the same state (independent streams), and a state that moves the figures."""

from __future__ import annotations

import math

import numpy as np
import pytest

from conftest import AXIS_URDF, ROOT
from tribokin import workspace_map
from tribokin.kinematics.robot import load_urdf
from tribokin.maps.pose_expected import series_expected_figures
from tribokin.maps.series_expected import series_factor
from tribokin.simulation.joint_errors import JointErrorModel
from tribokin.simulation.pose_test import PoseRunner, TestSettings, pose_task
from tribokin.study.map_spec import JointMap
from tribokin.tribology.friction_series import COLD, WARM, FrictionSeries, FrictionState, RunIn, draw_series
from tribokin.tribology.laws import Uniform
from tribokin.tribology.thermal import Thermal

LOAD_N, STIFFNESS, CYCLE_S, CYCLES = 150.0, 2e6, 6.0, 30
THERMAL = Thermal(time_constant_s=900.0, resistance_K_per_W=4.0, mu_per_K=-0.01)
#: μ uniform, lag-one correlation 0.9, run in from 0.3 over 20 cycles, warming by R·P = 4 K/W × 150 N × 1 m / 6 s
#: per unit of μ (about 12 K at μ = 0.12), μ 1 % lower per kelvin.
SERIES = FrictionSeries(ar1=0.9, run_in=RunIn(0.3, 20.0), thermal=THERMAL)
LAW = Uniform(low=0.09, high=0.15)


@pytest.fixture(scope="module")
def axis():
    return load_urdf(AXIS_URDF, "tool")


def test_the_start_temperature_is_the_thermal_models_closed_form():
    """A state ``after_s`` seconds of cycles from cold: with μ independent of temperature the warm-up under a constant
    power, T∞ + (ambient − T∞)·exp(−t/τ) (Thermal.temperature), also for a time that is not whole cycles; ``warm``
    the settled temperature, which a long warm-up reaches; the age replaces a running-in joint's own."""
    flat = Thermal(time_constant_s=900.0, resistance_K_per_W=4.0, mu_per_K=0.0)
    series = FrictionSeries(run_in=RunIn(0.3, 20.0), age_cycles=3.0, thermal=flat)
    power = LOAD_N * 1.0 / CYCLE_S  # W per unit of μ: N·travel / cycle time
    for after_s in (6.0, 903.0, 3600.0):
        aged, start = FrictionState(age_cycles=40.0, after_s=after_s).start(LAW, series, power, CYCLE_S)
        assert aged.age_cycles == 40.0
        closed = float(flat.temperature(after_s, power * LAW.mean()))
        assert start == pytest.approx(closed, rel=1e-12)
        assert start > flat.ambient_C
    assert COLD.start(LAW, series, power, CYCLE_S) == (series, None)  # cold: its own age, ambient
    _, warm = WARM.start(LAW, SERIES, power, CYCLE_S)
    assert warm == THERMAL.settled_C(power, LAW.mean())
    _, long = FrictionState(after_s=60 * THERMAL.time_constant_s).start(LAW, SERIES, power, CYCLE_S)
    assert long == pytest.approx(warm, rel=1e-12)  # stepped until settled (the rest of the hour's cycles skipped)
    _, half = FrictionState(after_s=THERMAL.time_constant_s).start(LAW, SERIES, power, CYCLE_S)
    assert THERMAL.ambient_C < half < warm


def map_and_pose(axis, state: FrictionState, seed: int = 5):
    """The axis's expected map at q = 0.2 m (a joint map of one target) and the pose test's sampled expected figures
    there, both from ``state``, from independent streams."""
    model = JointErrorModel(LAW, STIFFNESS, normal_force_N=LOAD_N, series=SERIES, travel_per_cycle=1.0)
    spec = JointMap(joints=("x",), ranges=((0.2, 0.2),), counts=(1,), directional=False, state=state)
    mapped = workspace_map(axis, [model], spec, cycles=CYCLES, seed=seed, cycle_time_s=CYCLE_S).reference
    runner = PoseRunner(TestSettings(CYCLES, seed, cycle_time_s=CYCLE_S), axis, [model], state=state)
    task = pose_task(axis, "P1", [0.2])
    pose = series_expected_figures(runner, task, runner.normal_forces(task), np.ones(1), series_factor(runner))
    return mapped, pose


@pytest.mark.parametrize("state", [FrictionState(age_cycles=5.0, after_s=600.0), WARM])
def test_a_map_target_is_the_pose_test_in_the_same_state(axis, state):
    """The map's sampled expected RP_l and AP_p at a target agree with the pose test's at the same configuration and
    state (2 000 tests each, independent streams) within 4 of their combined standard errors; the map's stated
    errors at most 1 %."""
    mapped, pose = map_and_pose(axis, state)
    for name in ("RP_l_um", "AP_p_um"):
        value, error = mapped.figure(name)[0], mapped.mc_error(name)[0]
        assert 0 < error <= 0.01, (name, error)
        assert abs(value - pose[f"expected_{name}"]) <= 4 * math.sqrt(2) * error * value, (name, value, pose)


def test_the_state_moves_the_figures(axis):
    """New and cold (the run-in's μ from 0.3, 2.5 times the steady mean) against run in (age 2 000 cycles) and warm
    (μ about 12 % lower): AP_p, the lost motion's mean, falls; RP_l too (the run-in's decay within the test spreads
    the cycles); each by far more than its Monte Carlo error. The lost motion μ̄·N/k against AP_p: the cold, new
    test's mean μ over its 30 cycles computed here from the run-in's closed form."""
    new, _ = map_and_pose(axis, FrictionState(age_cycles=0.0))
    old, _ = map_and_pose(axis, FrictionState(age_cycles=2000.0, after_s=math.inf))
    for name in ("RP_l_um", "AP_p_um"):
        a, b = new.figure(name)[0], old.figure(name)[0]
        assert a - b > 10 * (new.mc_error(name)[0] * a + old.mc_error(name)[0] * b), name
    power, temperature, mu = LOAD_N * 1.0 / CYCLE_S, THERMAL.ambient_C, []
    for cycle in range(CYCLES):  # the mean's recursion: run-in, then the factor at the cycle's temperature
        mu.append((LAW.mean() + (0.3 - LAW.mean()) * math.exp(-cycle / 20.0)) * (1 - 0.01 * (temperature - 20.0)))
        settled = 20.0 + 4.0 * power * mu[-1]
        temperature = settled + (temperature - settled) * math.exp(-CYCLE_S / 900.0)
    assert temperature > 22.0  # the warm-up within the test counts (about 3 % of μ)
    assert new.figure("AP_p_um")[0] == pytest.approx(np.mean(mu) * LOAD_N / STIFFNESS * 1e6, rel=0.01)


def test_a_directional_maps_vap_p_and_rp_l_multi_with_time_keys_are_an_independent_monte_carlos():
    """A directional map of the gantry (3 prismatic joints, fixed loads) whose joints' friction runs in, warms up and
    is correlated (ar1 0.9), from { age 5, 600 s }: its vAP_p (the three directions' tests sampled whole through the
    fast engine) and RP_l_multi (each cycle's joint signs drawn at random, the series running on) against a Monte
    Carlo computed here from draw_series and the tool's position Jacobian (exact for prismatic joints), 4 000
    independent tests each: within 4 combined standard errors."""
    gantry = load_urdf(ROOT / "urdf" / "cartesian_xyz.urdf", "tool")
    model = JointErrorModel(LAW, STIFFNESS, normal_force_N=LOAD_N, series=SERIES, travel_per_cycle=1.0)
    state, q = FrictionState(age_cycles=5.0, after_s=600.0), np.array([0.3, 0.2, 0.1])
    spec = JointMap(joints=("x",), ranges=((0.3, 0.3),), counts=(1,), start_q=tuple(q), state=state)
    mapped = workspace_map(gantry, [model] * 3, spec, cycles=CYCLES, seed=5, cycle_time_s=CYCLE_S).reference
    jacobian = gantry.tool_jacobian(q)[:3]
    power = LOAD_N * 1.0 / CYCLE_S
    series, start = state.start(LAW, SERIES, power, CYCLE_S)
    rng, tests, lever = np.random.default_rng(2024), 4000, LOAD_N / STIFFNESS

    def lost(count: int) -> np.ndarray:  # (count, cycles, 3) each joint's lost motion, its own series
        return lever * np.stack([draw_series(LAW, series, count, CYCLES, rng, power, CYCLE_S, start).values
                                 for _ in range(3)], axis=-1)

    directions = np.sign(np.round(np.linalg.pinv(jacobian) @ np.eye(3), 12)).T  # +x, +y, +z: joint signs
    barycentres = [(lost(tests) * signs).mean(axis=1) @ jacobian.T for signs in directions]
    vap = np.max([np.linalg.norm(barycentres[a] - barycentres[b], axis=1) for a, b in ((0, 1), (0, 2), (1, 2))],
                 axis=0) * 1e6
    positions = (lost(tests) * rng.choice([-1.0, 1.0], size=(tests, CYCLES, 3))) @ jacobian.T
    distances = np.linalg.norm(positions - positions.mean(axis=1, keepdims=True), axis=-1)
    multi = (distances.mean(axis=1) + 3 * distances.std(axis=1, ddof=1)) * 1e6
    for name, sampled in (("vAP_p_um", vap), ("RP_l_multi_um", multi)):
        value, error = mapped.figure(name)[0], mapped.mc_error(name)[0] * mapped.figure(name)[0]
        assert 0 < error <= 0.01 * value, (name, error)
        combined = math.hypot(error, sampled.std(ddof=1) / math.sqrt(tests))
        assert abs(value - sampled.mean()) <= 4 * combined, (name, value, sampled.mean(), combined)


def test_the_change_is_the_two_states_difference(axis):
    """``compare``: each target's change, end minus start, is the map in the second state less the map in the first,
    to the byte (the same streams); AP_p's is the lost motion's change, lever × (E μ̄ at the end − at the start),
    the means of μ over a test computed here from the run-in and the thermal model; its stated Monte Carlo error, of
    the states' paired tests, holds two seeds' changes within 4 of it and lies below the two states' errors summed
    (AP_p's by a factor of 10: both states' tests share their random numbers)."""
    start, end = FrictionState(age_cycles=0.0), FrictionState(age_cycles=2000.0, after_s=math.inf)
    model = JointErrorModel(LAW, STIFFNESS, normal_force_N=LOAD_N, series=SERIES, travel_per_cycle=1.0)

    def mapped(state, compare=None, seed=5):
        spec = JointMap(joints=("x",), ranges=((0.1, 0.3),), counts=(3,), directional=False, state=state,
                        compare=compare)
        return workspace_map(axis, [model], spec, cycles=CYCLES, seed=seed, cycle_time_s=CYCLE_S).reference

    both, first, last = mapped(start, end), mapped(start), mapped(end)
    for name, figure in (("RP_l_change_um", "RP_l_um"), ("AP_p_change_um", "AP_p_um")):
        np.testing.assert_array_equal(both.change_figure(name), last.figure(figure) - first.figure(figure))
        assert np.all(both.change_figure(name) < 0)  # run in and warm: less friction, and less spread
    power = LOAD_N * 1.0 / CYCLE_S

    def mean_mu(age: float, temperature: float) -> float:  # E μ̄ over a test, cycle by cycle
        mu = []
        for cycle in range(CYCLES):
            mu.append((LAW.mean() + (0.3 - LAW.mean()) * math.exp(-(age + cycle) / 20.0))
                      * (1 - 0.01 * (temperature - 20.0)))
            settled = 20.0 + 4.0 * power * mu[-1]
            temperature = settled + (temperature - settled) * math.exp(-CYCLE_S / 900.0)
        return float(np.mean(mu))

    warm = THERMAL.settled_C(power, LAW.mean())
    lost_um = (mean_mu(2000.0, warm) - mean_mu(0.0, 20.0)) * LOAD_N / STIFFNESS * 1e6
    np.testing.assert_allclose(both.change_figure("AP_p_change_um"), lost_um, rtol=0.01)
    other = mapped(start, end, seed=6)
    for name in ("RP_l_change_um", "AP_p_change_um"):
        error = both.change_error(name)
        assert np.all(error > 0)
        summed = sum(m.mc_error(figure) * np.abs(m.figure(figure)) for m in (first, last)
                     for figure in [name.replace("_change", "")])
        assert np.all(error < (0.1 if name == "AP_p_change_um" else 1.2) * summed), (name, error, summed)
        assert np.all(np.abs(both.change_figure(name) - other.change_figure(name)) <= 4 * math.sqrt(2) * error)


def test_a_one_test_map_with_time_keys_is_the_same_in_any_chunks():
    """A one-test map of the gantry (4 rows of 3 targets) whose joints' friction is a time series that warms up on the
    loads where the rows start: each target's test from its own stream, so the same numbers in chunks of one row as in
    one chunk; its change is the map in the second state less the map in the first, target by target (the same stream
    in both)."""
    gantry = load_urdf(ROOT / "urdf" / "cartesian_xyz.urdf", "tool")
    model = JointErrorModel(LAW, STIFFNESS, series=SERIES, travel_per_cycle=0.5)
    start, end = FrictionState(age_cycles=0.0), WARM

    def mapped(compare=None, state=start, rows=None):
        spec = JointMap(joints=("x", "y"), ranges=((0.1, 0.3), (0.0, 0.3)), counts=(3, 4), statistic="one-test",
                        state=state, compare=compare, chunk_rows=rows)
        return workspace_map(gantry, [model] * 3, spec, cycles=CYCLES, seed=2, cycle_time_s=CYCLE_S).reference

    whole, chunked = mapped(end), mapped(end, rows=1)
    np.testing.assert_array_equal(whole.figures, chunked.figures)
    np.testing.assert_array_equal(whole.read("change"), chunked.read("change"))
    change = mapped(state=end).figure("RP_l_um") - mapped().figure("RP_l_um")
    np.testing.assert_array_equal(whole.change_figure("RP_l_change_um"), change)
    assert np.all(np.isfinite(change)) and len(set(change)) == 12  # one test each: noisy, target by target
