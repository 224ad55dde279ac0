"""Settled dwells of a raw stream (times and positions, no pose labels), labelled as poses and cycles.

A window of ``min_duration_s`` is settled when all its readings lie within
``radius_m`` of the centre of their bounding box (half-diagonal of the box
<= radius). A dwell is a run of readings each inside some settled window; its
position is the mean of its readings. Dwells whose positions lie within
``match_radius_m`` of a pose's first dwell are cycles of that pose; poses are
named ``P1``, ``P2``, ... in order of first visit. A dwell whose pose has fewer
than ``min_cycles`` dwells (a home position, a pause) cannot form a series: it
is listed as unmatched, not dropped silently.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tribokin.errors import InputError
from tribokin.measurement.contract import DEFAULT_DIRECTION, Measurements, Rows, Stream, assemble

#: Defaults: a dwell holds still within 0.1 mm for 1 s; dwells within 1 mm are one pose.
DWELL_RADIUS_M = 1e-4
DWELL_MIN_DURATION_S = 1.0
MATCH_RADIUS_M = 1e-3


@dataclass(frozen=True)
class Dwell:
    """A settled stretch of the stream.

    Attributes:
        first, last: indices of its first and last reading in the stream.
        start_s, end_s: times of those readings [s].
        position_m: (3,) mean of its readings [m].
        pose: pose label, or None when unmatched.
        cycle: cycle number within the pose (1, 2, ...), or None when unmatched.
    """

    first: int
    last: int
    start_s: float
    end_s: float
    position_m: np.ndarray
    pose: str | None = None
    cycle: int | None = None


def _window_half_diagonal(positions_m: np.ndarray, start: np.ndarray, stop: np.ndarray) -> np.ndarray:
    """Half-diagonal [m] of the bounding box of readings ``start[i]..stop[i]`` (inclusive), by sparse tables
    of running maxima and minima (range queries without a loop over readings)."""
    highs, lows = [positions_m], [positions_m]
    while 2 ** len(highs) <= len(positions_m):
        half = 2 ** (len(highs) - 1)
        highs.append(np.maximum(highs[-1][:-half], highs[-1][half:]))
        lows.append(np.minimum(lows[-1][:-half], lows[-1][half:]))
    level = np.floor(np.log2(stop - start + 1)).astype(int)
    extent = np.empty((len(start), 3))
    for k in np.unique(level):
        mine = level == k
        tail = stop[mine] - 2 ** k + 1
        extent[mine] = (np.maximum(highs[k][start[mine]], highs[k][tail])
                        - np.minimum(lows[k][start[mine]], lows[k][tail]))
    return np.linalg.norm(extent, axis=1) / 2


def find_dwells(times_s: np.ndarray, positions_m: np.ndarray, radius_m: float = DWELL_RADIUS_M,
                min_duration_s: float = DWELL_MIN_DURATION_S) -> tuple[Dwell, ...]:
    """Settled dwells of (n,) increasing ``times_s`` [s] and (n, 3) ``positions_m`` [m], in time order."""
    stop = np.searchsorted(times_s, times_s + min_duration_s)  # first reading at or after the window's end
    full = stop < len(times_s)
    starts = np.flatnonzero(full)
    settled = starts[_window_half_diagonal(positions_m, starts, stop[starts]) <= radius_m]
    cover = np.zeros(len(times_s) + 1, dtype=int)
    np.add.at(cover, settled, 1)
    np.add.at(cover, stop[settled] + 1, -1)
    covered = np.concatenate([[0], (np.cumsum(cover[:-1]) > 0).astype(int), [0]])
    edges = np.diff(covered)
    firsts, lasts = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1
    return tuple(Dwell(int(a), int(b), float(times_s[a]), float(times_s[b]), positions_m[a:b + 1].mean(axis=0))
                 for a, b in zip(firsts, lasts, strict=True))


def label_dwells(dwells: tuple[Dwell, ...], match_radius_m: float = MATCH_RADIUS_M,
                 min_cycles: int = 2) -> tuple[Dwell, ...]:
    """The dwells with pose and cycle set (None for the unmatched: their pose has fewer than ``min_cycles``)."""
    anchors: list[np.ndarray] = []
    groups = []
    for dwell in dwells:
        near = [k for k, anchor in enumerate(anchors) if np.linalg.norm(dwell.position_m - anchor) <= match_radius_m]
        if not near:
            anchors.append(dwell.position_m)
            near = [len(anchors) - 1]
        groups.append(near[0])
    counts = np.bincount(groups, minlength=len(anchors))
    names = {g: f"P{k + 1}" for k, g in enumerate(g for g in range(len(anchors)) if counts[g] >= min_cycles)}
    seen: dict[int, int] = {}
    labelled = []
    for dwell, group in zip(dwells, groups, strict=True):
        if group in names:
            seen[group] = seen.get(group, 0) + 1
            labelled.append(Dwell(dwell.first, dwell.last, dwell.start_s, dwell.end_s, dwell.position_m,
                                  names[group], seen[group]))
        else:
            labelled.append(dwell)
    return tuple(labelled)


def dwell_measurements(stream: Stream, dwells: tuple[Dwell, ...]) -> Measurements:
    """The matched dwells as a measurement (direction ``+``; time of a cycle: the middle of its dwell;
    line: its first reading's); unmatched dwells are left out (report them from ``dwells``)."""
    matched = [d for d in dwells if d.pose is not None]
    if not matched:
        raise InputError(f"{len(dwells)} settled dwells found, no pose among them visited twice; check the "
                         "dwell radius and minimum time against the stream", stream.source)
    rows = Rows(
        lines=stream.lines[[d.first for d in matched]],
        poses=tuple(d.pose for d in matched),
        directions=(DEFAULT_DIRECTION,) * len(matched),
        cycles=np.array([d.cycle for d in matched]),
        positions_m=np.array([d.position_m for d in matched]).reshape(-1, 3),
        times_s=np.array([(d.start_s + d.end_s) / 2 for d in matched]),
    )
    return assemble(stream.source, rows)
