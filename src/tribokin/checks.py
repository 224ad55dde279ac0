"""Value checks: each takes (value, source, key) and returns the clean value, or raises an
:class:`~tribokin.errors.InputError` naming the source and the key."""

from __future__ import annotations

import math

from tribokin.errors import InputError, closest_hint


def _number(value, source, key) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(f"must be a number (got {value!r})", source, key)
    if not math.isfinite(value):
        raise InputError(f"must be finite (got {value})", source, key)
    return float(value)


def finite(value, source, key) -> float:
    return _number(value, source, key)


def non_negative(value, source, key) -> float:
    value = _number(value, source, key)
    if value < 0:
        raise InputError(f"must be >= 0 (got {value:g})", source, key)
    return value


def positive(value, source, key) -> float:
    value = _number(value, source, key)
    if value <= 0:
        raise InputError(f"must be > 0 (got {value:g})", source, key)
    return value


def positive_int(value, source, key) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise InputError(f"must be a whole number >= 1 (got {value!r})", source, key)
    return value


def seed_int(value, source, key) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise InputError(f"must be a whole number >= 0 (got {value!r})", source, key)
    return value


def text(value, source, key) -> str:
    if not isinstance(value, str) or not value.strip():
        raise InputError(f"must be a non-empty string (got {value!r})", source, key)
    return value


def one_of(*choices):
    def check(value, source, key) -> str:
        if value not in choices:
            hint = closest_hint(str(value), list(choices))
            raise InputError(f"must be one of {', '.join(choices)} (got {value!r}){hint}", source, key)
        return value
    return check


def table(value, source, key) -> dict:
    if not isinstance(value, dict):
        raise InputError(f"must be a table (got {value!r})", source, key)
    return value


def number_list(value, source, key) -> list[float]:
    if not isinstance(value, list) or not value:
        raise InputError(f"must be a non-empty list of numbers (got {value!r})", source, key)
    return [_number(v, source, f"{key}[{i}]") for i, v in enumerate(value)]


def string_list(value, source, key) -> list[str]:
    if not isinstance(value, list):
        raise InputError(f"must be a list of strings (got {value!r})", source, key)
    return [text(v, source, f"{key}[{i}]") for i, v in enumerate(value)]
