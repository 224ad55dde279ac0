"""Tribometer logs: the friction coefficient per cycle and its running-in.

A log is a CSV file with the columns ``cycle, mu`` or
``cycle, friction_force_N, normal_force_N`` (then mu = F / N); ``cycle`` is
optional. The first cycles of a test (running-in: the surfaces wear in and
mu drifts) do not belong to the steady state whose statistics a study needs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tribokin.checks import count
from tribokin.errors import InputError
from tribokin.tribology.columns import read_columns
from tribokin.tribology.laws import MU_MAX

MIN_CYCLES = 20


@dataclass(frozen=True)
class TribometerLog:
    """Friction coefficient per cycle [-] and the cycle numbers [-] of one test."""

    source: str
    cycle: np.ndarray
    mu: np.ndarray


def read_log(path) -> TribometerLog:
    """Read a tribometer log (``cycle, mu`` or ``friction_force_N, normal_force_N``)."""
    columns, lines = read_columns(path, (("mu",), ("friction_force_N", "normal_force_N")), MIN_CYCLES, ("cycle",))
    if "mu" in columns:
        mu, key = columns["mu"], "mu"
    else:
        normal, key = columns["normal_force_N"], "friction_force_N"
        if np.any(normal <= 0):
            raise InputError(f"line {lines[np.argmax(normal <= 0)]}: expected a normal force > 0", path,
                             "normal_force_N")
        with np.errstate(over="ignore"):  # an overflowing ratio is refused below, as too large
            mu = np.abs(columns["friction_force_N"]) / normal
    if np.any(mu < 0):
        raise InputError(f"line {lines[np.argmax(mu < 0)]}: expected mu >= 0: friction is never negative", path, key)
    if np.any(mu > MU_MAX):
        row = int(np.argmax(mu > MU_MAX))
        raise InputError(f"line {lines[row]} gives mu = {mu[row]:g}, above {MU_MAX:g}: not sliding friction (clean "
                         "metals in vacuum reach a few); check the row and the units", path, key)
    cycle = columns.get("cycle", np.arange(1, mu.size + 1, dtype=float))
    return TribometerLog(str(path), cycle, mu)


def running_in_cycles(mu: np.ndarray) -> int:
    """Number of leading running-in cycles of a log of mu [-].

    Rule: the steady state is described by the median m and the robust
    standard deviation s = 1.4826 * MAD of the second half of the log; with
    windows of w = max(5, n // 50) cycles, running-in ends at the first cycle
    i whose window mean mu[i:i+w] lies within 3 * s / sqrt(w) of m (three
    standard errors of a window mean). A steady log therefore keeps (almost)
    all its cycles; a late excursion does not trim the log.
    """
    mu = np.asarray(mu, dtype=float)
    tail = mu[mu.size // 2:]
    median = np.median(tail)
    spread = 1.4826 * np.median(np.abs(tail - median))
    window = max(5, mu.size // 50)
    means = np.convolve(mu, np.ones(window) / window, mode="valid")
    settled = np.abs(means - median) <= 3 * spread / np.sqrt(window)
    return int(np.argmax(settled)) if settled.any() else mu.size // 2


def steady_state(log: TribometerLog, running_in: int | None = None) -> tuple[np.ndarray, int]:
    """mu of the cycles after running-in [-] and the number of cycles trimmed.

    ``running_in`` overrides the detected count (``running_in_cycles``).
    """
    trimmed = running_in_cycles(log.mu) if running_in is None else running_in
    count(trimmed, log.source, "running_in")
    if log.mu.size - trimmed < MIN_CYCLES:
        shown = trimmed if trimmed <= log.mu.size else "more than all"
        raise InputError(f"trimming {shown} of {log.mu.size} cycles leaves fewer than {MIN_CYCLES}; "
                         "use a smaller running-in count", log.source, "running_in")
    return log.mu[trimmed:], int(trimmed)

