"""Value checks: each takes (value, source, key) and returns the clean value, or raises an
:class:`~tribokin.errors.InputError` naming the source and the key."""

from __future__ import annotations

import math
import sys

from tribokin.errors import InputError, SettingsError, closest_hint

#: Largest seed: NumPy's seeds are 64-bit numbers.
SEED_MAX = 2 ** 64 - 1


def _number(value, source, key) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(f"must be a number (got {value!r})", source, key)
    number = float(value) if isinstance(value, float) or value.bit_length() <= 1000 else math.inf
    if not math.isfinite(number):
        raise InputError(f"must be finite (got {_shown(value)})", source, key)
    return number


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


def whole_number(value, source, key) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise InputError(f"must be a whole number (got {value!r})", source, key)
    return value


def positive_int(value, source, key) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 1:
        raise InputError(f"must be a whole number >= 1 (got {value!r})", source, key)
    return value


def count(value, source, key) -> int:
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise InputError(f"must be a whole number >= 0 (got {value!r})", source, key)
    return value


def seed_int(value, source, key) -> int:
    value = count(value, source, key)
    if value > SEED_MAX:
        raise InputError(f"must be at most 2**64 - 1 (got {_shown(value)}): seeds are 64-bit numbers", source, key)
    return value


seed_int.bounds = (0, SEED_MAX, "", "seeds are 64-bit numbers")


def argument(check, value, name: str):
    """``check(value, source, key)`` applied to argument ``name`` of a library function: its refusal a
    :class:`~tribokin.errors.SettingsError` naming the argument, no file (the command locates it)."""
    try:
        return check(value, None, name)
    except InputError as error:
        raise SettingsError(error.message, name) from None


def _shown(value) -> str:
    """A number for a message: ``1e+308``, ``12``, or ``a number of about 400 digits`` for a whole number too long."""
    if isinstance(value, int) and value.bit_length() > 60:
        return f"a number of about {int(value.bit_length() * math.log10(2)) + 1} digits"
    return f"{value:g}"


def within(check, low: float, high: float, unit: str, why: str):
    """``check``, then a range: the value must lie in [low, high] [unit]; ``why`` (in the error) says what lies
    outside. Both ends may be whole numbers (a count) or floats. The range is kept on the check as ``bounds``
    ``(low, high, unit, why)``, which the study-file reference (``tools/study_reference.py``) prints and a fit stays
    within."""
    def bounded(value, source, key):
        value = check(value, source, key)
        if not low <= value <= high:
            raise InputError(f"must be between {low:g} and {high:g}{' ' + unit if unit else ''} (got "
                             f"{_shown(value)}): {why}", source, key)
        return value
    bounded.bounds = (low, high, unit, why)
    return bounded


def finite_cell(cell: str, where: str, source, key) -> float:
    """The text of a table's cell as a finite number; ``where`` names its place (``line 4``, ``line 4, column 2``).
    The error never quotes the cell: a file's content stays out of messages."""
    try:
        value = float(cell)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise InputError(f"{where}: expected a finite number; fix or remove that row", source, key)
    return value


def text(value, source, key) -> str:
    if not isinstance(value, str) or not value.strip():
        raise InputError(f"must be a non-empty string (got {value!r})", source, key)
    return value


def boolean(value, source, key) -> bool:
    if not isinstance(value, bool):
        raise InputError(f"must be true or false (got {value!r})", source, key)
    return value


def one_of(*choices):
    def check(value, source, key) -> str:
        if value not in choices:
            hint = closest_hint(str(value), list(choices))
            raise InputError(f"must be one of {', '.join(choices)} (got {value!r}){hint}", source, key)
        return value
    check.choices = choices
    return check


def table(value, source, key) -> dict:
    if not isinstance(value, dict):
        raise InputError(f"must be a table (got {value!r})", source, key)
    return value


def number_list(value, source, key, element=finite) -> list[float]:
    """A non-empty list of numbers, each passing ``element``."""
    if not isinstance(value, list) or not value:
        raise InputError(f"must be a non-empty list of numbers (got {value!r})", source, key)
    return [element(v, source, f"{key}[{i}]") for i, v in enumerate(value)]


def string_list(value, source, key) -> list[str]:
    if not isinstance(value, list):
        raise InputError(f"must be a list of strings (got {value!r})", source, key)
    return [text(v, source, f"{key}[{i}]") for i, v in enumerate(value)]


def distinct_strings(value, source, key, needed: str) -> list[str]:
    """A non-empty list of distinct non-empty strings; ``needed`` is the error of an empty list."""
    names = string_list(value, source, key)
    if not names:
        raise InputError(needed, source, key)
    for i, name in enumerate(names):
        if name in names[:i]:
            raise InputError(f"'{name}' is named twice; name it once", source, f"{key}[{i}]")
    return names


def toml_mapping(text: str, source) -> dict:
    """The mapping of TOML ``text`` read from ``source``; text that is not TOML, or nests arrays and inline tables
    deeper than the parser can follow (it recurses once per level), is an :class:`InputError` naming the line."""
    if sys.version_info >= (3, 11):
        import tomllib
    else:  # pragma: no cover
        import tomli as tomllib
    try:
        return tomllib.loads(text)
    except ValueError as error:  # also a number of more than 4300 digits
        raise InputError(f"not valid TOML: {error}", source) from None
    except RecursionError:
        raise nested_too_deep(text, source) from None


def nested_too_deep(text: str, source) -> InputError:
    """The error of TOML ``text`` whose arrays or inline tables nest deeper than a TOML reader follows, naming the
    line of the deepest."""
    depth, line = _deepest(text)
    return InputError(f"not valid TOML here: arrays or inline tables nested {depth} deep, deeper than a TOML reader "
                      "follows; no study value nests more than a few levels", source, f"line {line}")


def _deepest(text: str) -> tuple[int, int]:
    """The deepest nesting of brackets and braces in TOML ``text`` outside strings and comments, and its line."""
    depth = deepest = 0
    line = where = 1
    quote = None
    escaped = False
    for char in text:
        if char == "\n":
            line, quote = line + 1, None if quote == "#" else quote
        elif escaped:
            escaped = False
        elif quote is not None:
            escaped = char == "\\" and quote == '"'
            quote = None if char == quote else quote
        elif char in "\"'#":
            quote = char
        elif char in "[{":
            depth += 1
            if depth > deepest:
                deepest, where = depth, line
        elif char in "]}":
            depth -= 1
    return deepest, where
