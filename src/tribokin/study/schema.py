"""The study file's schema tables: key -> (check, default), checked by :func:`check_table`; ``REQUIRED`` marks a key
without a default."""

from __future__ import annotations

from tribokin.errors import InputError, closest_hint

REQUIRED = object()


def check_table(mapping: dict, schema: dict, source, prefix: str, extra_ok=()) -> dict:
    """Validate ``mapping`` against ``schema``; return every key with its value or default.

    Keys in ``extra_ok`` are left for the caller; any other unknown key is an error.
    """
    for key in mapping:
        if key not in schema and key not in extra_ok:
            valid = list(schema) + list(extra_ok)
            raise InputError(f"unknown key '{key}'{closest_hint(key, valid)}; valid keys: {', '.join(valid)}",
                             source, f"{prefix}.{key}")
    clean = {}
    for key, (check, default) in schema.items():
        if key in mapping:
            clean[key] = check(mapping[key], source, f"{prefix}.{key}")
        elif default is REQUIRED:
            raise InputError("missing: this key is required", source, f"{prefix}.{key}")
        else:
            clean[key] = default
    return clean
