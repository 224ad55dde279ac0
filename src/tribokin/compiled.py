"""Which path the per-target kernels take: compiled (numba, where it pays) or NumPy.

A module of compiled kernels imports numba at its top and is imported only once :func:`use_compiled` says so, so a
run on the NumPy path never loads numba. The environment variable ``TRIBOKIN_KERNELS`` chooses: ``compiled`` (the
default; the NumPy path when numba is not installed) or ``numpy``. It is read at each call, so child processes and
tests follow it. The two paths' kernels agree to rounding (about 1e-12 relative), not to the bit, so an iterative
solve may end elsewhere within its tolerance, or where rounding decides (an IK crossing a singular configuration or
running into a joint limit) on another solution: ``summary.json`` records which path a run took
(:func:`kernels_used`).
"""

from __future__ import annotations

import importlib.util
import os
from functools import lru_cache

from tribokin.errors import InputError

#: The environment variable that chooses the path, and its values.
VARIABLE = "TRIBOKIN_KERNELS"
COMPILED, NUMPY = "compiled", "numpy"


@lru_cache(maxsize=1)
def _numba_installed() -> bool:
    return importlib.util.find_spec("numba") is not None


def requested() -> str:
    """The path ``TRIBOKIN_KERNELS`` asks for (``compiled`` when unset); any other value is refused in one line."""
    value = os.environ.get(VARIABLE, COMPILED).strip().lower() or COMPILED
    if value not in (COMPILED, NUMPY):
        raise InputError(f"{value!r} is not a kernel path: set it to {COMPILED!r} (the default) or {NUMPY!r}",
                         "environment", VARIABLE)
    return value


def use_compiled() -> bool:
    """Whether the per-target kernels run compiled now: asked for (:func:`requested`) and numba installed."""
    return requested() == COMPILED and _numba_installed()


def kernels_used() -> str:
    """``"compiled (numba <version>)"`` or ``"numpy"``: the path :func:`use_compiled` takes, for ``summary.json``."""
    if not use_compiled():
        return NUMPY
    from importlib import metadata

    return f"{COMPILED} (numba {metadata.version('numba')})"


def cache_is_empty(modules) -> bool:
    """Whether numba's cache holds no compiled code, for their source as it now stands, of any kernel (a numba
    dispatcher made with ``cache=True``) of ``modules``: a run on the compiled path then compiles the kernels it uses
    (the first run after installing or changing tribokin). ``False`` when numba is not installed or ``modules`` has
    no such kernel."""
    if not _numba_installed():
        return False
    from numba.core.caching import FunctionCache

    caches = [cache for module in modules for value in vars(module).values()
              if isinstance(cache := getattr(value, "_cache", None), FunctionCache)]  # a dispatcher's, cache=True
    return bool(caches) and not any(cache._cache_file._load_index() for cache in caches)  # {} when none is fresh
