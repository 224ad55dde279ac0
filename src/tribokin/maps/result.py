"""Results of a workspace map: every target's figures per scenario, read from the map's store."""

from __future__ import annotations

from collections.abc import Iterator
from concurrent.futures import Executor, Future
from dataclasses import dataclass, field

import numpy as np

from tribokin.kinematics.robot import Robot
from tribokin.maps.expected_figures import ANALYTIC, SAMPLED, TARGET_ENGINES, stated_figures
from tribokin.maps.frames import map_dataset, map_frame
from tribokin.maps.grid import TargetGrid
from tribokin.maps.rows import IK_ROUTES, unreachable_reasons
from tribokin.maps.schema import (
    CHANGE_FIGURES,
    figure_index,
    figure_stem,
    map_figures,
    robot_column,
    scenario_column,
)
from tribokin.maps.store import ChunkStore
from tribokin.maps.streaming import Spread, blocks, spread
from tribokin.output.dispatch import result_figures, result_scene

#: What a map approached from both directions says of its unsuffixed figures (``summary.json``).
DIRECTIONS_NOTE = ("RP_l, its band, AP_p and RP_a/b/c: the larger of the + and - approach directions' (ISO's "
                   "figure per direction; each direction's in <figure>_plus_<unit>, <figure>_minus_<unit>)")
#: Who reaches a target, as :meth:`MapResult.reached_by` gives it: a scenario's robot and the reference's, the
#: scenario's only, the reference's only, neither.
REACHED_BY = ("both", "this only", "reference only", "neither")


@dataclass
class ScenarioMap:
    """One scenario's figures at every target of a map (NaN where unreachable), read from the map's store.

    Attributes:
        name: scenario name. cycles: cycles per target.
        number: the scenario's place in the study (its columns in the store).
        joint_names: active joints, in the order of ``q`` (the names of ``dominant_joint``'s indices).
        store: where the columns are (:class:`~tribokin.maps.store.ChunkStore`).
        figure_set: which figures it has (:attr:`~tribokin.study.map_spec.MapSpec.figure_set`,
            :func:`~tribokin.maps.schema.map_figures`).
        robot: the robot it is measured with, its number among the map's (0: the study's); its IK's columns
            (:meth:`read_robot`).
        both_directions: approached from both directions (``bidirectional``, ``random``): each direction's figures
            too, and RP_l, AP_p, RP_a/b/c (and the band) the larger of the two
            (:func:`~tribokin.maps.schema.map_figures`).
        engine: its ``study.engine``: ``"fast"`` (an expected map's engine chosen at each target by the bound) or
            ``"exact"`` (an expected map's every figure sampled through exact FK).
        change: the map compares two states of the joints' friction series: each target's change from the first to
            the second (:data:`~tribokin.maps.schema.CHANGE_FIGURES`, :meth:`change`).
    """

    name: str
    cycles: int
    number: int
    joint_names: list[str]
    store: ChunkStore = field(repr=False)
    figure_set: str
    robot: int = 0
    both_directions: bool = False
    engine: str = "fast"
    change: bool = False

    def read_robot(self, name: str, targets=slice(None)) -> np.ndarray:
        """Its robot's column ``name`` at ``targets``: ``q`` (k, nv) [m or rad] (NaN where unreachable),
        ``reachable`` (k,), ``closest`` (k, 2) (:class:`MapResult`)."""
        return self.store.read(robot_column(self.robot, name), targets)

    def read(self, name: str, targets=slice(None), item: int | None = None) -> np.ndarray:
        """Column ``name`` at ``targets`` (with ``item``, only that element of each target's value:
        :meth:`~tribokin.maps.store.ChunkStore.read`): ``figures`` (k, len(map_figures(figure_set))),
        ``normal_forces_N`` (k, nv) bearing loads [N], ``dominant_joint`` (k,) index in ``joint_names`` of the joint
        with the largest share of the position variance (-1: none); an expected map's ``method``, ``fallbacks``,
        ``engine``, ``engine_bound``, ``figure_errors``, ``mc_errors``
        (:func:`~tribokin.maps.expected_figures.expected_targets`)."""
        return self.store.read(scenario_column(self.number, name), targets, item)

    def figure(self, name: str, targets=slice(None)) -> np.ndarray:
        """Figure ``name`` (:func:`~tribokin.maps.schema.map_figures`) at ``targets`` (default: all; read the whole
        column only for small maps)."""
        return self.read("figures", targets, figure_index(name, self.figure_set, self.both_directions))

    def figure_error(self, name: str, targets=slice(None)) -> np.ndarray:
        """An expected map's bound [µm, mdeg] on how far figure ``name`` at ``targets`` may lie from the same figure
        through exact FK, derived from the bound of the engine that computed it
        (:func:`~tribokin.maps.expected_figures.figure_errors`)."""
        return self.read("figure_errors", targets, figure_index(name, self.figure_set, self.both_directions))

    def mc_error(self, name: str, targets=slice(None)) -> np.ndarray:
        """An expected map's relative Monte Carlo standard error of figure ``name`` at ``targets`` (0: in closed form;
        :func:`~tribokin.maps.expected_figures.expected_targets`)."""
        return self.read("mc_errors", targets, figure_index(name, self.figure_set, self.both_directions))

    def change_figure(self, name: str, targets=slice(None)) -> np.ndarray:
        """Change ``name`` (:data:`~tribokin.maps.schema.CHANGE_FIGURES`) [µm] at ``targets``: the figure in the map's
        ``compare`` state less the figure in its ``state`` (NaN where unreachable)."""
        return self.read("change", targets, CHANGE_FIGURES.index(name))

    def change_error(self, name: str, targets=slice(None)) -> np.ndarray:
        """Change ``name``'s Monte Carlo standard error [µm] at ``targets`` (an expected map's): its paired tests'
        (:func:`~tribokin.maps.expected_figures.change_errors`)."""
        return self.read("change_mc_errors", targets, CHANGE_FIGURES.index(name))

    def change_bound(self, name: str, targets=slice(None)) -> np.ndarray:
        """Change ``name``'s bound [µm] at ``targets`` (an expected map's) on how far it may lie from the same change
        through exact FK: its two figures' :meth:`figure_error` in the two states, summed
        (:func:`~tribokin.maps.mapping.change_figures`)."""
        return self.read("change_engine_bounds", targets, CHANGE_FIGURES.index(name))

    def has(self, name: str) -> bool:
        """Whether the map has figure ``name``."""
        return name in [figure.name for figure in self.figure_list]

    @property
    def figure_list(self) -> tuple:
        """Its figures (:func:`~tribokin.maps.schema.map_figures`), in the store's order."""
        return map_figures(self.figure_set, self.both_directions)

    @property
    def figures(self) -> np.ndarray:
        """(N, figures) figures of every target (the whole column, in memory)."""
        return self.read("figures")

    @property
    def normal_forces_N(self) -> np.ndarray:
        """(N, nv) bearing loads of every target [N]."""
        return self.read("normal_forces_N")

    @property
    def dominant_joint(self) -> np.ndarray:
        """(N,) index in ``joint_names`` of each target's dominant joint (-1: none); :meth:`dominant_joint_names`
        gives the names."""
        return self.read("dominant_joint")

    def dominant_joint_names(self, targets=slice(None)) -> np.ndarray:
        """Name of the dominant joint at each of ``targets`` (``""``: none, e.g. unreachable), as Python strings."""
        return np.array([*self.joint_names, ""], dtype=object)[self.read("dominant_joint", targets)]


@dataclass(frozen=True)
class ScenarioStatistics:
    """One scenario's statistics over a map's targets (:class:`MapStatistics`).

    Attributes:
        name: the scenario's name.
        RP_l_um: min, median and max of its RP_l over the targets its robot reaches [µm].
        wins: the targets where its RP_l is the smallest among the scenarios whose robots reach them (``None``: the
            map's only scenario).
        reachable: the targets its robot reaches (``None``: every scenario is measured with the study's robot).
    """

    name: str
    RP_l_um: Spread
    wins: int | None = None
    reachable: int | None = None


@dataclass(frozen=True)
class MapStatistics:
    """A map's statistics over its targets, computed once (:meth:`MapResult.statistics`): the figures the command
    prints, and the ``map`` block of ``summary.json`` made of them.

    Attributes:
        count: the targets, reachable or not.
        reachable: the targets the study's robot reaches.
        RP_l_um: min, median and max of the reference's RP_l over them [µm].
        scenarios: each scenario's, in the study's order (the reference first; one: the map's only scenario).
        summary: the ``map`` block of ``summary.json``.
        reached_by_any: the targets any scenario's robot reaches (``None``: one robot measures every scenario).
        RP_l_change_um, AP_p_change_um: a map comparing two states (``compare``): min, median and max of each target's
            change from the first state to the second [µm] (``None``: none compared).
    """

    count: int
    reachable: int
    RP_l_um: Spread
    scenarios: tuple[ScenarioStatistics, ...]
    summary: dict = field(repr=False)
    reached_by_any: int | None = None
    RP_l_change_um: Spread | None = None
    AP_p_change_um: Spread | None = None


@dataclass
class MapResult:
    """A workspace map: the targets, their configurations, and each scenario's figures there, kept on
    disk in ``store`` and read back block by block (:meth:`blocks`), so its size is not bounded by memory.

    Attributes:
        grids: the targets (axes, held orientation) as each robot of the scenarios reaches them (its reach bounds),
            the study's robot's first.
        joint_names: the study robot's active joints, in the order of ``q``.
        store: the per-target columns: ``position_m`` (N, 3) target positions [m]; the study robot's ``q`` (N, nv)
            configurations [m or rad] (NaN where unreachable), ``reachable`` (N,), ``closest`` (N, 2) how
            close the IK came to unreachable targets [m, rad] (beyond the robot's reach: how far beyond [m],
            NaN), and the same of each other robot (:func:`~tribokin.maps.schema.robot_column`); each scenario's
            (:class:`ScenarioMap`).
        scenarios: one :class:`ScenarioMap` per scenario, by name, in the study's order; the first is the
            reference of comparisons (measured with the study's robot).
        robot: the study's robot, which the 3-D scene draws (:meth:`_repr_html_`; ``None``: no scene).
        states: where the tests' friction series start, where a joint's friction is a time series: ``state`` and
            ``compare`` (:meth:`~tribokin.tribology.friction_series.FrictionState.describe`); empty: none.
    """

    grids: tuple[TargetGrid, ...]
    joint_names: list[str]
    store: ChunkStore = field(repr=False)
    scenarios: dict[str, ScenarioMap]
    robot: Robot | None = field(default=None, repr=False)
    states: dict = field(default_factory=dict)
    _statistics: MapStatistics | Future | None = field(default=None, init=False, repr=False)

    def __getstate__(self) -> dict:
        """What a worker gets: the map without this process's statistics, or their computation under way."""
        return {**self.__dict__, "_statistics": None}

    @property
    def grid(self) -> TargetGrid:
        """The targets, as the study's robot reaches them."""
        return self.grids[0]

    @property
    def reference(self) -> ScenarioMap:
        return next(iter(self.scenarios.values()))

    @property
    def robot_count(self) -> int:
        """How many robots (kinematics, bases, tools) the scenarios are measured with."""
        return len(self.grids)

    def blocks(self, block: int | None = None) -> Iterator[slice]:
        """The targets in consecutive blocks of ``block`` targets (default :data:`~tribokin.maps.streaming.
        BLOCK_TARGETS`)."""
        return blocks(self.grid.size, block)

    def read(self, name: str, targets=slice(None)) -> np.ndarray:
        """Store column ``name`` at ``targets``."""
        return self.store.read(name, targets)

    @property
    def q(self) -> np.ndarray:
        """(N, nv) configurations [m or rad] (the whole column, in memory)."""
        return self.read("q")

    @property
    def reachable(self) -> np.ndarray:
        return self.read("reachable")

    @property
    def positions_m(self) -> np.ndarray:
        """(N, 3) target positions [m]: commanded (plane, box), or reached at the configurations (joint maps)."""
        return self.read("position_m")

    def reasons(self, targets=slice(None), scenario: ScenarioMap | None = None) -> np.ndarray:
        """Why each of ``targets`` is unreachable (``""`` when reachable) by ``scenario``'s robot (default the
        study's), as Python strings."""
        robot = 0 if scenario is None else scenario.robot
        return unreachable_reasons(self.grids[robot], self.read("position_m", targets),
                                   self.read(robot_column(robot, "closest"), targets))

    def reached_by(self, scenario: ScenarioMap, targets=slice(None)) -> np.ndarray:
        """Who reaches each of ``targets``, as an index into ``REACHED_BY``: both ``scenario``'s robot and the
        reference's, ``scenario``'s only, the reference's only, or neither."""
        own, reference = scenario.read_robot("reachable", targets), self.reference.read_robot("reachable", targets)
        return np.where(own, np.where(reference, 0, 1), np.where(reference, 2, 3))

    def reached_by_any(self, targets=slice(None)) -> np.ndarray:
        """(k,) whether any scenario's robot reaches each of ``targets``."""
        return np.any([self.read(robot_column(r, "reachable"), targets) for r in range(self.robot_count)], axis=0)

    def ratio_RP_l(self, scenario: ScenarioMap, targets=slice(None)) -> np.ndarray:
        """RP_l of ``scenario`` over the reference's [-] (NaN where the reference's is 0 or unreachable)."""
        reference = self.reference.figure("RP_l_um", targets)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(reference > 0, scenario.figure("RP_l_um", targets) / reference, np.nan)

    def diff_RP_l_um(self, scenario: ScenarioMap, targets=slice(None)) -> np.ndarray:
        """RP_l of ``scenario`` minus the reference's [µm]."""
        return scenario.figure("RP_l_um", targets) - self.reference.figure("RP_l_um", targets)

    def winners(self, targets=slice(None)) -> np.ndarray:
        """Place in ``scenarios`` of the scenario with the smallest RP_l at each of ``targets``, among those whose
        robot reaches it; -1 for a tie or a target no scenario reaches."""
        rp = np.column_stack([s.figure("RP_l_um", targets) for s in self.scenarios.values()])
        rp = np.where(np.isnan(rp), np.inf, rp)
        ties = (rp == rp.min(axis=1, keepdims=True)).sum(axis=1) > 1
        return np.where(self.reached_by_any(targets) & ~ties, np.argmin(rp, axis=1), -1)

    def _counts(self) -> tuple[int, np.ndarray, np.ndarray, int]:
        """Reachable targets (by the study's robot); per joint, those it dominates; per scenario, the targets it
        wins; the targets any scenario's robot reaches."""
        reachable, dominant, wins = 0, np.zeros(len(self.joint_names), dtype=int), np.zeros(len(self.scenarios) + 1,
                                                                                           dtype=int)
        reached = 0
        for part in self.blocks():
            flags, any_flags = self.read("reachable", part), self.reached_by_any(part)
            reachable += int(flags.sum())
            reached += int(any_flags.sum())
            dominant += np.bincount(self.reference.read("dominant_joint", part)[flags] + 1,
                                    minlength=len(self.joint_names) + 1)[1:]
            if len(self.scenarios) > 1:
                wins += np.bincount(self.winners(part)[any_flags] + 1, minlength=len(self.scenarios) + 1)
        return reachable, dominant, wins, reached

    def ik_routes(self, robot: int = 0) -> dict[str, int]:
        """How many targets robot ``robot``'s IK reached by each route (:data:`~tribokin.maps.rows.IK_ROUTES`)."""
        counts = np.zeros(max(IK_ROUTES.values()) + 1, dtype=int)
        for part in self.blocks():
            counts += np.bincount(self.read(robot_column(robot, "ik_route"), part), minlength=len(counts))
        return {name: int(counts[route]) for name, route in IK_ROUTES.items()}

    def _reach_counts(self, scenario: ScenarioMap) -> dict[str, int]:
        """The targets ``scenario``'s robot reaches, and those it reaches and the reference's does not, and back."""
        counts = np.zeros(len(REACHED_BY), dtype=int)
        for part in self.blocks():
            counts += np.bincount(self.reached_by(scenario, part), minlength=len(REACHED_BY))
        return {"reachable": int(counts[0] + counts[1]), "reached_only_by_this": int(counts[1]),
                "reached_only_by_reference": int(counts[2]),
                **({"ik": self.ik_routes(scenario.robot)} if self.grid.kind != "joint" else {})}

    def statistics(self) -> MapStatistics:
        """The map's statistics, computed once: here, or on a worker (:meth:`summarise_on`), whose result it then
        waits for."""
        if isinstance(self._statistics, Future):
            self._statistics = self._statistics.result()
        if self._statistics is None:
            self._statistics = self._summarise()
        return self._statistics

    def summary(self) -> dict:
        """The ``map`` block of ``summary.json`` (:meth:`statistics`)."""
        return self.statistics().summary

    def change_rests_on(self) -> str | None:
        """``RP_l 0.012 / 3.4e-06, AP_p ...``: each change of the reference (:data:`CHANGE_FIGURES`) with its largest
        Monte Carlo standard error and largest bound from the engines' bounds over the targets [µm], from its
        ``computed`` block of :meth:`summary`, as the command prints them and the report shows them; ``None`` for a
        map without changes or without expected figures."""
        computed = self.summary().get("computed")
        if computed is None or not self.reference.change:
            return None
        own = computed[self.reference.name]
        return ", ".join(f"{figure_stem(name).removesuffix('_change')} "
                         f"{own[f'{figure_stem(name)}_max_mc_error_um']:.3g} / "
                         f"{own[f'{figure_stem(name)}_max_engine_bound_um']:.3g}" for name in CHANGE_FIGURES)

    def use_statistics(self, statistics: MapStatistics | Future) -> None:
        """Take ``statistics``, this map's computed elsewhere (or its future), as :meth:`statistics`."""
        self._statistics = statistics

    def summarise_on(self, pool: Executor) -> None:
        """Start computing :meth:`statistics` on a worker of ``pool`` (this machine's processes: they read the store),
        unless they are known or under way, while this process does other work."""
        if self._statistics is None:
            self._statistics = pool.submit(map_statistics, self)

    def _summarise(self) -> MapStatistics:
        reference, size = self.reference, self.grid.size
        reachable, dominant, wins, reached = self._counts()
        figures = {f.name: spread(lambda part, f=f: reference.figure(f.name, part), size)
                   for f in reference.figure_list if f.summarised}
        changes = {name: spread(lambda part, name=name: reference.change_figure(name, part), size)
                   for name in (CHANGE_FIGURES if reference.change else ())}
        several = len(self.scenarios) > 1
        reach = {s.name: self._reach_counts(s) for s in self.scenarios.values()} if self.robot_count > 1 else {}
        scenarios = tuple(ScenarioStatistics(
            s.name, figures["RP_l_um"] if s is reference else spread(lambda part, s=s: s.figure("RP_l_um", part), size),
            int(wins[place + 1]) if several else None, reach[s.name]["reachable"] if reach else None)
            for place, s in enumerate(self.scenarios.values()))
        block = {
            **self.grid.describe(),
            "count": size,
            "reachable": reachable,
            "unreachable": size - reachable,
            "cycles": reference.cycles,
            "statistic": "one-test" if reference.figure_set == "one-test" else "expected",
            "directional": reference.figure_set == "directional",
            **({"unsuffixed_figures": DIRECTIONS_NOTE} if reference.both_directions else {}),
            **{name: figure.as_dict() for name, figure in figures.items()},
            **self.states,
            **{name: change.as_dict() for name, change in changes.items()},
            "dominant_joint_counts": {name: int(count) for name, count in zip(self.joint_names, dominant, strict=True)},
        }
        if self.grid.kind != "joint":
            block["ik"] = self.ik_routes()
        if several:
            block["scenarios"] = [{
                "name": s.name,
                "cycles": s.cycles,
                **reach.get(s.name, {}),
                **({"unsuffixed_figures": DIRECTIONS_NOTE} if s.both_directions else {}),
                "RP_l_um": own.RP_l_um.as_dict(),
                "RP_l_ratio": spread(lambda part, s=s: self.ratio_RP_l(s, part), size).as_dict(),
                "RP_l_diff_um": spread(lambda part, s=s: self.diff_RP_l_um(s, part), size).as_dict(),
            } for s, own in zip(self.scenarios.values(), scenarios, strict=True)]
            if reach:
                block["reached_by_any"] = reached
            block["wins"] = {s.name: s.wins for s in scenarios}
            block["ties"] = int(wins[0])
        if reference.figure_set != "one-test":
            block["computed"] = {s.name: self._computed(s) for s in self.scenarios.values()}
        return MapStatistics(size, reachable, figures["RP_l_um"], scenarios, block, reached if reach else None,
                             changes.get("RP_l_change_um"), changes.get("AP_p_change_um"))

    def _computed(self, scenario: ScenarioMap) -> dict:
        """How an expected map's figures were computed: its ``study.engine`` (``engine``), targets per method and per
        engine (the least exact its figures rest on), fallbacks, the largest bound of the engines used against exact
        FK and each sampled figure's largest relative Monte Carlo standard error (``<stem>_max_mc_error``,
        :func:`~tribokin.maps.schema.figure_stem`; :mod:`tribokin.maps.expected_figures`)."""
        analytic = sampled = fallback = 0
        engines = np.zeros(len(TARGET_ENGINES), dtype=int)
        stated = stated_figures(scenario.figure_set, scenario.both_directions)
        bound, mc_errors = np.zeros(2), np.zeros(len(stated))
        columns = [figure_index(name, scenario.figure_set, scenario.both_directions) for name in stated]
        for part in self.blocks():
            flags = scenario.read_robot("reachable", part)
            method = scenario.read("method", part)[flags]
            analytic += int(np.sum(method == ANALYTIC))
            sampled += int(np.sum(method == SAMPLED))
            fallback += int(np.count_nonzero(scenario.read("fallbacks", part)[flags]))
            engines += np.bincount(scenario.read("engine", part)[flags], minlength=len(TARGET_ENGINES))
            bound = np.fmax(bound, np.nanmax(scenario.read("engine_bound", part)[flags], axis=0, initial=0.0))
            mc_errors = np.fmax(mc_errors, np.nanmax(scenario.read("mc_errors", part)[flags][:, columns], axis=0,
                                                     initial=0.0))
        change = {}
        for name in CHANGE_FIGURES if scenario.change else ():  # each change's largest Monte Carlo standard error
            stem = figure_stem(name)  # and largest bound from the engines' bounds [µm]
            change[f"{stem}_max_mc_error_um"] = spread(lambda part, name=name: scenario.change_error(name, part),
                                                       self.grid.size).max
            change[f"{stem}_max_engine_bound_um"] = spread(lambda part, name=name: scenario.change_bound(name, part),
                                                           self.grid.size).max
        return {"engine": scenario.engine, "analytic_targets": analytic, "sampled_targets": sampled,
                "fallback_targets": fallback,
                "engine_targets": {name: int(count) for name, count in zip(TARGET_ENGINES, engines, strict=True)},
                "engine_max_deviation_nm": float(bound[0] * 1e9),
                "engine_max_angle_deviation_nrad": float(bound[1] * 1e9),
                **{f"{figure_stem(name)}_max_mc_error": float(error)
                   for name, error in zip(stated, mc_errors, strict=True)}, **change}

    def to_pandas(self):
        """Every scenario's table (``map.csv``, ``map_<scenario>.csv``: the same columns and numbers, NaN where a cell
        is empty) as one tidy pandas DataFrame with a ``scenario`` column (:func:`~tribokin.maps.frames.map_frame`;
        pandas: ``pip install 'tribokin[data]'``). The whole map, in memory."""
        return map_frame(self)

    def to_xarray(self):
        """The map as an xarray Dataset on the grid's axes, one variable per figure, a ``scenario`` dimension, the
        IK's ``q`` per robot (:func:`~tribokin.maps.frames.map_dataset`; xarray: ``pip install 'tribokin[data]'``).
        The whole map, in memory."""
        return map_dataset(self)

    def figures(self, title: str = "map") -> dict:
        """The heat maps ``tribokin run`` writes of the map (reference, scenarios, ratios, differences, winner) as
        matplotlib ``Figure`` objects, by file name in that order, titled ``title: ...``."""
        return result_figures(self, title=title)  # viz.notebook.map_figures

    def _repr_html_(self) -> str | None:
        """A notebook's view: the report's 3-D scene of the map (each scenario's RP_l a layer) inline (no server,
        offline); ``None`` (text) when the robot is not known."""
        return result_scene(self)  # viz.notebook.map_scene

    def first_reachable_q(self) -> np.ndarray | None:
        """The configuration of the first reachable target [m or rad], ``None`` if none is."""
        for part in self.blocks():
            flags = self.read("reachable", part)
            if flags.any():
                return self.read("q", part.start + int(np.argmax(flags)))
        return None


def map_statistics(workspace_map: MapResult) -> MapStatistics:
    """``workspace_map.statistics()`` (run where an executor runs it: :meth:`MapResult.summarise_on`)."""
    return workspace_map.statistics()
