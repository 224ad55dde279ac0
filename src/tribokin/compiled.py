"""Which path the per-target kernels take: compiled (numba, where it pays) or NumPy.

A module of compiled kernels imports numba at its top and is imported only once :func:`use_compiled` says so, so a
run on the NumPy path never loads numba. The environment variable ``TRIBOKIN_KERNELS`` chooses: ``compiled`` (the
default; the NumPy path when numba is not installed) or ``numpy``. It is read at each call, so child processes and
tests follow it. The two paths' kernels agree to rounding (about 1e-12 relative), not to the bit, so an iterative
solve may end elsewhere within its tolerance, or where rounding decides (an IK crossing a singular configuration or
running into a joint limit) on another solution: ``summary.json`` records which path a run took
(:func:`kernels_used`).

Kernels are declared with :func:`kernel` (``numba.njit(nogil=True)``) and kept in numba's cache (``NUMBA_CACHE_DIR``,
else ``__pycache__`` beside the source, else the user's cache folder). A cache that cannot be used (no location
writable, or an index or data file that cannot be read back: a corrupted or truncated file) does not stop a run:
the kernels are compiled in memory for the process, and it warns once (:class:`CacheWarning`).
"""

from __future__ import annotations

import hashlib
import importlib.util
import os
import warnings
from functools import lru_cache
from pathlib import Path

from tribokin.errors import InputError

#: The environment variable that chooses the path, and its values.
VARIABLE = "TRIBOKIN_KERNELS"
COMPILED, NUMPY = "compiled", "numpy"


class CacheWarning(UserWarning):
    """numba's cache of tribokin's kernels cannot be used: they are compiled in memory (module docstring)."""


#: The reason numba's cache could not be used, once warned of (a process, and the workers it forks, warn once).
_WARNED: list[str] = []


def _warn_once(reason: str) -> None:
    if not _WARNED:
        _WARNED.append(reason)
        warnings.warn(f"numba's cache of tribokin's kernels cannot be used ({reason}): they are compiled in memory "
                      "for this run, which takes longer (set NUMBA_CACHE_DIR to a writable folder, or delete the "
                      "cache's files)", CacheWarning, stacklevel=3)


@lru_cache(maxsize=1)
def _cache_class():
    """numba's ``FunctionCache``, with a file that cannot be read or written taken as a miss (module docstring)."""
    from numba.core.caching import FunctionCache

    class Cache(FunctionCache):
        def __init__(self, py_func):
            super().__init__(py_func)
            if hasattr(self, "_cache_file"):  # numba's key: the kernel's own file's source (IndexDataCacheFile)
                root = _package_root(Path(py_func.__code__.co_filename))
                self._cache_file._source_stamp = (self._cache_file._source_stamp, kernel_sources_digest(root))

        def load_overload(self, sig, target_context):
            try:
                return super().load_overload(sig, target_context)
            except Exception as error:  # noqa: BLE001 - whatever unpickling a damaged file raises
                _warn_once(f"{self.cache_path} holds a file that cannot be read: {type(error).__name__}")
                return None

        def save_overload(self, sig, data):
            try:
                super().save_overload(sig, data)
            except Exception as error:  # noqa: BLE001 - a damaged index read back, a full or read-only disk
                _warn_once(f"{self.cache_path} cannot be written: {type(error).__name__}")

    return Cache


@lru_cache(maxsize=4)
def kernel_sources_digest(package: Path) -> str:
    """SHA-256 of the source of every kernel module (``*_kernels.py``) in the folder ``package`` and below: part of
    each kernel's key in numba's cache, which numba keys on the kernel's own file alone, so that a kernel calling
    another module's kernels (compiled into it) is compiled again when they change, not loaded with their old code."""
    digest = hashlib.sha256()
    for path in sorted(package.glob("**/*_kernels.py")):
        digest.update(path.relative_to(package).as_posix().encode() + b"\0" + path.read_bytes() + b"\0")
    return digest.hexdigest()


def _package_root(path: Path) -> Path:
    """The folder of the top-level package holding the module at ``path`` (its own folder if not in a package)."""
    folder = path.resolve().parent
    while (folder.parent / "__init__.py").exists():
        folder = folder.parent
    return folder


def kernel(function):
    """``function`` compiled by numba (``njit(nogil=True)``) on first call, kept in numba's cache when it can be
    (module docstring)."""
    from numba import njit

    dispatcher = njit(nogil=True)(function)
    try:
        dispatcher._cache = _cache_class()(function)  # what njit(cache=True) sets, through this cache
    except RuntimeError as error:  # numba: no locator available, no cache folder writable
        _warn_once(f"no folder it can write: {error}")
    return dispatcher


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
    return bool(caches) and not any(_holds(cache) for cache in caches)


def _holds(cache) -> bool:
    """Whether a numba cache's index holds code fresh for its function's source (not when it cannot be read)."""
    try:
        return bool(cache._cache_file._load_index())  # {} when none is fresh
    except Exception as error:  # noqa: BLE001 - whatever unpickling a damaged file raises
        _warn_once(f"{cache.cache_path} holds a file that cannot be read: {type(error).__name__}")
        return False
