"""The ``[map]`` kinds of a study: a plane or a box of tool positions, or a grid of joint values.

Each kind knows its own grid: the targets along each axis (columns first), their count, its grid rows
and the key that sets its size. The values are checked when the study is read (:mod:`tribokin.study.spec`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

from tribokin.tribology.friction_series import FrictionState

#: ``map.statistic``: the expected figures over tests of ``cycles`` cycles (:mod:`tribokin.maps.expected_figures`), or
#: one simulated test per target (:mod:`tribokin.maps.measure`).
STATISTICS = ("expected", "one-test")
#: The sets of figures a map target has (:attr:`MapSpec.figure_set`).
FIGURE_SETS = ("one-test", "expected", "directional")
#: A map chunk holds at most about this many targets, in whole grid rows split evenly between the chunks
#: (``map.chunk_rows`` overrides). A chunk's rows are solved together column by column
#: (:func:`tribokin.maps.rows.solve_rows`), so the more rows, the less each target pays of NumPy's per-call costs
#: (``benchmarks/ik.py`` measures it against the rows per batch); a chunk's columns take about 260 bytes a target
#: (a 600 x 600 plane: 4 chunks of 150 rows; 1000 x 1000: 8 of 125).
CHUNK_TARGETS = 131072
#: A grid of this many rows or more makes at least this many chunks, so that several workers share even a small map.
MIN_CHUNKS = 4

Vector3 = tuple[float, float, float]


@dataclass(frozen=True, kw_only=True)
class MapSpec:
    """What every ``[map]`` has: ``start_q`` [m or rad] (the IK's start posture, or the other joints' posture of
    a joint grid; ``None``: chosen) and ``chunk_rows`` (grid rows per chunk; ``None``: :attr:`rows_per_chunk`),
    ``statistic`` (``"expected"``: each figure's mean over tests, or ``"one-test"``) and ``directional``
    (an expected map's vAP_p and RP_l_multi too: the default; a study's ``map.directional = false`` turns them off, a
    one-test map has none), ``state`` (where the joints' friction series start in every test:
    :class:`~tribokin.tribology.friction_series.FrictionState`; ``None``: each joint's own age, cold) and ``compare``
    (a second state: the change of RP_l and AP_p from ``state`` to it; ``None``: none). Each kind has ``counts``: the
    targets along each axis, columns first."""

    kind: ClassVar[str]
    #: The study key that sets the number of targets.
    size_key: ClassVar[str] = "map.resolution"

    start_q: tuple[float, ...] | None = None
    chunk_rows: int | None = None
    statistic: str = "expected"
    directional: bool = True
    state: FrictionState | None = None
    compare: FrictionState | None = None

    @property
    def figure_set(self) -> str:
        """Which figures each target has (:data:`FIGURE_SETS`): ``"one-test"``, ``"expected"`` or, with
        ``directional``, ``"directional"`` (the expected ones, vAP_p and RP_l_multi besides)."""
        return "one-test" if self.statistic == "one-test" else "directional" if self.directional else "expected"

    @property
    def target_count(self) -> int:
        """Every grid point, reachable or not."""
        return math.prod(self.counts)

    @property
    def row_length(self) -> int:
        """Targets of one grid row."""
        return self.counts[0]

    @property
    def grid_rows(self) -> int:
        """Grid rows (all layers)."""
        return self.target_count // self.row_length

    @property
    def rows_per_chunk(self) -> int:
        """Grid rows a chunk computes: ``chunk_rows``, default the grid's rows split evenly into as many chunks as rows
        of about ``CHUNK_TARGETS`` targets would make, and at least ``MIN_CHUNKS`` (or one a row)."""
        if self.chunk_rows:
            return self.chunk_rows
        chunks = max(math.ceil(self.grid_rows / math.ceil(CHUNK_TARGETS / self.row_length)),
                     min(MIN_CHUNKS, self.grid_rows))
        return math.ceil(self.grid_rows / chunks)

    @property
    def chunk_targets(self) -> int:
        """Targets of the largest chunk."""
        return min(self.rows_per_chunk * self.row_length, self.target_count)


@dataclass(frozen=True, kw_only=True)
class CartesianMap(MapSpec):
    """Tool positions: ``resolution`` points along each axis, at tool orientation ``rpy_deg`` [deg] (``None``: the
    start posture's)."""

    resolution: tuple[int, ...]
    rpy_deg: Vector3 | None = None

    @property
    def counts(self) -> tuple[int, ...]:
        """Targets along each axis, columns first."""
        return self.resolution


@dataclass(frozen=True, kw_only=True)
class PlaneMap(CartesianMap):
    """Tool positions on a plane: ``origin_m + u·axis_u + v·axis_v`` [m], ``u`` and ``v`` spanning ``extent_u_m``
    and ``extent_v_m`` [m] in ``resolution`` = (nu, nv) points."""

    kind: ClassVar[str] = "plane"

    origin_m: Vector3
    axis_u: Vector3
    axis_v: Vector3
    extent_u_m: tuple[float, float]
    extent_v_m: tuple[float, float]


@dataclass(frozen=True, kw_only=True)
class BoxMap(CartesianMap):
    """Tool positions in a box from ``min_m`` to ``max_m`` [m], ``resolution`` = (nx, ny, nz) points."""

    kind: ClassVar[str] = "box"

    min_m: Vector3
    max_m: Vector3


@dataclass(frozen=True, kw_only=True)
class JointMap(MapSpec):
    """1 to 3 ``joints`` each over its ``ranges`` entry [m or rad] in ``counts`` values; the others at ``start_q``."""

    kind: ClassVar[str] = "joint"
    size_key: ClassVar[str] = "map.counts"

    joints: tuple[str, ...]
    ranges: tuple[tuple[float, float], ...]
    counts: tuple[int, ...]


#: ``map.kind`` -> its spec.
MAP_SPECS = {cls.kind: cls for cls in (PlaneMap, BoxMap, JointMap)}
