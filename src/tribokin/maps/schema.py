"""What a map keeps of each target: its figures and the store's columns, declared once.

The store's columns (:meth:`MapLayout.columns`), the bytes a target takes in it (:attr:`MapLayout.bytes_per_target`,
the memory and disk checks), the columns of ``map.csv`` and the figures ``summary.json`` summarises
are all derived from :data:`ALL_FIGURES` and the column tables below.
"""

from __future__ import annotations

from dataclasses import dataclass

from tribokin.maps.store import row_bytes
from tribokin.study.assembly import MapRobots
from tribokin.study.map_spec import FIGURE_SETS


@dataclass(frozen=True)
class MapFigure:
    """A scalar figure of every target, per scenario.

    Attributes:
        name: its column in ``map.csv`` and its key in ``summary.json``, the unit as suffix (``_um``, ``_mdeg``;
            none: dimensionless).
        summarised: ``summary.json`` gives its min, exact median and max over the map.
        after_dominant_joint: ``map.csv`` gives it after the dominant joint's name (a figure of that joint).
        sets: the figure sets that have it (:attr:`~tribokin.study.map_spec.MapSpec.figure_set`).
        per_direction: ISO's figure per approach direction: a map approached from both (``bidirectional``,
            ``random``) gives each direction's in its own columns (:func:`direction_figure`), and in this one the
            larger of the two.
    """

    name: str
    summarised: bool = False
    after_dominant_joint: bool = False
    sets: tuple[str, ...] = FIGURE_SETS
    per_direction: bool = False


_EXPECTED = ("expected", "directional")
#: The figures of every map target, in the store's order (µm, mdeg; ``dominant_share`` in [0, 1]); an expected map's
#: RP_l band of one test (2.5 and 97.5 %) and a directional map's vAP_p (along +x, +y, +z) and RP_l_multi (cycles
#: from random joint-space directions) are their own.
ALL_FIGURES = (MapFigure("RP_l_um", summarised=True, per_direction=True),
               MapFigure("RP_l_lo_um", sets=_EXPECTED, per_direction=True),
               MapFigure("RP_l_hi_um", sets=_EXPECTED, per_direction=True),
               MapFigure("AP_p_um", summarised=True, per_direction=True),
               MapFigure("vAP_p_um", summarised=True, sets=("directional",)),
               MapFigure("RP_l_multi_um", summarised=True, sets=("directional",)),
               MapFigure("RP_a_mdeg", per_direction=True), MapFigure("RP_b_mdeg", per_direction=True),
               MapFigure("RP_c_mdeg", per_direction=True),
               MapFigure("largest_semi_axis_um"), MapFigure("dominant_share", after_dominant_joint=True))
#: The approach directions of a map approached from both, by the suffix of their figures' names.
DIRECTIONS = ("plus", "minus")
#: A one-test map approached from both directions also gives RP_l of every cycle pooled (as poses name it).
POOLED = MapFigure("RP_l_all_directions_um", sets=("one-test",))


def direction_figure(name: str, direction: str) -> str:
    """The name of figure ``name`` of one approach ``direction`` (``"plus"``, ``"minus"``): ``<figure>_<direction>_
    <unit>`` (``RP_l_lo_um`` -> ``RP_l_lo_plus_um``)."""
    figure, unit = name.rsplit("_", 1)
    return f"{figure}_{direction}_{unit}"


def per_direction(approach: str) -> bool:
    """Whether a map of ``approach`` mode gives its figures per approach direction: approached from both."""
    return approach != "unidirectional"


def study_approaches(study) -> tuple[str, ...]:
    """The approach mode of each scenario of a :class:`~tribokin.study.spec.Study`'s map (the study's own without
    scenarios), for :meth:`MapLayout.of`."""
    return tuple(s.study.approach for s in study.scenarios) or (study.approach,)


def map_figures(figure_set: str, both_directions: bool = False) -> tuple[MapFigure, ...]:
    """The figures of a map's ``figure_set`` (:data:`~tribokin.study.map_spec.FIGURE_SETS`), in the store's order;
    ``both_directions`` (a map approached from both, :func:`per_direction`): then each direction's figures
    (:data:`DIRECTIONS`, :func:`direction_figure`), the + direction's first, and a one-test map's pooled RP_l."""
    figures = tuple(figure for figure in ALL_FIGURES if figure_set in figure.sets)
    if not both_directions:
        return figures
    split = tuple(MapFigure(direction_figure(figure.name, direction), figure.summarised, sets=figure.sets)
                  for direction in DIRECTIONS for figure in figures if figure.per_direction)
    return figures + split + ((POOLED,) if figure_set in POOLED.sets else ())


def figure_index(name: str, figure_set: str, both_directions: bool = False) -> int:
    """Place of figure ``name`` in :func:`map_figures` (its column in the store's ``figures``)."""
    return [figure.name for figure in map_figures(figure_set, both_directions)].index(name)


def figure_stem(name: str) -> str:
    """Figure ``name`` without its unit (``RP_l_um``: ``RP_l``): the stem of its error's names."""
    for unit in ("_um", "_mdeg"):
        name = name.removesuffix(unit)
    return name


def mc_error_name(name: str) -> str:
    """The ``map.csv`` column of figure ``name``'s relative Monte Carlo standard error (``RP_l_um``:
    ``RP_l_mc_error``); ``summary.json`` gives its largest as ``<stem>_max_mc_error``."""
    return f"{figure_stem(name)}_mc_error"


#: A map's change from its ``state`` to its ``compare`` state (:attr:`~tribokin.study.map_spec.MapSpec.compare`), end
#: minus start, signed [µm]: RP_l's and AP_p's (the figures of each state's tests, not ISO 9283's drift figures, which
#: are absolute differences within one test).
CHANGE_FIGURES = ("RP_l_change_um", "AP_p_change_um")
#: The figures each change is of (:func:`~tribokin.maps.schema.figure_index`).
CHANGED_FIGURES = ("RP_l_um", "AP_p_um")


def change_error_name(name: str) -> str:
    """The ``map.csv`` column of change ``name``'s Monte Carlo standard error, in its unit (``RP_l_change_um``:
    ``RP_l_change_mc_error_um``): the paired tests' (:func:`~tribokin.maps.expected_figures.change_errors`)."""
    return f"{figure_stem(name)}_mc_error_um"


def change_bound_name(name: str) -> str:
    """The ``map.csv`` column of change ``name``'s bound from the engines' bounds [µm] (``RP_l_change_um``:
    ``RP_l_change_engine_bound_um``): the two states' figure-level errors summed (:func:`~tribokin.maps.mapping.
    change_figures`)."""
    return f"{figure_stem(name)}_engine_bound_um"


def table_figures(figure_set: str, both_directions: bool = False) -> list[str]:
    """The figures' columns of ``map.csv`` in order, ``dominant_joint`` (the joint's name) among them."""
    figures = map_figures(figure_set, both_directions)
    names = [figure.name for figure in figures if not figure.after_dominant_joint]
    return names + ["dominant_joint"] + [figure.name for figure in figures if figure.after_dominant_joint]


@dataclass(frozen=True)
class MapColumn:
    """A column of the map's store.

    Attributes:
        name: the column's name (per scenario: :func:`scenario_column` of it).
        width: values per target: a number, ``"joints"`` (one per active joint), ``"figures"`` (one per
            :func:`map_figures`), or ``None`` (one value, no axis).
        dtype: NumPy type code.
        sets: the figure sets whose maps have it.
        change: only a map that compares two states has it (:data:`CHANGE_FIGURES`).
    """

    name: str
    width: int | str | None
    dtype: str
    sets: tuple[str, ...] = FIGURE_SETS
    change: bool = False

    def shape(self, nv: int, figure_set: str, both_directions: bool = False) -> tuple[int, ...]:
        """Shape of one target's value, with ``nv`` active joints (``both_directions``: :func:`map_figures`)."""
        if self.width is None:
            return ()
        return ({"joints": nv, "figures": len(map_figures(figure_set, both_directions))}.get(self.width, self.width),)


#: Columns of every target (see :class:`~tribokin.maps.result.MapResult`).
TARGET_COLUMNS = (MapColumn("position_m", 3, "f8"),)
#: Columns of every target per robot of the map's scenarios (:func:`robot_column`): its IK's outcome.
ROBOT_COLUMNS = (MapColumn("q", "joints", "f8"), MapColumn("reachable", None, "?"), MapColumn("closest", 2, "f8"),
                 MapColumn("ik_route", None, "i1"))
#: Columns of every target per scenario (see :class:`~tribokin.maps.result.ScenarioMap`); an expected map's also
#: say how its figures were computed (:func:`~tribokin.maps.expected_figures.expected_targets`).
SCENARIO_COLUMNS = (MapColumn("figures", "figures", "f8"), MapColumn("normal_forces_N", "joints", "f8"),
                    MapColumn("dominant_joint", None, "i8"), MapColumn("method", None, "i8", _EXPECTED),
                    MapColumn("fallbacks", None, "i8", _EXPECTED), MapColumn("engine", None, "i1", _EXPECTED),
                    MapColumn("engine_bound", 2, "f8", _EXPECTED),
                    MapColumn("figure_errors", "figures", "f8", _EXPECTED),
                    MapColumn("mc_errors", "figures", "f8", _EXPECTED),
                    MapColumn("change", len(CHANGE_FIGURES), "f8", change=True),
                    MapColumn("change_mc_errors", len(CHANGE_FIGURES), "f8", _EXPECTED, change=True),
                    MapColumn("change_engine_bounds", len(CHANGE_FIGURES), "f8", _EXPECTED, change=True))


def scenario_column(scenario: int, name: str) -> str:
    """Store column of scenario number ``scenario``'s ``name`` (``figures``, ``normal_forces_N``,
    ``dominant_joint``...)."""
    return f"scenario{scenario}_{name}"


def robot_column(robot: int, name: str) -> str:
    """Store column (or record) of the map's robot number ``robot``'s ``name`` (``q``, ``reachable``, ``closest``,
    ``ik_route``):
    the first robot's (the study's) plain, the others' ``robot<k>_<name>``."""
    return name if robot == 0 else f"robot{robot}_{name}"


@dataclass(frozen=True)
class MapLayout:
    """What a map's store holds: ``joints``, the active joints of each robot its scenarios measure with (the study's
    first), ``places``, each scenario's robot (an index in ``joints``), the ``figure_set``, ``directions``, the
    scenarios approached from both directions (:func:`per_direction`; empty: none), and ``change``: the map compares
    two states (:data:`CHANGE_FIGURES`)."""

    joints: tuple[int, ...]
    places: tuple[int, ...]
    figure_set: str
    directions: tuple[bool, ...] = ()
    change: bool = False

    @classmethod
    def of(cls, robots: MapRobots, figure_set: str, approaches: tuple[str, ...] = (),
           change: bool = False) -> MapLayout:
        """The layout of the map's ``robots`` (:func:`~tribokin.study.assembly.map_robots`), its scenarios
        approached in modes ``approaches`` (``()``: unidirectional), comparing two states or not."""
        return cls(tuple(robot.model.nv for robot in robots.robots), robots.places, figure_set,
                   tuple(per_direction(approach) for approach in approaches), change)

    @classmethod
    def shared(cls, nv: int, scenarios: int, figure_set: str, approaches: tuple[str, ...] = (),
               change: bool = False) -> MapLayout:
        """The layout of ``scenarios`` scenarios measured with one robot of ``nv`` active joints (``approaches``,
        ``change``: as :meth:`of`)."""
        return cls((nv,), (0,) * scenarios, figure_set, tuple(per_direction(approach) for approach in approaches),
                   change)

    def both_directions(self, scenario: int) -> bool:
        """Whether scenario number ``scenario`` is approached from both directions (:func:`map_figures`)."""
        return bool(self.directions) and self.directions[scenario]

    def scenarios_of(self, robot: int) -> list[int]:
        """The scenarios measured with robot ``robot``, in the study's order."""
        return [s for s, place in enumerate(self.places) if place == robot]

    def columns(self, robot: int | None = None) -> dict[str, tuple[tuple, str]]:
        """The store's columns, ``name -> (shape of one target's value, dtype)``: every one, or (``robot``) those
        robot ``robot``'s IK and its scenarios fill."""
        columns = {} if robot is not None else {column.name: (column.shape(0, self.figure_set), column.dtype)
                                                for column in TARGET_COLUMNS}
        for r, nv in enumerate(self.joints):
            if robot in (None, r):
                columns.update({robot_column(r, column.name): (column.shape(nv, self.figure_set), column.dtype)
                                for column in ROBOT_COLUMNS})
        for s, r in enumerate(self.places):
            if robot in (None, r):
                columns.update({scenario_column(s, column.name): (column.shape(self.joints[r], self.figure_set,
                                                                               self.both_directions(s)), column.dtype)
                                for column in SCENARIO_COLUMNS
                                if self.figure_set in column.sets and (self.change or not column.change)})
        return columns

    @property
    def bytes_per_target(self) -> int:
        """Bytes a target takes in the store (:meth:`columns`)."""
        return row_bytes(self.columns())
