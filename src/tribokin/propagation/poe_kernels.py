"""Compiled (numba) kernel of the fast engine's truncation bounds (:mod:`tribokin.propagation.poe`), pose by pose:
the weighted deviation sums, then the tails of the series of e^s and -log(2 - e^w) after each order. It agrees with
the NumPy path to rounding (about 1e-15 relative).

Imported only on the compiled path (:func:`tribokin.compiled.use_compiled`). The series' coefficients and radii are
passed in as arguments: numba's cache would keep a module global's old value.
"""

from __future__ import annotations

import math

import numpy as np

from tribokin.compiled import kernel


@kernel
def order_bounds(twists, dq, orders, exp_coefficients, log_coefficients, exp_radius, log_radius):
    """The bounds on the position [m] and the angle [rad] (k, ``orders``) each after orders 1 to ``orders``, of twists
    (k, 6, nv) and deviations (k, n, nv) [m or rad], as ``poe._order_bounds``: with s, b, w the largest over the
    samples of Σ c_i |dq_i|, Σ |v_i| |dq_i|, Σ |ω_i| |dq_i|, the position's min(tail_{K+1}(e^s), b tail_K(e^w))
    and the angle's tail_{K+1}(-log(2 - e^w)) (``inf`` from w = ln 2 on)."""
    count, samples, joints = dq.shape
    position, angle = np.empty((count, orders)), np.empty((count, orders))
    weights = np.empty((3, joints))  # c_i, |v_i|, |ω_i|
    sums = np.empty(3)  # a sample's Σ weight_i |dq_i|
    terms = np.empty(exp_coefficients.shape[0])  # a series' terms
    full_tail, angular_tail = np.empty(orders + 1), np.empty(orders + 1)
    for k in range(count):
        for i in range(joints):
            linear = math.sqrt(twists[k, 0, i] ** 2 + twists[k, 1, i] ** 2 + twists[k, 2, i] ** 2)
            angular = math.sqrt(twists[k, 3, i] ** 2 + twists[k, 4, i] ** 2 + twists[k, 5, i] ** 2)
            weights[0, i], weights[1, i], weights[2, i] = math.hypot(linear, angular), linear, angular
        full, linear_sum, angular_sum = 0.0, 0.0, 0.0  # zero without samples
        for j in range(samples):
            sums[:] = 0.0
            for i in range(joints):
                size = abs(dq[k, j, i])
                for row in range(3):
                    sums[row] += weights[row, i] * size
            full, linear_sum, angular_sum = (np.maximum(full, sums[0]), np.maximum(linear_sum, sums[1]),
                                             np.maximum(angular_sum, sums[2]))
        _tails(exp_coefficients, exp_radius, False, full, 2, terms, full_tail)
        _tails(exp_coefficients, exp_radius, False, angular_sum, 1, terms, angular_tail)
        for order in range(orders):
            position[k, order] = np.minimum(full_tail[order], linear_sum * angular_tail[order])
        converging = angular_sum < math.log(2.0)
        if converging:
            _tails(log_coefficients, log_radius, True, angular_sum, 2, terms, angular_tail)
        for order in range(orders):  # (a loop: numba compiles an array's slice assignment slowly)
            angle[k, order] = angular_tail[order] if converging else math.inf
    return position, angle


@kernel
def _tails(coefficients, radius, logarithm, s, first, terms, out):
    """``out[o]`` = Σ_{m >= first + o} c_m s^m, for each o < len(out), as ``poe._series_tail``: up to s = ``radius``
    term by term from the smallest, up to the first term below half the one before and 2^-60 of the tail's first
    (within their radii the terms of e^s and -log(2 - e^w) shrink at least as fast from there on, so those left out
    move no tail by a rounding); else the closed form (e^s, or -log(2 - e^s) where ``logarithm``) less the first
    terms (``inf`` where they overflow). ``terms``: room for the c_m s^m, m < len(coefficients)."""
    count, power = coefficients.shape[0], 1.0
    if s <= radius:
        last = count
        for m in range(count):
            terms[m] = coefficients[m] * power
            power *= s
            if m > first + out.shape[0] and terms[m] <= terms[m - 1] / 2 and terms[m] <= terms[first] * 2.0 ** -60:
                last = m + 1
                break
        total = 0.0
        for m in range(last - 1, first - 1, -1):
            total += terms[m]
            if m - first < out.shape[0]:
                out[m - first] = total
        return
    closed = -math.log(2.0 - math.exp(s)) if logarithm else math.exp(s)
    head = 0.0
    for m in range(first + out.shape[0]):
        if m >= first:
            out[m - first] = math.inf if math.isinf(head) else closed - head  # s^m overflows too
        head += coefficients[m] * power
        power *= s


@kernel
def first_order_model_bounds(twists, departure, mean_dq, exp_coefficients, log_coefficients, exp_radius, log_radius):
    """``poe.first_order_model_bounds`` target by target: (k,) each, the position's [m] and the rotation vector's [rad]
    bounds after order 1 over deviations within ``departure`` (k, nv) about (k, 6, nv) twists, and the angle's terms
    of composing with the mean deviation ``mean_dq`` (k, nv)'s rotation."""
    count, joints = departure.shape
    position, angle, extra = np.empty(count), np.empty(count), np.empty(count)
    speeds, turns = np.empty(joints), np.empty(joints)
    terms, out = np.empty(exp_coefficients.shape[0]), np.empty(1)
    ln2 = math.log(2.0)
    for k in range(count):
        full, speed_sum, turn_sum, mean_sum = 0.0, 0.0, 0.0, 0.0
        for i in range(joints):
            speeds[i] = math.sqrt(twists[k, 0, i] ** 2 + twists[k, 1, i] ** 2 + twists[k, 2, i] ** 2)
            turns[i] = math.sqrt(twists[k, 3, i] ** 2 + twists[k, 4, i] ** 2 + twists[k, 5, i] ** 2)
            full += math.hypot(speeds[i], turns[i]) * departure[k, i]
            speed_sum += speeds[i] * departure[k, i]
            turn_sum += turns[i] * departure[k, i]
            mean_sum += turns[i] * abs(mean_dq[k, i])
        moved, turned = 0.0, 0.0
        for i in range(joints):
            wx, wy, wz = twists[k, 3, i], twists[k, 4, i], twists[k, 5, i]
            for j in range(i, joints):
                vx, vy, vz = twists[k, 0, j], twists[k, 1, j], twists[k, 2, j]
                size = math.sqrt((wy * vz - wz * vy) ** 2 + (wz * vx - wx * vz) ** 2 + (wx * vy - wy * vx) ** 2)
                moved += (0.5 if i == j else 1.0) * size * departure[k, i] * departure[k, j]
                if j > i:
                    ux, uy, uz = twists[k, 3, j], twists[k, 4, j], twists[k, 5, j]
                    size = math.sqrt((wy * uz - wz * uy) ** 2 + (wz * ux - wx * uz) ** 2 + (wx * uy - wy * ux) ** 2)
                    turned += 0.5 * size * departure[k, i] * departure[k, j]
        _tails(exp_coefficients, exp_radius, False, full, 3, terms, out)
        rest = out[0]
        _tails(exp_coefficients, exp_radius, False, turn_sum, 2, terms, out)
        position[k] = moved + min(rest, speed_sum * out[0])
        angle[k] = turned + _log_tail(log_coefficients, log_radius, turn_sum, 3, terms, out)
        u = _log_tail(log_coefficients, log_radius, turn_sum, 1, terms, out)
        if mean_sum == 0:  # no mean rotation (c = 0): nothing to compose with, as the terms below give exactly
            extra[k] = math.inf if u >= ln2 else 0.0
            continue
        v = _log_tail(log_coefficients, log_radius, mean_sum, 1, terms, out)
        miss = _log_tail(log_coefficients, log_radius, mean_sum, 2, terms, out)
        if u + v >= ln2:
            extra[k] = math.inf
        else:
            mixed = (_log_tail(log_coefficients, log_radius, u + v, 3, terms, out)
                     - _log_tail(log_coefficients, log_radius, u, 3, terms, out)
                     - _log_tail(log_coefficients, log_radius, v, 3, terms, out))
            extra[k] = max(mixed, 0.0) + u * miss / 2
    return position, angle, extra


@kernel
def _log_tail(coefficients, radius, w, first, terms, out):
    """Σ_{m >= first} of the series of -log(2 - e^w) (``inf`` from w = ln 2 on), through :func:`_tails`."""
    if w >= math.log(2.0):
        return math.inf
    _tails(coefficients, radius, True, w, first, terms, out)
    return out[0]
