"""Every random stream of a run, one function per purpose, so no two purposes share numbers by accident.

A stream depends on its arguments only (never on the order of work, the chunking, the workers or a
resume), and each call returns a new generator at the stream's start. Study-seeded streams are the
study seed's :class:`numpy.random.SeedSequence` with the spawn key ``(index, purpose)``; the searches
for postures (IK restarts) use fixed seeds, so a robot's cube and map targets do not change with the
study's seed. One coincidence is kept, so that the numbers stay as they were: SeedSequence pads its
entropy with zeros, so the IK restarts of map target 0 equal :func:`posture_search`.
"""

from __future__ import annotations

import numpy as np

#: Spawn-key purposes of the study-seeded streams: a pose's cycles, its replicate tests, a map target's cycles,
#: an expected map's common random numbers, a pose's drift tests.
POSE, POSE_REPLICATES, MAP_TARGET, EXPECTED, DRIFT = 0, 1, 2, 3, 4
#: Seed of the fixed streams: posture searches and IK restarts.
SEARCH_SEED = 9283


def _seeded(seed: int, index: int, purpose: int) -> np.random.Generator:
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(index, purpose)))


def pose_stream(seed: int, index: int) -> np.random.Generator:
    """The cycles of pose ``index`` of a study seeded ``seed`` (approach order, friction, noise)."""
    return _seeded(seed, index, POSE)


def replicate_stream(seed: int, index: int) -> np.random.Generator:
    """The replicate tests of pose ``index`` (the 95 % interval of RP_l)."""
    return _seeded(seed, index, POSE_REPLICATES)


def drift_stream(seed: int, index: int) -> np.random.Generator:
    """The simulated drift tests of pose ``index`` (``[drift]``: :mod:`tribokin.simulation.drift`)."""
    return _seeded(seed, index, DRIFT)


def map_target_stream(seed: int, index: int) -> np.random.Generator:
    """The cycles of map target ``index``; every scenario draws the same (common random numbers)."""
    return _seeded(seed, index, MAP_TARGET)


def expected_stream(seed: int, purpose: str) -> np.random.Generator:
    """The common random numbers of an expected map (:mod:`tribokin.maps.expected_figures`), the same at every target
    and scenario: ``purpose`` names them (``"table"``, ``"tests"``, ``"signs"``, ``"vap"``, ``"multi"``, ...)."""
    return _seeded(seed, int.from_bytes(purpose.encode(), "little"), EXPECTED)


def ik_restart_stream(index: int) -> np.random.Generator:
    """The random IK restarts of map target ``index``."""
    return np.random.default_rng([SEARCH_SEED, index])


def posture_search() -> np.random.Generator:
    """Random postures searched for a well-conditioned one, and the IK restarts placing the ISO cube."""
    return np.random.default_rng(SEARCH_SEED)
