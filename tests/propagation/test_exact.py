"""Exact engine (batched FK) against Pinocchio per sample; fast engine against the exact one, finite differences and
its own bounds."""

import os

import numpy as np
import pinocchio as pin
import pytest

from conftest import AXIS_URDF
from helpers.robots import GANTRY_URDF, screw_robot
from tribokin.kinematics.robot import load_example_robot, load_urdf
from tribokin.propagation import exact
from tribokin.propagation.exact import engine_bound, tool_deviations, tool_deviations_exact
from tribokin.propagation.poe import _exp_tail, _log_tail, tool_deviations_fast, tool_twists

NANOMETRE = 1e-9




@pytest.fixture(scope="module")
def robots():
    return {name: load_example_robot(name) for name in ("ur5", "panda")}


@pytest.fixture
def gantry_urdf(tmp_path):
    path = tmp_path / "gantry.urdf"
    path.write_text(GANTRY_URDF)
    return path


def pinocchio_deviations(robot, q, dq):
    """Tool positions [m] and rotation vectors log3(R_j R_c^T) [rad] by one Pinocchio FK call per sample."""
    commanded = robot.tool_placement(q).rotation
    placements = [robot.tool_placement(q + step) for step in dq]
    return (np.array([p.translation for p in placements]).reshape(-1, 3),
            np.array([pin.log3(p.rotation @ commanded.T) for p in placements]).reshape(-1, 3))


@pytest.mark.parametrize("name", ["ur5", "panda", "gantry with a spindle"])
def test_batched_exact_fk_matches_pinocchio_per_sample(robots, gantry_urdf, name, kernel_path, monkeypatch):
    """The batched exact engine at 5 random configurations, deviations from friction's size (1e-6) to 0.5 rad or m,
    against one Pinocchio call per sample: to 1e-12 m and rad; the small angles to 1e-9 of their size (both roundings
    of R_j R_c^T, about 1e-16 each, over an angle of 1e-6 rad); and the same bits whatever the size of the passes."""
    robot = load_urdf(gantry_urdf, tool_frame="tool") if name.startswith("gantry") else robots[name]
    rng = np.random.default_rng(14)
    for q in random_configurations(robot, 5, rng):
        for size in (1e-6, 1e-3, 0.5):
            dq = rng.uniform(-size, size, (40, robot.model.nv))
            positions, angles = tool_deviations_exact(robot, q, dq)
            expected_positions, expected_angles = pinocchio_deviations(robot, q, dq)
            np.testing.assert_allclose(positions, expected_positions, rtol=0, atol=1e-12)
            np.testing.assert_allclose(angles, expected_angles, rtol=0, atol=1e-12)
            if size == 1e-6:
                assert np.abs(angles - expected_angles).max() <= 1e-9 * np.abs(expected_angles).max()
            with monkeypatch.context() as patch:
                patch.setattr(exact, "BLOCK", 7)
                in_passes_of_7 = tool_deviations_exact(robot, q, dq)
            assert in_passes_of_7[0].tobytes() == positions.tobytes()
            assert in_passes_of_7[1].tobytes() == angles.tobytes()
    assert tool_deviations_exact(robot, q, dq[:0])[0].shape == (0, 3)
    assert os.environ["TRIBOKIN_KERNELS"] == kernel_path  # the path under test throughout


def test_a_robot_with_no_serial_chain_keeps_pinocchio_per_sample(monkeypatch):
    """A screw (a helical joint: no serial chain) through Pinocchio sample by sample: its bits, and the batched pass
    never called."""
    robot = screw_robot()
    monkeypatch.setattr(exact, "log3", None)  # the batched pass would call it
    dq = np.random.default_rng(15).uniform(-0.3, 0.3, (20, 1))
    positions, angles = tool_deviations_exact(robot, np.array([0.4]), dq)
    expected_positions, expected_angles = pinocchio_deviations(robot, np.array([0.4]), dq)
    assert positions.tobytes() == expected_positions.tobytes() and angles.tobytes() == expected_angles.tobytes()
    assert np.abs(angles[:, 2]).max() > 0.1  # it turns: the rotation vectors are compared


def random_configurations(robot, count, rng):
    """Configurations drawn uniformly within the joint limits (revolute limits capped to ±π)."""
    lower, upper = np.maximum(robot.lower_limits, -np.pi), np.minimum(robot.upper_limits, np.pi)
    return [rng.uniform(lower, upper) for _ in range(count)]


def errors(robot, q, dq, **options):
    """Largest fast-vs-exact position [m] and angle [rad] differences, and the fast engine's bound."""
    fast = tool_deviations_fast(robot, q, dq, **options)
    positions, angles = tool_deviations_exact(robot, q, dq)
    return (np.linalg.norm(fast.positions - positions, axis=1).max(),
            np.linalg.norm(fast.angles - angles, axis=1).max(), fast.bound)


@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_fast_matches_exact_on_arms(robots, name):
    robot = robots[name]
    rng = np.random.default_rng(7)
    for q in random_configurations(robot, 4, rng):
        dq = rng.uniform(-1e-3, 1e-3, (64, robot.model.nv))
        position_error, angle_error, bound = errors(robot, q, dq)
        assert position_error <= NANOMETRE  # measured ≈ 1e-12 m at order 3
        assert angle_error <= 1e-9  # measured ≈ 5e-13 rad at order 3
        assert bound.order == 3  # 1e-3 rad on every joint needs the cubic terms for 1e-10
        assert position_error <= bound.position_m and angle_error <= bound.angle_rad


def test_prismatic_axis_is_exact_at_first_order():
    robot = load_urdf(AXIS_URDF, tool_frame="tool")
    dq = np.random.default_rng(1).uniform(-1e-3, 1e-3, (50, 1))
    position_error, angle_error, bound = errors(robot, np.array([0.2]), dq)
    assert bound == (1, 0.0, 0.0)  # a translation is linear in dq: nothing truncated
    assert position_error <= 1e-15 and angle_error <= 1e-15  # float64 rounding


def test_gantry_with_rotary_wrist(gantry_urdf):
    robot = load_urdf(gantry_urdf, tool_frame="tool")
    rng = np.random.default_rng(2)
    q = np.array([0.7, 0.4, 0.2, 0.5])
    dq = rng.uniform(-1e-3, 1e-3, (64, 4))
    position_error, angle_error, bound = errors(robot, q, dq)
    assert position_error <= NANOMETRE and angle_error <= 1e-9
    assert position_error <= bound.position_m and angle_error <= bound.angle_rad


def test_gantry_translation_axes_need_no_truncation(gantry_urdf):
    robot = load_urdf(gantry_urdf, tool_frame="flange")  # the x, y, z axes only
    dq = np.random.default_rng(3).uniform(-1e-3, 1e-3, (64, 3))
    position_error, angle_error, bound = errors(robot, np.array([0.7, 0.4, 0.2]), dq)
    assert bound == (1, 0.0, 0.0)
    assert position_error <= 1e-15 and angle_error <= 1e-15  # float64 rounding


@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_twists_are_finite_differences_of_pinocchio_fk(robots, name):
    robot = robots[name]
    step = 1e-6
    for q in random_configurations(robot, 3, np.random.default_rng(4)):
        commanded = robot.tool_placement(q)
        for i in range(robot.model.nv):
            shift = np.zeros(robot.model.nv)
            shift[i] = step
            plus, minus = robot.tool_placement(q + shift), robot.tool_placement(q - shift)
            velocity = (plus.translation - minus.translation) / (2 * step)
            rotation = (pin.log3(plus.rotation @ commanded.rotation.T)
                        - pin.log3(minus.rotation @ commanded.rotation.T)) / (2 * step)
            np.testing.assert_allclose(tool_twists(robot, q)[:, i], np.concatenate([velocity, rotation]),
                                       rtol=0, atol=1e-8)


@pytest.mark.parametrize("order", [1, 2, 3])
def test_error_shrinks_like_the_next_power_and_stays_below_the_bound(robots, order):
    robot = robots["ur5"]
    rng = np.random.default_rng(5)
    q = random_configurations(robot, 1, rng)[0]
    direction = rng.uniform(-1.0, 1.0, (16, robot.model.nv))
    measured = []
    for scale in (1e-2, 5e-3):
        position_error, angle_error, bound = errors(robot, q, scale * direction, order=order)
        assert position_error <= bound.position_m and angle_error <= bound.angle_rad
        measured.append((position_error, angle_error))
    (position_big, angle_big), (position_half, angle_half) = measured
    expected = 2.0 ** (order + 1)
    assert expected * 0.85 <= position_big / position_half <= expected * 1.15
    assert expected * 0.85 <= angle_big / angle_half <= expected * 1.15


def test_bound_holds_for_large_deviations(robots, kernel_path):
    robot = robots["panda"]
    rng = np.random.default_rng(6)
    for q in random_configurations(robot, 3, rng):
        dq = rng.uniform(-0.05, 0.05, (32, robot.model.nv))
        for order in (1, 2, 3):
            position_error, angle_error, bound = errors(robot, q, dq, order=order)
            assert position_error <= bound.position_m and angle_error <= bound.angle_rad


@pytest.mark.parametrize("s", [0.01, 0.1, 0.3])
def test_bound_series_tails_match_their_closed_forms(s):
    """Series of coefficients (1/m!, Fubini numbers) against e^s and -log(2 - e^s) minus their first terms."""
    assert _exp_tail(s, 2) == pytest.approx(np.expm1(s) - s, rel=1e-12)
    assert _log_tail(s, 2) == pytest.approx(-np.log(2.0 - np.exp(s)) - s, rel=1e-9)
    assert _log_tail(s, 4) == pytest.approx(-np.log(2.0 - np.exp(s)) - s - s**2 - s**3, rel=1e-6)


def test_bound_series_tails_of_several_orders_at_once_are_each_orders_sum():
    """Tails for an array of starts (a last axis) against the series summed term by term, for each start."""
    import math

    s = np.array([[0.01, 0.3], [0.05, 2.0], [0.5, 12.0]])  # about the series' radii 0.3 (log) and 10 (exp)
    starts = np.array([2, 3, 4])
    tails = _exp_tail(s, starts)
    for k, start in enumerate(starts):
        for index, value in np.ndenumerate(s):
            expected = math.fsum(value ** m / math.factorial(m) for m in range(start, 120))
            assert tails[index + (k,)] == pytest.approx(expected, rel=1e-12)
    logs = _log_tail(s, starts)
    assert np.isinf(logs[1, 1]).all() and not np.isinf(logs[0]).any()
    for k, start in enumerate(starts):
        assert logs[..., k][np.isfinite(logs[..., k])] == pytest.approx(
            [float(_log_tail(value, int(start))) for value in s.ravel() if value < math.log(2.0)], rel=1e-12)


def test_angle_bound_is_infinite_past_the_log_series_radius(robots):
    robot = robots["ur5"]
    dq = np.full((1, robot.model.nv), 0.2)  # Σ|ω_i||dq_i| = 1.2 rad > ln 2
    assert tool_deviations_fast(robot, np.zeros(robot.model.nv), dq).bound.angle_rad == np.inf


@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_zero_deviation_gives_exactly_the_commanded_pose(robots, name):
    robot = robots[name]
    q = random_configurations(robot, 1, np.random.default_rng(8))[0]
    fast = tool_deviations_fast(robot, q, np.zeros((30, robot.model.nv)))
    assert np.array_equal(fast.positions, np.tile(robot.tool_placement(q).translation, (30, 1)))
    assert np.array_equal(fast.angles, np.zeros((30, 3)))
    assert fast.bound.position_m == 0.0 and fast.bound.angle_rad == 0.0


def test_empty_batch(robots):
    fast = tool_deviations_fast(robots["ur5"], np.zeros(6), np.zeros((0, 6)))
    assert fast.positions.shape == (0, 3) and fast.angles.shape == (0, 3)


@pytest.mark.parametrize("size, engine", [(2e-6, "fast"), (2e-3, "exact")])
def test_the_engine_bound_is_that_of_the_engine_used_over_every_sample(robots, size, engine):
    """Friction-sized deviations: the fast engine, its bound holding against exact FK on every sample; deviations
    past its tolerance: exact FK, bound 0 (not the bound of an engine that was not used)."""
    robot = robots["panda"]
    rng = np.random.default_rng(9)
    q = random_configurations(robot, 1, rng)[0]
    dq = rng.uniform(-size, size, (100, robot.model.nv))
    used = engine_bound(robot, q, dq)
    assert used.engine == engine
    positions, angles = tool_deviations(robot, q, dq)
    exact_positions, exact_angles = tool_deviations_exact(robot, q, dq)
    assert np.linalg.norm(positions - exact_positions, axis=1).max() <= used.position_m + 1e-15
    assert np.linalg.norm(angles - exact_angles, axis=1).max() <= used.angle_rad + 1e-15
    assert (used.order > 0 and used.position_m > 0) if engine == "fast" else used == (engine, 0, 0.0, 0.0)


def test_dq_of_the_wrong_width_is_refused(robots):
    with pytest.raises(ValueError, match=r"\(n, 6\)"):
        tool_deviations_fast(robots["ur5"], np.zeros(6), np.zeros((3, 7)))


@pytest.mark.parametrize("engine", ["fast", "exact"])
def test_poses_propagated_together_match_each_alone(robots, engine):
    """A batch mixing orders (and, for "fast", one pose past the bound, sent to exact FK) gives
    every pose what it gets on its own."""
    from tribokin.propagation.exact import tool_deviations, tool_deviations_at_poses, tool_frames

    robot = robots["ur5"]
    rng = np.random.default_rng(4)
    qs = np.array(random_configurations(robot, 4, rng))
    dq = np.stack([scale * rng.standard_normal((50, robot.model.nv)) for scale in (1e-7, 1e-5, 1e-4, 0.2)])
    twists, translations = tool_frames(robot, qs)
    positions, angles = tool_deviations_at_poses(robot, qs, dq, engine, twists, translations)
    for q, samples, p, a in zip(qs, dq, positions, angles, strict=True):
        alone_p, alone_a = tool_deviations(robot, q, samples, engine)
        np.testing.assert_allclose(p, alone_p, rtol=0, atol=1e-15)
        np.testing.assert_allclose(a, alone_a, rtol=0, atol=1e-15)


def test_bounds_of_several_poses_are_each_poses_bound(robots, kernel_path):
    from tribokin.propagation.poe import truncation_bound

    robot = robots["panda"]
    rng = np.random.default_rng(5)
    qs = random_configurations(robot, 3, rng)
    twists = np.array([tool_twists(robot, q) for q in qs])
    dq = np.stack([scale * rng.standard_normal((40, robot.model.nv)) for scale in (1e-6, 1e-4, 0.5)])
    together = truncation_bound(twists, dq)
    for k in range(3):
        alone = truncation_bound(twists[k], dq[k])
        assert together.order[k] == alone.order
        assert together.position_m[k] == pytest.approx(alone.position_m, rel=1e-12)
        assert together.angle_rad[k] == pytest.approx(alone.angle_rad, rel=1e-12)
    assert list(together.order) == [2, 3, 3] and np.isinf(together.angle_rad[2])


@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_the_compiled_bounds_agree_with_numpy(robots, name, monkeypatch):
    """The compiled bounds after each order (:mod:`tribokin.propagation.poe_kernels`) against the NumPy path, at
    deviations from none to 3 rad (about and past each series' radius) on 40 poses of a few samples: to 1e-12."""
    from tribokin.propagation.poe import _order_bounds

    robot = robots[name]
    rng = np.random.default_rng(12)
    twists = np.array([tool_twists(robot, q) for q in random_configurations(robot, 40, rng)])
    for size in (0.0, 1e-300, 1e-9, 1e-5, 1e-3, 0.05, 0.3, 3.0):
        dq = rng.uniform(-size, size, (40, 5, robot.model.nv))
        monkeypatch.setenv("TRIBOKIN_KERNELS", "numpy")
        reference = _order_bounds(twists, dq)
        monkeypatch.setenv("TRIBOKIN_KERNELS", "compiled")
        for compiled, expected in zip(_order_bounds(twists, dq), reference, strict=True):
            assert np.array_equal(np.isinf(compiled), np.isinf(expected))
            finite = np.isfinite(expected)
            np.testing.assert_allclose(compiled[finite], expected[finite], rtol=1e-12, atol=0)



@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_the_compiled_first_order_model_bounds_agree_with_numpy(robots, name, monkeypatch):
    """The first-order model's three bounds compiled against the NumPy path on 40 poses, deviations from none to
    3 rad, about a mean deviation of none (the mixed model's: no composition, 0 or, past the series' radius, inf) or
    of the same size: to 1e-12, infinite where NumPy's are."""
    from tribokin.propagation.poe import first_order_model_bounds

    robot = robots[name]
    rng = np.random.default_rng(14)
    twists = np.array([tool_twists(robot, q) for q in random_configurations(robot, 40, rng)])
    for size in (0.0, 1e-9, 1e-3, 0.05, 0.3, 3.0):
        departure = rng.uniform(0, size, (40, robot.model.nv))
        for mean_dq in (np.zeros((40, robot.model.nv)), rng.uniform(-size, size, (40, robot.model.nv))):
            results = {}
            for path in ("numpy", "compiled"):
                monkeypatch.setenv("TRIBOKIN_KERNELS", path)
                results[path] = first_order_model_bounds(twists, departure, mean_dq)
            for compiled, expected in zip(results["compiled"], results["numpy"], strict=True):
                assert np.array_equal(np.isinf(compiled), np.isinf(expected))
                finite = np.isfinite(expected)
                np.testing.assert_allclose(compiled[finite], expected[finite], rtol=1e-12, atol=0)

def test_deviations_too_large_for_any_series_are_bounded_by_infinity_not_nan(robots, kernel_path):
    """Deviations of 1e5 to 1e200 rad overflow the series' terms: the bounds are infinite (so exact FK is used), not
    NaN (which no tolerance refuses)."""
    from tribokin.propagation.poe import truncation_bound

    robot = robots["ur5"]
    twists = tool_twists(robot, random_configurations(robot, 1, np.random.default_rng(13))[0])
    for size in (1e5, 1e200):
        bound = truncation_bound(twists, np.full((2, robot.model.nv), size))
        assert bound.position_m == np.inf and bound.angle_rad == np.inf
    assert engine_bound(robot, np.zeros(robot.model.nv), np.full((2, robot.model.nv), 1e200)).engine == "exact"


@pytest.mark.parametrize("kernels", ["numpy", "compiled"])
@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_the_first_order_bounds_hold_against_exact_fk_and_are_tighter_than_the_majorants(robots, name, kernels,
                                                                                        monkeypatch):
    """On both kernel paths, at 20 random configurations, deviations at every corner of a box of ±2e-4 rad per joint
    (and random points in it): |first order - exact FK| within :func:`first_order_model_bounds` in position and
    rotation vector, and those within the order-1 truncation bound, several times below it on both robots' parallel
    or offset axes."""
    from tribokin.propagation.poe import first_order_model_bounds, truncation_bound

    monkeypatch.setenv("TRIBOKIN_KERNELS", kernels)
    robot, rng = robots[name], np.random.default_rng(12)
    nv = robot.model.nv
    corners = np.array(np.meshgrid(*[[-1.0, 1.0]] * nv)).reshape(nv, -1).T
    ratios = []
    for q in random_configurations(robot, 20, rng):
        departure = rng.uniform(0.5e-4, 2e-4, nv)
        deltas = np.vstack([corners, rng.uniform(-1, 1, (64, nv))]) * departure
        twists = tool_twists(robot, q)
        positions, angles = tool_deviations_exact(robot, q, deltas)
        position_bound, angle_bound, _ = (value[0] for value in first_order_model_bounds(
            twists[None], departure[None], np.zeros((1, nv))))
        linear = robot.tool_placement(q).translation + deltas @ twists[:3].T
        assert np.linalg.norm(positions - linear, axis=1).max() <= position_bound
        assert np.linalg.norm(angles - deltas @ twists[3:].T, axis=1).max() <= angle_bound + 1e-18
        majorant = truncation_bound(twists, departure[None], order=1)
        assert position_bound <= majorant.position_m and angle_bound <= majorant.angle_rad
        ratios.append((majorant.position_m / position_bound, majorant.angle_rad / angle_bound))
    assert np.median(ratios, axis=0).min() > 1.5
