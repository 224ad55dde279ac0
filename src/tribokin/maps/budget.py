"""The memory and disk a run needs, estimated from the study before anything runs, against what the machine has.

A run keeps every cycle of every pose in memory (``samples.npz`` holds them all). A map keeps its
per-target results on disk (:class:`~tribokin.maps.store.ChunkStore`, a few hundred bytes per
target); in memory it holds the chunks being computed, one warm start per grid row, and blocks of
about ``TARGET_BLOCK_SAMPLES`` cycles. A study that would not fit is refused up front with the
estimate, rather than killed by the operating system half-way. The byte counts below were
measured (``tracemalloc``, UR5 and gantry) and rounded up about twofold.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

from tribokin.errors import InputError
from tribokin.maps.expected_figures import BLOCK_CYCLES, MAX_BAND_FACTOR, SAMPLED_CYCLES, tests_for
from tribokin.maps.schema import MapLayout, study_approaches
from tribokin.study.spec import Study, map_series
from tribokin.units import gib

FLOAT = 8
#: A map draws, propagates and measures its targets in blocks of about this many cycles: enough to
#: share the per-call costs, few enough for the block's arrays (a few MiB) to stay small.
TARGET_BLOCK_SAMPLES = 16384
#: Bytes per cycle of a pose while the results are written (figures, the report's clouds).
WRITTEN_PER_CYCLE = 800


def kept_per_cycle(nv: int) -> int:
    """Bytes per cycle of a pose kept until written: positions (3), angles (3), approach (1), mu and dq (2 nv)."""
    return FLOAT * (7 + 2 * nv)


def computed_per_cycle(nv: int) -> int:
    """Bytes per cycle and approach direction while a pose is computed (draws, signs, engine intermediates)."""
    return FLOAT * 8 * nv


#: (limit, usage) files of a cgroup v2, then v1: a container's memory limit.
CGROUP_FILES = (("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current"),
                ("/sys/fs/cgroup/memory/memory.limit_in_bytes", "/sys/fs/cgroup/memory/memory.usage_in_bytes"))


def available_bytes() -> int | None:
    """Memory this process may still take [bytes]: ``MemAvailable``, capped by a cgroup (container)
    limit; ``None`` when the system does not say."""
    candidates = []
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                candidates.append(int(line.split()[1]) * 1024)
    except (OSError, ValueError, IndexError):
        pass
    for limit, usage in CGROUP_FILES:
        try:
            candidates.append(int(Path(limit).read_text()) - int(Path(usage).read_text()))
        except (OSError, ValueError):
            continue  # no such cgroup, or no limit ("max")
    if not candidates:
        try:
            candidates.append(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
        except (OSError, ValueError, AttributeError):
            return None
    return max(0, min(candidates))


def _count(number: int, word: str) -> str:
    """``"1,000 cycles"``, ``"1 pose"``."""
    return f"{number:,} {word}{'' if number == 1 else 's'}"


def map_layout(study: Study, nv: int, layout: MapLayout | None) -> MapLayout:
    """``layout``, or by default that of the study's scenarios all measured with its robot of ``nv`` active joints."""
    return layout or MapLayout.shared(nv, max(1, len(study.scenarios)), study.map.figure_set, study_approaches(study),
                                      study.map.compare is not None)


def check_disk(study: Study, nv: int, folder, layout: MapLayout | None = None) -> None:
    """An :class:`InputError` naming the map's size key if its store would not fit on the disk holding ``folder``
    (``layout``: the store's, :func:`map_layout`)."""
    if study.map is None:
        return
    targets = study.map.target_count
    scenarios = max(1, len(study.scenarios))
    needed = targets * map_layout(study, nv, layout).bytes_per_target
    existing = Path(folder).absolute()
    while not existing.exists():
        existing = existing.parent
    free = shutil.disk_usage(existing).free
    if needed > free:
        key = study.map.size_key
        raise InputError(f"this map needs about {gib(needed)} of disk space for its results "
                         f"({_count(targets, 'map target')} × {_count(scenarios, 'scenario')} × "
                         f"{_count(nv, 'joint')}), and {gib(free)} is available in "
                         f"'{existing}': lower {key}, or split the map into several", study.source, key)


def estimate(study: Study, nv: int, directions: list[int], workers: int = 1,
             layout: MapLayout | None = None) -> list[tuple[float, str, str]]:
    """The bytes a run needs, in parts: ``(bytes, key, what)``, ``key`` the study key to lower.

    Args:
        study: the validated study (poses, ``[map]``, scenarios).
        nv: active joints of the study's robot.
        directions: per pose to run, the approach directions tested (``cycles`` kept from each).
        workers: local processes computing map chunks at once.
        layout: the map store's (:func:`map_layout`): each robot of the scenarios keeps its own configurations.
    """
    cycles = study.cycles
    parts = []
    if directions:
        kept = sum(directions) * cycles * (kept_per_cycle(nv) + WRITTEN_PER_CYCLE)
        computed = max(directions) * cycles * computed_per_cycle(nv)
        parts.append((kept + computed, "study.cycles",
                      f"{_count(cycles, 'cycle')} × {_count(len(directions), 'pose')} × {_count(nv, 'joint')}"))
    if study.map is not None:
        scenarios = max(1, len(study.scenarios))
        cycles = max([s.study.cycles for s in study.scenarios] or [study.cycles])
        key, chunk, rows = study.map.size_key, study.map.chunk_targets, study.map.grid_rows
        layout = map_layout(study, nv, layout)
        per_target = layout.bytes_per_target
        held = 2 * (max(1, workers) + 1) * chunk * per_target + 3 * FLOAT * sum(layout.joints) * rows
        # chunks computed, in transit and written; a warm start per row (kept, sent, solved)
        parts.append((held, key, f"{_count(chunk, 'map target')} per chunk × {_count(scenarios, 'scenario')} × "
                                 f"{_count(nv, 'joint')}, and {_count(rows, 'grid row')}"))
        # cycles of the targets measured together (a one-test map approached from both directions: cycles from each)
        block = max(cycles * (2 if any(layout.directions) else 1), TARGET_BLOCK_SAMPLES)
        most = max(layout.joints)
        parts.append((max(1, workers) * block * (kept_per_cycle(most) + computed_per_cycle(most)), "study.cycles",
                      f"{_count(cycles, 'cycle')} per map target × {_count(max(1, workers), 'worker')}"))
        if study.map.statistic == "expected" and map_series(study):
            parts.append((max(1, workers) * series_bytes(cycles, most, study.map.compare is not None,
                                                         study.map.figure_set == "directional"), "study.cycles",
                          f"the friction series' sampled tests of {_count(cycles, 'cycle')} × "
                          f"{_count(max(1, workers), 'worker')}"))
    return parts


def series_bytes(cycles: int, nv: int, compare: bool, directional: bool = False) -> int:
    """Bytes an expected map's worker holds where a joint's friction is a time series: its sampled tests drawn whole
    (:func:`~tribokin.maps.expected_figures.series_draws`; from ``ASYMPTOTIC_CYCLES`` cycles on too, not as single
    cycles), the band's further tests at most ``MAX_BAND_FACTOR`` times as many: per cycle the common numbers (3 nv),
    the draws (nv) and a joint's latent series, values and temperatures (3), twice with ``compare`` (each state's);
    and a block of targets' sampled positions, angles and the band's positions (3 each) of ``BLOCK_CYCLES``. A
    ``directional`` map's vAP_p draws three directions' tests at once (their common numbers, a target's positions and
    angles through the engine: 3 nv + 6 a cycle)."""
    tests = tests_for(SAMPLED_CYCLES, cycles)
    tested = tests * cycles * MAX_BAND_FACTOR
    vap = 3 * tests * cycles * (3 * nv + 6) if directional else 0
    return (tested * (4 * nv + 3) + vap) * FLOAT * (2 if compare else 1) + BLOCK_CYCLES * FLOAT * 9


def check_memory(study: Study, nv: int, directions: list[int], workers: int = 1,
                 cycles_set_by: tuple[str, str] | None = None, available: int | None = None,
                 layout: MapLayout | None = None) -> None:
    """An :class:`InputError` naming the key to lower if the run needs more memory than is available.

    ``cycles_set_by``: ``(source, key)`` named when the cycles are to lower, if not the study file's
    ``study.cycles`` (``("command line", "--cycles")``); ``available`` [bytes] defaults to
    :func:`available_bytes` (no check when unknown); ``layout``: the map store's (:func:`map_layout`).
    """
    parts = estimate(study, nv, directions, workers, layout)
    _, key, _ = max(parts)
    source = study.source
    if key == "study.cycles" and cycles_set_by is not None:
        source, key = cycles_set_by
    check_parts([(size, what) for size, _, what in parts], "this run", f"lower {key}, or split the study into several",
                source, key, available)


def check_parts(parts: list[tuple[float, str]], task: str, advice: str, source, key: str | None,
                available: int | None = None) -> None:
    """An :class:`InputError` naming ``source`` and ``key`` if ``task`` (``"this run"``) needs more memory than is
    ``available`` [bytes] (default :func:`available_bytes`; no check when unknown): ``parts`` are ``(bytes, what)``,
    ``advice`` says what to do."""
    needed = sum(size for size, _ in parts)
    available = available_bytes() if available is None else available
    if available is None or needed <= available:
        return
    size, what = max(parts)
    raise InputError(f"{task} needs about {gib(needed)} of memory (mostly {gib(size)} for {what}), and "
                     f"{gib(available)} is available: {advice}", source, key)
