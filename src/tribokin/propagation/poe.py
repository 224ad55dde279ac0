"""Fast engine: joint deviations to tool pose by a truncated product of exponentials.

For 1-DoF screw joints (revolute, prismatic) the pose reached at ``q + dq`` is exactly

    T(q + dq) = exp(X_1 dq_1) exp(X_2 dq_2) ... exp(X_n dq_n) T(q),

with ``X_i = [[ω̂_i, v_i], [0, 0]]`` the twist of joint i at ``q`` written in a frame A at the
tool origin with world axes: column i of Pinocchio's ``LOCAL_WORLD_ALIGNED`` tool-frame Jacobian,
``v_i`` the velocity of the tool origin [m/rad or m/m] and ``ω_i`` the angular velocity
[rad/rad or rad/m]. In A the tool origin is ``e = (0, 0, 0, 1)``, so with ``P(dq)`` the product:

    position deviation  = ((P(dq) - I) e)[:3]            [m]
    orientation         = vee(log R(dq)), R = P[:3, :3]  [rad], world axes

Both are power series in ``dq``. Truncated at total degree K they are polynomials: one
coefficient 6-vector per monomial ``dq^α`` with ``1 <= |α| <= K``, computed once per pose. A batch
of samples is then one product ``features(dq) @ coefficients``; the orientation comes from the
series of the matrix logarithm (to second order it is the BCH formula
``Σ ω_i dq_i + ½ Σ_{i<j} ω_i × ω_j dq_i dq_j``).

Truncation bounds, rigorous for any sample (norms are 2-norms; ‖ω̂‖ = |ω|):

- position, from the 4×4 operator norm ‖X_i‖ <= c_i = sqrt(|ω_i|² + |v_i|²): the degree-m part of
  P has norm <= s^m/m! with s = Σ c_i |dq_i| (multinomial theorem), so the error after order K is
  <= e^s - Σ_{m<=K} s^m/m!;
- position, from the structure ``(P - I) e = Σ_i R_1⋯R_{i-1} φ(ω̂_i dq_i) v_i dq_i`` with
  φ(x) = (e^x - 1)/x: the error after order K is <= b · (e^w - Σ_{m<K} w^m/m!) with
  b = Σ |v_i||dq_i| and w = Σ |ω_i||dq_i|. It is zero for prismatic chains (exactly linear);
  the engine reports the smaller of the two;
- orientation: the degree-m parts of R - I are bounded by those of e^w - 1, so those of
  log R = Σ_k (-1)^{k+1} (R - I)^k / k by those of -log(2 - e^w) = Σ_m 2 F_{m-1} w^m/m!
  (F the ordered Bell numbers), and the error after order K is that series' tail (valid for
  w < ln 2).

Bounds cover truncation only; float64 rounding adds ~1e-15 m and ~1e-16 rad.
"""

from __future__ import annotations

import math
from fractions import Fraction
from functools import cache
from itertools import combinations_with_replacement, product
from typing import NamedTuple

import numpy as np

from tribokin.compiled import use_compiled
from tribokin.kinematics.robot import Robot

#: Highest truncation order the engine expands to.
MAX_ORDER = 3
#: Default truncation tolerance on the tool position [m] and on the orientation [rad].
DEFAULT_TOLERANCE = 1e-10
#: Samples evaluated together: features of a chunk stay in cache.
CHUNK_SAMPLES = 4096


class TruncationBound(NamedTuple):
    """Worst-case truncation error of the fast engine over a batch of samples (arrays over the
    poses when several poses are bounded at once).

    Attributes:
        order: total degree K of the polynomial in ``dq`` used.
        position_m: bound on |fast - exact| tool position [m].
        angle_rad: bound on |fast - exact| rotation vector [rad] (``inf`` past its validity).
    """

    order: int
    position_m: float
    angle_rad: float


class FastDeviations(NamedTuple):
    """Output of :func:`tool_deviations_fast`.

    Attributes:
        positions: (n, 3) tool positions in the world frame [m].
        angles: (n, 3) rotation vectors ``log3(R_j R_c^T)`` in world axes [rad].
        bound: truncation order used and its error bounds.
    """

    positions: np.ndarray
    angles: np.ndarray
    bound: TruncationBound


def tool_twists(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Joint twists at ``q`` about the tool origin, in world axes.

    Returns:
        (6, nv) array, column i = (v_i; ω_i): velocity of the tool origin [m/rad or m/m] and
        angular velocity [rad/rad or rad/m] per unit speed of joint i (the tool frame's
        ``LOCAL_WORLD_ALIGNED`` Jacobian).
    """
    return robot.tool_jacobian(q)


# --- truncation bounds --------------------------------------------------------------------------

_TERMS = 60
#: Taylor coefficients of exp(s): 1/m!.
_EXP_COEFFICIENTS = np.array([1.0 / math.factorial(m) for m in range(_TERMS)])


def _log_majorant_coefficients() -> np.ndarray:
    """Taylor coefficients of -log(2 - e^s) = Σ_{m>=1} 2 F_{m-1} s^m / m! - s (F: ordered Bell numbers).

    From d/ds = e^s / (2 - e^s) = 2 / (2 - e^s) - 1 and 1 / (2 - e^s) = Σ F_m s^m / m!.
    """
    fubini = [1]
    for n in range(1, _TERMS):
        fubini.append(sum(math.comb(n, j) * fubini[n - j] for j in range(1, n + 1)))
    coefficients = [0.0] + [float(Fraction(2 * fubini[m - 1], math.factorial(m))) for m in range(1, _TERMS)]
    coefficients[1] -= 1.0
    return np.array(coefficients)


_LOG_COEFFICIENTS = _log_majorant_coefficients()


#: The series are summed term by term up to these |s| (their first _TERMS terms then hold the tail to double
#: precision), and beyond from their closed forms less their first terms (which cancel little there).
_EXP_RADIUS, _LOG_RADIUS = 10.0, 0.3


def _series_tail(coefficients: np.ndarray, closed_form, radius: float, s, start, horner: bool = False) -> np.ndarray:
    """Σ_{m >= start} c_m s^m of a series with non-negative coefficients, without cancellation: term by term up to
    |s| = ``radius`` (with ``horner``, an int ``start``: by Horner's rule, some 50 times faster), else
    ``closed_form(s)`` less the first terms (``s``: any array shape, element-wise; ``start``: an int, or a 1-D array
    of them, giving a last axis)."""
    s = np.asarray(s, dtype=float)
    terms = np.arange(_TERMS)
    kept = terms[:, None] >= np.atleast_1d(start)  # (_TERMS, starts)
    if horner:  # the terms past where s^m (the coefficients grow at most about 1.5^m) falls 40 decades are dropped
        clipped, small = np.minimum(s, radius), np.zeros(s.shape)
        largest = 1.5 * float(np.max(clipped, initial=0.0))
        stop = _TERMS if largest >= 0.1 else min(_TERMS, start + 1 + math.ceil(40 / -math.log10(max(largest, 1e-300))))
        for coefficient in coefficients[start:stop][::-1]:
            small = small * clipped + coefficient
        small = (small * clipped ** start)[..., None]
    else:
        small = np.minimum(s, radius)[..., None] ** terms @ np.where(kept, coefficients[:, None], 0.0)
    if np.all(s <= radius):
        tail = small
    else:
        with np.errstate(over="ignore", invalid="ignore"):
            terms_at = np.maximum(s, radius)[..., None, None] ** terms[:, None] * coefficients[:, None]
            head = np.where(kept, 0.0, terms_at).sum(axis=-2)  # no overflowed term of the tail in it
            rest = np.where(np.isinf(head), np.inf, closed_form(s)[..., None] - head)  # s^start overflows too
            tail = np.where(s[..., None] <= radius, small, rest)
    return tail if np.ndim(start) else tail[..., 0]


def _exp_tail(s, start, horner: bool = False) -> np.ndarray:
    """Σ_{m >= start} s^m / m!."""
    return _series_tail(_EXP_COEFFICIENTS, np.exp, _EXP_RADIUS, s, start, horner)


def _log_tail(w, start, horner: bool = False) -> np.ndarray:
    """Σ_{m >= start} of the series of -log(2 - e^w); ``inf`` for w >= ln 2 (no convergence)."""
    w = np.asarray(w, dtype=float)
    converging = w < math.log(2.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        tail = _series_tail(_LOG_COEFFICIENTS, lambda x: -np.log(2.0 - np.exp(x)), _LOG_RADIUS,
                            np.where(converging, w, 0.0), start, horner)
    return np.where(converging if np.ndim(start) == 0 else converging[..., None], tail, np.inf)


class _BatchNorms(NamedTuple):
    """Maxima over the samples of each pose of the weighted deviation sums that the bounds need."""

    full: np.ndarray  # s = max Σ sqrt(|ω_i|² + |v_i|²) |dq_i|
    linear: np.ndarray  # b = max Σ |v_i| |dq_i| [m]
    angular: np.ndarray  # w = max Σ |ω_i| |dq_i| [rad]


def _batch_norms(twists: np.ndarray, dq: np.ndarray) -> _BatchNorms:
    """Norms of (..., 6, nv) twists and (..., n, nv) deviations, one value per pose (shape ...)."""
    linear = np.linalg.norm(twists[..., :3, :], axis=-2)
    angular = np.linalg.norm(twists[..., 3:, :], axis=-2)
    weights = np.stack([np.hypot(linear, angular), linear, angular], axis=-2)  # (..., 3, nv)
    if not dq.shape[-2]:
        return _BatchNorms(*np.zeros((3,) + dq.shape[:-2]))
    sums = weights @ np.swapaxes(np.abs(dq), -1, -2)  # (..., 3, n): row reductions are fast
    return _BatchNorms(*np.moveaxis(sums.max(axis=-1), -1, 0))


def _order_bounds(twists: np.ndarray, dq: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The position [m] and angle [rad] bounds (..., ``MAX_ORDER``) after each order 1 to ``MAX_ORDER``, of (..., 6, nv)
    twists and (..., n, nv) deviations; compiled where :func:`~tribokin.compiled.use_compiled`."""
    if use_compiled():
        from tribokin.propagation import poe_kernels

        batch = np.broadcast_shapes(twists.shape[:-2], dq.shape[:-2])
        flat_twists, flat_dq = (np.ascontiguousarray(np.broadcast_to(a, batch + a.shape[-2:]).reshape(
            (math.prod(batch),) + a.shape[-2:])) for a in (twists, dq))
        position, angle = poe_kernels.order_bounds(flat_twists, flat_dq, MAX_ORDER, _EXP_COEFFICIENTS,
                                                   _LOG_COEFFICIENTS, _EXP_RADIUS, _LOG_RADIUS)
        return position.reshape(batch + (MAX_ORDER,)), angle.reshape(batch + (MAX_ORDER,))
    norms = _batch_norms(twists, dq)
    orders = np.arange(1, MAX_ORDER + 1)  # every order at once, along a last axis
    position = np.minimum(_exp_tail(norms.full, orders + 1), norms.linear[..., None] * _exp_tail(norms.angular, orders))
    return position, _log_tail(norms.angular, orders + 1)


def truncation_bound(twists: np.ndarray, dq: np.ndarray, order: int | None = None,
                     tolerance_m: float = DEFAULT_TOLERANCE, tolerance_rad: float = DEFAULT_TOLERANCE,
                     lowest_order: int = 1) -> TruncationBound:
    """Truncation order and error bounds of the fast engine for a batch of deviations at one pose,
    or for batches at several poses (then each field is an array over the poses).

    Args:
        twists: (6, nv) joint twists about the tool origin (:func:`tool_twists`), or (poses, 6, nv).
        dq: (n, nv) joint deviations [m or rad], or (poses, n, nv).
        order: force this order (1 to ``MAX_ORDER``); by default the lowest order from ``lowest_order`` on whose
            bounds meet both tolerances, or ``MAX_ORDER`` when none does (check the returned bound).
        tolerance_m: tolerated position error [m].
        tolerance_rad: tolerated orientation error [rad].
        lowest_order: the lowest order chosen by default.
    """
    if order is not None and not 1 <= order <= MAX_ORDER:
        raise ValueError(f"order must be 1 to {MAX_ORDER}, got {order}")
    position, angle = _order_bounds(np.asarray(twists, dtype=float), np.asarray(dq, dtype=float))
    if order is None:  # the lowest order meeting both tolerances, else the highest
        met = (position <= tolerance_m) & (angle <= tolerance_rad) & (np.arange(1, MAX_ORDER + 1) >= lowest_order)
        chosen = np.where(met.any(axis=-1), met.argmax(axis=-1), MAX_ORDER - 1)
    else:
        chosen = np.full(position.shape[:-1], order - 1)
    bound = TruncationBound(chosen + 1, *(np.take_along_axis(a, chosen[..., None], axis=-1)[..., 0]
                                          for a in (position, angle)))
    if np.ndim(bound.order) == 0:
        return TruncationBound(int(bound.order), float(bound.position_m), float(bound.angle_rad))
    return bound


def _cross_norms(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(k, n, m) |a_i × b_j| of (k, n, 3) and (k, m, 3) vectors."""
    a, b = a[:, :, None, :], b[:, None, :, :]
    x = a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1]
    y = a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2]
    z = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return np.sqrt(x * x + y * y + z * z)


def first_order_model_bounds(twists: np.ndarray, departure: np.ndarray, mean_dq: np.ndarray
                             ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(k,) bounds of the first-order model about q″ = q + E[dq] with (k, 6, nv) twists at q″, over deviations from
    E[dq] within ``departure`` (k, nv), E[dq] = ``mean_dq`` (k, nv): on the position's [m] and the rotation vector's
    [rad] errors after order 1 (tighter than :func:`truncation_bound`'s order 1, whose degree-2 terms count every pair
    of joints at its largest, where axes are (nearly) parallel or pass near the tool), and the angle's further terms
    [rad] when the rotation x of a deviation is composed with c, that from q's orientation to q″'s, as
    c + x + x × c̃ / 2, c̃ = Σ ω_i E[dq_i]: :func:`composition_bound` and |x| |c - c̃| / 2. Compiled where
    :func:`~tribokin.compiled.use_compiled`.

    The product's degree-2 part is exact: Σ_i X_i² dq_i² / 2 + Σ_{i<j} X_i X_j dq_i dq_j, which moves the tool origin
    by Σ_i (ω_i × v_i) dq_i² / 2 + Σ_{i<j} (ω_i × v_j) dq_i dq_j; its logarithm's, ½ Σ_{i<j} (ω_i × ω_j) dq_i dq_j
    (``[ω̂_i, ω̂_j]`` is ``(ω_i × ω_j)^``). Each is bounded term by term; the parts from degree 3 on by the tails of
    the module's majorants after order 2 (``inf`` past ln 2 in angle)."""
    if use_compiled():
        from tribokin.propagation import poe_kernels

        return poe_kernels.first_order_model_bounds(*(np.ascontiguousarray(a, dtype=float) for a in (
            twists, departure, mean_dq)), _EXP_COEFFICIENTS, _LOG_COEFFICIENTS, _EXP_RADIUS, _LOG_RADIUS)
    linear, rates = np.swapaxes(twists[:, :3], 1, 2), np.swapaxes(twists[:, 3:], 1, 2)  # (k, nv, 3) each
    speeds, turns = (np.sqrt(np.einsum("kni,kni->kn", v, v)) for v in (linear, rates))  # |v_i|, |ω_i|
    later = np.triu(np.ones((twists.shape[-1],) * 2), 1)  # i < j
    moved = _cross_norms(rates, linear) * (later + 0.5 * np.eye(len(later)))  # |ω_i × v_j|, i <= j
    turned = _cross_norms(rates, rates) * (0.5 * later)
    position, angle = (np.sum((departure[:, None, :] @ weights)[:, 0] * departure, axis=1)
                       for weights in (moved, turned))
    full, speed, turn = (np.sum(norm * departure, axis=1) for norm in (np.hypot(speeds, turns), speeds, turns))
    mean = np.sum(turns * np.abs(mean_dq), axis=1)
    rest = np.minimum(_exp_tail(full, 3, True), speed * _exp_tail(turn, 2, True))
    size, miss = _log_tail(turn, 1, True), _log_tail(mean, 2, True)  # |x|, |c - c̃|
    twice = np.multiply(size, miss, out=np.zeros_like(miss), where=miss > 0)  # |x| |c - c̃|: 0 where c = 0 (|x| inf)
    return position + rest, angle + _log_tail(turn, 3, True), composition_bound(turn, mean) + twice / 2


def composition_bound(first_rad, second_rad) -> np.ndarray:
    """Bound [rad] on |log(R_x R_c) - x - c - x × c / 2| for rotations R_x, R_c that are each a product of joint
    rotations exp(ω̂_i dq_i) of weighted sums Σ |ω_i| |dq_i| <= ``first_rad``, ``second_rad`` (element-wise; ``inf``
    past ln 2). Their rotation vectors x, c are at most u, v, the sums' series M(w) = -log(2 - e^w) (the orientation
    bound's majorant). In log(e^x̂ e^ĉ) = x̂ + ĉ + [x̂, ĉ] / 2 + ... the words of x̂ alone sum to x̂ and those of ĉ
    alone to ĉ; the other words of degree 3 and more are bounded by the same terms of M(u + v), less those of M(u)
    and M(v)."""
    u, v = _log_tail(np.stack([first_rad, second_rad]), 1, True)
    with np.errstate(invalid="ignore"):
        both, first, second = _log_tail(np.stack([u + v, u, v]), 3, True)
        return np.where(np.isfinite(both), np.maximum(both - first - second, 0.0), np.inf)  # inf from u + v = ln 2


# --- the polynomial -----------------------------------------------------------------------------

@cache
def _monomials(nv: int, degree: int) -> tuple[tuple[int, ...], ...]:
    """Sorted index tuples of the monomials of one degree, in lexicographic order."""
    return tuple(combinations_with_replacement(range(nv), degree))


def _ordered_weight(word: tuple[int, ...]) -> float:
    """Coefficient of X_word in exp(X_1 dq_1)⋯exp(X_n dq_n): 1/Π(multiplicity!) if non-decreasing, else 0."""
    if list(word) != sorted(word):
        return 0.0
    return 1.0 / math.prod(math.factorial(word.count(i)) for i in set(word))


def _logarithm_weight(word: tuple[int, ...]) -> float:
    """Coefficient of X_word in log(exp(X_1 dq_1)⋯exp(X_n dq_n)).

    From log(I + M) = Σ_k (-1)^{k+1} M^k / k with M = P - I: every cut of the word into k
    non-empty consecutive pieces contributes the product of the pieces' ordered weights.
    """
    total = 0.0
    for cuts in product((False, True), repeat=len(word) - 1):
        bounds = [0] + [i + 1 for i, cut in enumerate(cuts) if cut] + [len(word)]
        pieces = [word[a:b] for a, b in zip(bounds, bounds[1:], strict=False)]
        total += (-1) ** (len(pieces) + 1) / len(pieces) * math.prod(_ordered_weight(p) for p in pieces)
    return total


@cache
def _summations(nv: int, degree: int) -> tuple[np.ndarray, np.ndarray]:
    """Matrices taking the products X_word of every word (row-major) to monomial coefficients.

    Returns:
        two (number of monomials, nv**degree) matrices: each word's weight in the product of
        exponentials (P) and in its logarithm, placed in the row of the word's monomial.
    """
    monomials = _monomials(nv, degree)
    row = {monomial: r for r, monomial in enumerate(monomials)}
    words = list(product(range(nv), repeat=degree))
    rows, columns = [row[tuple(sorted(w))] for w in words], np.arange(len(words))
    pose, logarithm = np.zeros((2, len(monomials), len(words)))
    pose[rows, columns] = [_ordered_weight(w) for w in words]
    logarithm[rows, columns] = [_logarithm_weight(w) for w in words]
    return pose, logarithm


def tool_polynomial(twists: np.ndarray, order: int) -> np.ndarray:
    """Coefficients of the tool deviation polynomial of total degree ``order``.

    Args:
        twists: (6, nv) joint twists about the tool origin (:func:`tool_twists`), or (..., 6, nv)
            for several poses at once.
        order: total degree K (1 to ``MAX_ORDER``).

    Returns:
        (..., number of monomials, 6) array: for each monomial ``dq^α`` (degree-major, then
        lexicographic, as :func:`monomial_features` orders them) the coefficient of the position
        deviation [m / unit^|α|] and of the rotation vector [rad / unit^|α|].
    """
    nv, batch = twists.shape[-1], twists.shape[:-2]
    generators = np.zeros(batch + (nv, 4, 4))
    generators[..., :3, 3] = np.swapaxes(twists[..., :3, :], -1, -2)
    wx, wy, wz = twists[..., 3, :], twists[..., 4, :], twists[..., 5, :]
    generators[..., 0, 1], generators[..., 0, 2], generators[..., 1, 2] = -wz, wy, -wx  # ω̂ = [ω]×
    generators[..., 1, 0], generators[..., 2, 0], generators[..., 2, 1] = wz, -wy, wx
    words = generators  # X_w for every word w of the current degree, row-major
    blocks = []
    for degree in range(1, order + 1):
        if degree > 1:
            words = (words[..., :, None, :, :] @ generators[..., None, :, :, :]).reshape(batch + (-1, 4, 4))
        pose, logarithm = _summations(nv, degree)
        rotations = words[..., :3, :3]  # [[A, a], [0, 0]] [[B, b], [0, 0]] = [[AB, Ab], [0, 0]]
        skew = 0.5 * np.stack([rotations[..., 2, 1] - rotations[..., 1, 2], rotations[..., 0, 2] - rotations[..., 2, 0],
                               rotations[..., 1, 0] - rotations[..., 0, 1]], axis=-1)  # the log's parts are skew
        blocks.append(np.concatenate([pose @ words[..., :3, 3], logarithm @ skew], axis=-1))
    return np.concatenate(blocks, axis=-2)


@cache
def _feature_plan(nv: int, order: int) -> tuple[tuple[int, int, int], ...]:
    """How each block of monomial rows extends a lower-degree row: (prefix row, first new index, first row).

    Monomials of degree d sharing the prefix (a_1..a_{d-1}) are contiguous and end with every
    index a_d >= a_{d-1}; their features are the prefix's row times dq[a_{d-1}:].
    """
    plan, offset = [], 0
    for degree in range(1, order):
        first_row_next = offset + len(_monomials(nv, degree))
        row = first_row_next
        for r, prefix in enumerate(_monomials(nv, degree)):
            plan.append((offset + r, prefix[-1], row))
            row += nv - prefix[-1]
        offset = first_row_next
    return tuple(plan)


def monomial_features(dq_transposed: np.ndarray, order: int) -> np.ndarray:
    """The monomials ``dq^α``, 1 <= |α| <= ``order``, of each sample, one sample per column.

    Args:
        dq_transposed: (..., nv, n) joint deviations, one sample per column [m or rad].
        order: total degree K.

    Returns:
        (..., number of monomials, n) array, rows degree-major then lexicographic.
    """
    nv, n = dq_transposed.shape[-2:]
    rows = sum(len(_monomials(nv, d)) for d in range(1, order + 1))
    out = np.empty(dq_transposed.shape[:-2] + (rows, n))
    out[..., :nv, :] = dq_transposed
    for prefix_row, first_index, row in _feature_plan(nv, order):
        np.multiply(out[..., prefix_row:prefix_row + 1, :], dq_transposed[..., first_index:, :],
                    out=out[..., row:row + nv - first_index, :])
    return out


def evaluate_polynomial(twists: np.ndarray, translations: np.ndarray, dq: np.ndarray, orders: np.ndarray
                        ) -> tuple[np.ndarray, np.ndarray]:
    """Tool positions [m] and rotation vectors [rad] of samples at several poses, each pose's polynomial
    truncated at its own order.

    Args:
        twists: (poses, 6, nv) joint twists about the tool origin.
        translations: (poses, 3) commanded tool positions [m].
        dq: (poses, n, nv) joint deviations [m or rad].
        orders: (poses,) truncation order of each pose.

    Returns:
        positions and angles, each (poses, n, 3), views of (poses, 3, n) arrays. Each pose's values
        depend on its own inputs only. Fastest when ``dq`` is itself such a view of (poses, nv, n) memory.
    """
    poses, n, nv = dq.shape
    per_joint = np.swapaxes(dq, -1, -2)  # (poses, nv, n)
    deviations = np.empty((poses, 6, n))
    block = max(1, CHUNK_SAMPLES // max(n, 1))  # poses evaluated together; their features stay in cache
    for order in np.unique(orders):
        for run in _runs(np.flatnonzero(orders == order)):
            coefficients = np.swapaxes(tool_polynomial(twists[run], int(order)), -1, -2)  # (run, 6, M)
            for first in range(run.start, run.stop, block):
                group = slice(first, min(first + block, run.stop))
                for start in range(0, n, CHUNK_SAMPLES):
                    samples = np.ascontiguousarray(per_joint[group, :, start:start + CHUNK_SAMPLES])  # (g, nv, c)
                    np.matmul(coefficients[group.start - run.start:group.stop - run.start],
                              monomial_features(samples, int(order)),
                              out=deviations[group, :, start:start + samples.shape[-1]])
    deviations[:, :3] += translations[:, :, None]
    return np.swapaxes(deviations[:, :3], 1, 2), np.swapaxes(deviations[:, 3:], 1, 2)


def _runs(indices: np.ndarray) -> list[slice]:
    """Sorted ``indices`` as slices of consecutive ones (so poses are taken as views, not copies)."""
    breaks = np.flatnonzero(np.diff(indices) != 1) + 1
    return [slice(run[0], run[-1] + 1) for run in np.split(indices, breaks)]


def tool_deviations_fast(robot: Robot, q: np.ndarray, dq: np.ndarray, order: int | None = None,
                         tolerance_m: float = DEFAULT_TOLERANCE, tolerance_rad: float = DEFAULT_TOLERANCE
                         ) -> FastDeviations:
    """Tool poses for a batch of joint deviations, by the truncated product of exponentials.

    Same outputs as :func:`tribokin.propagation.exact.tool_deviations_exact`, plus the truncation order
    used and rigorous bounds on the difference to it (see the module docstring).

    Args:
        robot: the robot; its active joints are all 1-DoF.
        q: (nv,) commanded configuration [m or rad].
        dq: (n, nv) joint deviations of each cycle [m or rad].
        order: force this truncation order (1 to ``MAX_ORDER``); by default the lowest one whose
            bounds meet the tolerances (``MAX_ORDER`` if none does: check ``bound``).
        tolerance_m: tolerated position error [m].
        tolerance_rad: tolerated orientation error [rad].

    Returns:
        positions (n, 3) [m], angles (n, 3) [rad] and the :class:`TruncationBound`.
    """
    dq = np.asarray(dq, dtype=float)
    twists = tool_twists(robot, q)
    if dq.ndim != 2 or dq.shape[1] != twists.shape[1]:
        raise ValueError(f"dq must be (n, {twists.shape[1]}), got {dq.shape}")
    bound = truncation_bound(twists, dq, order, tolerance_m, tolerance_rad)
    positions, angles = evaluate_polynomial(twists[None], robot.tool_placement(q).translation[None], dq[None],
                                            np.array([bound.order]))
    return FastDeviations(positions[0], angles[0], bound)
