"""What a map keeps of each target: its figures and the store's columns, declared once.

The store's columns (:func:`map_columns`), the bytes a target takes in it (:func:`map_bytes_per_target`,
the memory and disk checks), the columns of ``map.csv`` and the figures ``summary.json`` summarises
are all derived from :data:`MAP_FIGURES` and the column tables below.
"""

from __future__ import annotations

from dataclasses import dataclass

from tribokin.maps.store import row_bytes


@dataclass(frozen=True)
class MapFigure:
    """A scalar figure of every target, per scenario.

    Attributes:
        name: its column in ``map.csv`` and its key in ``summary.json``, the unit as suffix (``_um``, ``_mdeg``;
            none: dimensionless).
        summarised: ``summary.json`` gives its min, exact median and max over the map.
        after_dominant_joint: ``map.csv`` gives it after the dominant joint's name (a figure of that joint).
    """

    name: str
    summarised: bool = False
    after_dominant_joint: bool = False


#: The figures of every map target, in the store's order (µm, mdeg; ``dominant_share`` in [0, 1]).
MAP_FIGURES = (MapFigure("RP_l_um", summarised=True), MapFigure("AP_p_um", summarised=True),
               MapFigure("RP_a_mdeg"), MapFigure("RP_b_mdeg"), MapFigure("RP_c_mdeg"),
               MapFigure("largest_semi_axis_um"), MapFigure("dominant_share", after_dominant_joint=True))


def figure_index(name: str) -> int:
    """Place of figure ``name`` in :data:`MAP_FIGURES` (its column in the store's ``figures``)."""
    return [figure.name for figure in MAP_FIGURES].index(name)


def table_figures() -> list[str]:
    """The figures' columns of ``map.csv`` in order, ``dominant_joint`` (the joint's name) among them."""
    names = [figure.name for figure in MAP_FIGURES if not figure.after_dominant_joint]
    return names + ["dominant_joint"] + [figure.name for figure in MAP_FIGURES if figure.after_dominant_joint]


@dataclass(frozen=True)
class MapColumn:
    """A column of the map's store.

    Attributes:
        name: the column's name (per scenario: :func:`scenario_column` of it).
        width: values per target: a number, ``"joints"`` (one per active joint), ``"figures"`` (one per
            :data:`MAP_FIGURES`), or ``None`` (one value, no axis).
        dtype: NumPy type code.
    """

    name: str
    width: int | str | None
    dtype: str

    def shape(self, nv: int) -> tuple[int, ...]:
        """Shape of one target's value, with ``nv`` active joints."""
        if self.width is None:
            return ()
        return ({"joints": nv, "figures": len(MAP_FIGURES)}.get(self.width, self.width),)


#: Columns of every target (see :class:`~tribokin.maps.result.MapResult`).
TARGET_COLUMNS = (MapColumn("position_m", 3, "f8"), MapColumn("q", "joints", "f8"), MapColumn("reachable", None, "?"),
                  MapColumn("closest", 2, "f8"))
#: Columns of every target per scenario (see :class:`~tribokin.maps.result.ScenarioMap`).
SCENARIO_COLUMNS = (MapColumn("figures", "figures", "f8"), MapColumn("normal_forces_N", "joints", "f8"),
                    MapColumn("dominant_joint", None, "i8"))


def scenario_column(scenario: int, name: str) -> str:
    """Store column of scenario number ``scenario``'s ``name`` (``figures``, ``normal_forces_N``, ``dominant_joint``)."""
    return f"scenario{scenario}_{name}"


def map_columns(nv: int, scenarios: int) -> dict[str, tuple[tuple, str]]:
    """The store's columns of a map with ``nv`` active joints and ``scenarios`` scenarios:
    ``name -> (shape of one target's value, dtype)``."""
    columns = {column.name: (column.shape(nv), column.dtype) for column in TARGET_COLUMNS}
    for s in range(scenarios):
        columns.update({scenario_column(s, column.name): (column.shape(nv), column.dtype)
                        for column in SCENARIO_COLUMNS})
    return columns


def map_bytes_per_target(nv: int, scenarios: int) -> int:
    """Bytes a target takes in the store (:func:`map_columns`)."""
    return row_bytes(map_columns(nv, scenarios))
