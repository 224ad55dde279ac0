"""Heat maps of workspace maps (PNG): one image per layer of the grid, a colour bar with units,
unreachable targets in grey."""

from __future__ import annotations

import math
import textwrap
from collections.abc import Collection
from dataclasses import dataclass
from pathlib import Path

import matplotlib
import numpy as np
from matplotlib.colors import BoundaryNorm, ListedColormap, Normalize, TwoSlopeNorm
from matplotlib.figure import Figure
from matplotlib.patches import Patch

from tribokin.maps.grid import GridAxis, TargetGrid
from tribokin.maps.result import REACHED_BY, MapResult, ScenarioMap
from tribokin.study.names import CHANGE_MAP_FILES, CHANGE_MAP_KINDS, EXPECTED_MAP_FILES, map_figure_file
from tribokin.viz.canvas import NO_MATH, agg_figure, save_png

UNREACHABLE_GREY = "#c8c8c8"


def _span(values: np.ndarray | None) -> tuple[float, float]:
    """Outer edges of the cells around evenly spaced ``values``, first to last (a single value gets a cell of
    width 1; no values: the cell -0.5 .. 0.5)."""
    if values is None or len(values) == 1:
        centre = 0.0 if values is None else float(values[0])
        return centre - 0.5, centre + 0.5
    half = (values[1] - values[0]) / 2
    return float(values[0] - half), float(values[-1] + half)


@dataclass(frozen=True)
class BaseMark:
    """A robot base on a heat map: its ``label``, its origin's position in the world ``world_m`` (3,) [m] and where
    that, projected onto the panel, lies in the panel's coordinates ``at`` [m] (``None``: outside the panel)."""

    label: str
    world_m: tuple[float, float, float]
    at: tuple[float, float] | None


@dataclass(frozen=True)
class PanelFrame:
    """How a heat-map panel is laid out.

    Attributes:
        xlabel, ylabel: axis labels with units, naming world-frame axes (``ylabel`` ``None``: the grid has one row).
        extent: (left, right, bottom, top) of the image in axis coordinates, first to last target (a
            decreasing coordinate gives left > right; the axes are then shown increasing).
        bases: the robot bases to mark (:class:`BaseMark`; none for a joint grid).
        plane: the coordinate a plane keeps constant, e.g. ``"z (world) = 0.1 m"`` (``""`` if none).
        layer: the name of the coordinate a box's layers keep constant, e.g. ``"z (world)"`` (a joint grid's: the
            joint's name).
    """

    xlabel: str
    ylabel: str | None
    extent: tuple[float, float, float, float]
    bases: tuple[BaseMark, ...]
    plane: str = ""
    layer: str = ""


#: How the axis labels name the world frame's axes: ``x (world) [m]``.
WORLD = " (world)"


def _world_axis(direction: np.ndarray) -> int | None:
    """Index of the world axis (x, y, z) ``direction`` runs along, either way; ``None`` for an oblique one."""
    along = np.flatnonzero(np.abs(direction) > 1e-12)
    return int(along[0]) if len(along) == 1 else None


def _shown_axis(axis: GridAxis, direction: np.ndarray, origin_m: np.ndarray,
                bases_m: np.ndarray) -> tuple[str, np.ndarray, np.ndarray]:
    """A Cartesian grid axis as a panel shows it: its label, the coordinates of its targets, and the
    coordinates of the points ``bases_m`` (k, 3) [m] of the world projected onto it [m]."""
    k = _world_axis(direction)
    if k is None:
        label = (f"{axis.label} along ({', '.join(f'{c:.3g}' for c in direction)}) from "
                 f"({', '.join(f'{c:.4g}' for c in origin_m)}) m{WORLD}")
        return label, axis.values, (bases_m - origin_m) @ direction
    return f"{'xyz'[k]}{WORLD} [{axis.unit}]", origin_m[k] + direction[k] * axis.values, bases_m[:, k]


def panel_frame(grid: TargetGrid, columns: GridAxis, rows: GridAxis | None,
                bases: dict[str, np.ndarray] | None = None) -> PanelFrame:
    """The labels, extent and base markers of panels showing ``columns`` and ``rows`` of ``grid``.

    A Cartesian grid's axes are shown in the coordinates of the world frame, which its targets are given in: an
    axis along a world axis is labelled by it (``x (world) [m]``) and shows that coordinate, ``origin_m`` included;
    an oblique one shows the offset from ``origin_m`` along its direction. ``bases``: label -> (3,) world position
    [m] of each robot base to mark (default: ``{"robot base": grid.base_m}``)."""
    if grid.kind == "joint":
        return PanelFrame(columns.label, None if rows is None else rows.label,
                          (*_span(columns.values), *_span(None if rows is None else rows.values)), (),
                          layer="" if grid.axes[2] is None else grid.axes[2].name)
    bases = {"robot base": grid.base_m} if bases is None else bases
    bases_m = np.array(list(bases.values()), dtype=float).reshape(-1, 3)
    # grid.directions has the layer axis's row too: a panel shows the first two
    (xlabel, x, base_x), (ylabel, y, base_y) = (_shown_axis(axis, direction, grid.origin_m, bases_m)
                                                for axis, direction
                                                in zip((columns, rows), grid.directions, strict=False))
    extent = (*_span(x), *_span(y))
    inside = ((min(extent[:2]) <= base_x) & (base_x <= max(extent[:2]))
              & (min(extent[2:]) <= base_y) & (base_y <= max(extent[2:])))
    marks = tuple(BaseMark(label, tuple(float(c) for c in world), (float(bx), float(by)) if within else None)
                  for label, world, bx, by, within in zip(bases, bases_m, base_x, base_y, inside, strict=True))
    plane = layer = ""
    if grid.kind == "plane":
        k = _world_axis(np.cross(*grid.directions[:2]))
        plane = "" if k is None else f"{'xyz'[k]}{WORLD} = {grid.origin_m[k]:.4g} m"
    elif grid.axes[2] is not None:
        layer = f"{grid.axes[2].name}{WORLD}"
    return PanelFrame(xlabel, ylabel, extent, marks, plane, layer)


def value_norm(values: np.ndarray, centre: float | None = None) -> Normalize:
    """A colour scale over the finite values; with a ``centre``, the middle colour is the centre: when the
    values straddle it each side spans its own range, else the scale reaches as far past the centre as
    the values lie on their side (so a map of ratios all below 1 is not white where nothing changed)."""
    finite = values[np.isfinite(values)]
    low, high = (float(finite.min()), float(finite.max())) if len(finite) else (0.0, 1.0)
    if centre is not None and low < centre < high:
        return TwoSlopeNorm(centre, low, high)
    if centre is not None:
        reach = max(abs(low - centre), abs(high - centre))
        low, high = centre - reach, centre + reach
    return Normalize(low, high if high > low else low + max(abs(low), 1.0) * 1e-9)


#: Most targets a heat map shows along a row or column of a panel (more are finer than its pixels),
#: and most panels (layers) per figure; larger grids show every k-th target.
PANEL_TARGETS = 400
PANELS = 16
#: Characters of a 10-point title line per inch of figure width.
TITLE_CHARACTERS_PER_IN = 13


def shown_targets(grid: TargetGrid) -> tuple[np.ndarray, tuple[int, int, int]]:
    """The targets a heat map of ``grid`` shows, (layers', rows', columns') indices, and the strides
    along (layers, rows, columns): every target up to ``PANEL_TARGETS`` per axis and ``PANELS`` layers."""
    layers, rows, columns = grid.shape
    step = max(math.ceil(rows / PANEL_TARGETS), math.ceil(columns / PANEL_TARGETS))
    strides = (math.ceil(layers / PANELS), step, step)
    return grid.every(strides), strides


#: Colours of the targets :class:`Marks` sets apart, gold and magenta: none of viridis', RdBu's or tab10's, nor grey.
MARK_COLOURS = ("#ffd700", "#ff00ff")


@dataclass(frozen=True)
class Marks:
    """Targets a heat map shows in colours of their own, with a legend: ``values(indices)`` gives each target's
    index into ``labels`` (and ``MARK_COLOURS``), -1 for none; a marked target has no value of the map's own."""

    values: object
    labels: tuple[str, ...]


@matplotlib.rc_context(NO_MATH)
def save_grid_image(grid: TargetGrid, values, path: Path, label: str, title: str, **options) -> None:
    """:func:`grid_image` written to ``path`` (PNG)."""
    save_png(grid_image(grid, values, label, title, **options), path)


@matplotlib.rc_context(NO_MATH)
def grid_image(grid: TargetGrid, values, label: str, title: str, cmap="viridis", norm: Normalize | None = None,
               centre: float | None = None, categories: list[str] | None = None, marks: Marks | None = None,
               grey: str = "unreachable", bases: dict[str, np.ndarray] | None = None) -> Figure:
    """``values`` as images over the grid's columns and rows, one panel per layer, for the targets
    :func:`shown_targets` picks.

    Args:
        grid: the map's targets.
        values: ``values(indices)`` of the targets ``indices`` (an integer array of any shape).
        label: colour-bar label with its unit, e.g. ``"RP_l [µm]"``.
        title: the figure's title.
        cmap: the colour map.
        norm: colour scale (default: the shown finite values' range, centred on ``centre`` when they straddle it).
        centre: the value a default colour scale is centred on.
        categories: names of the integer values -1, 0, 1, ... (a categorical colour bar).
        marks: targets drawn in colours of their own, named in a legend (:class:`Marks`).
        grey: what the grey targets (no value, not marked) are, for the title.
        bases: the robot bases to mark, label -> (3,) world position [m] (:func:`panel_frame`; one outside the
            panels is said so in the title).
    """
    shown, strides = shown_targets(grid)
    columns, rows, layers = (None if axis is None else GridAxis(axis.name, axis.unit, axis.values[::stride])
                             for axis, stride in zip(grid.axes, strides[::-1], strict=True))
    n_layers = shown.shape[0]
    data = np.asarray(values(shown.ravel()), dtype=float).reshape(shown.shape)
    images = np.ma.masked_invalid(data)
    marked = (None if marks is None
              else np.ma.masked_less(np.asarray(marks.values(shown.ravel())).reshape(shown.shape), 0))
    cmap = matplotlib.colormaps.get_cmap(cmap).with_extremes(bad=UNREACHABLE_GREY)
    norm = norm or value_norm(data, centre)
    panels_across = math.ceil(math.sqrt(n_layers))
    panels_down = math.ceil(n_layers / panels_across)
    width_in = 1.5 + 4.6 * panels_across
    fig = agg_figure(figsize=(width_in, 0.8 + 3.9 * panels_down), constrained_layout=True)
    axes = fig.subplots(panels_down, panels_across, squeeze=False)
    frame = panel_frame(grid, columns, rows, bases)
    mesh = None
    for layer, ax in enumerate(axes.flat):
        if layer >= n_layers:
            ax.set_visible(False)
            continue
        aspect = "equal" if grid.kind != "joint" and rows is not None else "auto"
        mesh = ax.imshow(images[layer], extent=frame.extent, origin="lower", cmap=cmap, norm=norm,
                         interpolation="nearest", aspect=aspect)
        if marked is not None:
            ax.imshow(marked[layer], extent=frame.extent, origin="lower", cmap=ListedColormap(MARK_COLOURS),
                      norm=BoundaryNorm([-0.5, 0.5, 1.5], 2), interpolation="nearest", aspect=aspect)
        ax.set_xlim(sorted(frame.extent[:2]))
        ax.set_ylim(sorted(frame.extent[2:]))
        ax.set_xlabel(frame.xlabel)
        if frame.ylabel is not None:
            ax.set_ylabel(frame.ylabel)
        else:
            ax.set_yticks([])
        for base in frame.bases:
            if base.at is not None:
                ax.plot(*base.at, marker="P", ms=11, color="black", mec="white", mew=1.2, ls="none")
                ax.annotate(base.label, base.at, xytext=(8, 8), textcoords="offset points", fontsize=8,
                            bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "none", "alpha": 0.8})
        if layers is not None:
            ax.set_title(f"{frame.layer} = {layers.values[layer]:.4g} {layers.unit}", fontsize=9)
        elif frame.plane:
            ax.set_title(f"plane {frame.plane}", fontsize=9)
    bar = fig.colorbar(mesh, ax=axes, label=label, shrink=0.9)
    if categories:
        bar.set_ticks(np.arange(-1, len(categories) - 1), labels=categories)
    if marked is not None:
        handles = [Patch(facecolor=colour, label=text) for colour, text in zip(MARK_COLOURS, marks.labels, strict=True)]
        fig.legend(handles=handles + [Patch(facecolor=UNREACHABLE_GREY, label=grey)], loc="outside lower center",
                   ncols=len(handles) + 1, fontsize=8, frameon=False)
    thinned = shown.size < grid.size
    grey_cells = np.ma.getmaskarray(images)
    if marked is not None:
        grey_cells &= np.ma.getmaskarray(marked)
    unreachable = int(grey_cells.sum())
    note = f" (grey: {unreachable} {grey}{' of those shown' if thinned else ''})" if unreachable else ""
    note += "".join(f"; {base.label} at ({', '.join(f'{c + 0.0:.4g}' for c in base.world_m)}) m{WORLD}, outside the "
                    "panels" for base in frame.bases if base.at is None)
    if thinned:
        note += (f"; shown: {shown.size:,} of {grid.size:,} targets, 1 in {strides[2]} along rows and columns"
                 + (f", 1 in {strides[0]} layers" if strides[0] > 1 else "") + "; map.csv has them all")
    fig.suptitle(textwrap.fill(f"{title}{note}", int(TITLE_CHARACTERS_PER_IN * width_in)), fontsize=10)
    return fig


def _categorical(count: int) -> ListedColormap:
    """White for the value -1 (none, tie), then one tab10 colour per category 0 .. count - 1."""
    return ListedColormap(["#ffffff"] + [matplotlib.colormaps["tab10"](i % 10) for i in range(count)])


def rp_l_norm(workspace_map: MapResult) -> Normalize:
    """One colour scale for the RP_l maps of every scenario: the range of all their values at the targets
    the heat maps show, so equal colours mean equal RP_l across scenarios."""
    shown = shown_targets(workspace_map.grid)[0].ravel()
    return value_norm(np.concatenate([s.figure("RP_l_um", shown) for s in workspace_map.scenarios.values()]))


#: Heat maps of an expected map's own figures: (file, figure, colour bar label, title).
EXPECTED_HEAT_MAPS = tuple((file, *drawn) for file, drawn in zip(EXPECTED_MAP_FILES["directional"], (
    ("RP_l_hi_um", "97.5 % of one test's RP_l [µm]", "RP_l of one test: 1 test in 40 exceeds this"),
    ("vAP_p_um", "expected vAP_p [µm]",
     "multi-directional position accuracy variation vAP_p, approached along +x, +y, +z"),
    ("RP_l_multi_um", "expected RP_l_multi [µm]",
     "RP_l of cycles each approached from a random joint-space direction")), strict=True))


#: Heat maps of a map comparing two states of its friction series: (the reference's file, the kind in another
#: scenario's file ``map_<kind>_<scenario>.png``, change, the figure that changes).
CHANGE_HEAT_MAPS = tuple(zip(CHANGE_MAP_FILES, CHANGE_MAP_KINDS, ("RP_l_change_um", "AP_p_change_um"), ("RP_l", "AP_p"),
                             strict=True))


def change_norms(workspace_map: MapResult) -> dict[str, Normalize]:
    """A map comparing two states: per change (``RP_l_change_um``, ``AP_p_change_um``), one colour scale centred on 0
    for every scenario's map of it, over all their values at the targets the heat maps show (:func:`rp_l_norm`'s
    reason); none for other maps."""
    if not workspace_map.reference.change:
        return {}
    shown = shown_targets(workspace_map.grid)[0].ravel()
    return {name: value_norm(np.concatenate([s.change_figure(name, shown) for s in workspace_map.scenarios.values()]),
                             centre=0.0)
            for _, _, name, _ in CHANGE_HEAT_MAPS}


def state_label(state: dict) -> str:
    """A map's friction state (:meth:`~tribokin.tribology.friction_series.FrictionState.describe`) in words."""
    after = state["after_s"]
    thermal = "cold" if after == 0 else "warm" if after == "warm" else f"{after:g} s warmed up"
    return thermal if "age_cycles" not in state else f"{thermal} at {state['age_cycles']:g} cycles of age"


#: What a map approached from both directions shows as RP_l (its titles say so).
LARGER_DIRECTION = " (the larger of the + and − approach directions')"


def _map_figures(workspace_map: MapResult, study_name: str, norm: Normalize | None,
                 changes: dict[str, Normalize] | None = None) -> dict[str, tuple]:
    """File name -> arguments of :func:`grid_image` (values, label, title, options) of each map figure,
    in the order a reader follows: the reference, each other scenario, their ratios and differences to
    the reference, each one's changes (a map comparing two states), the winner; ``norm``: RP_l's colour scale,
    ``changes``: each change's (:func:`change_norms`; ``None``: each map its own)."""
    reference = workspace_map.reference
    others = list(workspace_map.scenarios.values())[1:]
    shared = " (colour scale shared by all scenarios)" if others else ""
    compared = f", {reference.name}" if others else ""
    joints = workspace_map.joint_names
    expected = "expected " if reference.has("RP_l_hi_um") else ""
    larger = LARGER_DIRECTION if reference.both_directions else ""
    figures = {
        "map_RP_l.png": (lambda shown: reference.figure("RP_l_um", shown), f"{expected}RP_l [µm]",
                         f"position repeatability RP_l{larger}, {expected}over tests of {reference.cycles} cycles per "
                         f"target{compared}{shared}", {"norm": norm}),
        "map_dominant_joint.png": (
            lambda shown: np.where(workspace_map.read("reachable", shown), reference.read("dominant_joint", shown),
                                   np.nan),
            "joint with the largest share of the position variance", f"dominant joint{compared}",
            {"cmap": _categorical(len(joints)), "norm": BoundaryNorm(np.arange(-1.5, len(joints)), len(joints) + 1),
             "categories": ["none"] + joints}),
    }
    figures.update({file: (lambda shown, name=name: reference.figure(name, shown), label, title, {})
                    for file, name, label, title in EXPECTED_HEAT_MAPS if reference.has(name)})
    if reference.change:
        start, end = (state_label(workspace_map.states[key]) for key in ("state", "compare"))
        changes = changes or {}
        figures.update({file: (lambda shown, name=name: reference.change_figure(name, shown), f"{figure} change [µm]",
                               f"{figure} from {start} to {end}, end − start{compared} (near 0: drifts least){shared}",
                               {"cmap": "RdBu_r", "centre": 0.0, "norm": changes.get(name)})
                        for file, _, name, figure in CHANGE_HEAT_MAPS})
    for s in others:
        figures[map_figure_file("RP_l", s.name)] = (lambda shown, s=s: s.figure("RP_l_um", shown), "RP_l [µm]",
                                             f"RP_l{LARGER_DIRECTION if s.both_directions else ''}, {s.name}{shared}",
                                             {"norm": norm, "bases": _bases(workspace_map, s)})
    for s in others:
        figures[map_figure_file("RP_l_ratio", s.name)] = (
            lambda shown, s=s: workspace_map.ratio_RP_l(s, shown), f"RP_l {s.name} / {reference.name} [-]",
            f"RP_l ratio {s.name} / {reference.name}",
            {"cmap": "RdBu_r", "centre": 1.0, "bases": _bases(workspace_map, reference, s),
             **_reach_marks(workspace_map, s)})
    for s in others:
        figures[map_figure_file("RP_l_diff", s.name)] = (
            lambda shown, s=s: workspace_map.diff_RP_l_um(s, shown), f"RP_l {s.name} − {reference.name} [µm]",
            f"RP_l difference {s.name} − {reference.name}",
            {"cmap": "RdBu_r", "centre": 0.0, "bases": _bases(workspace_map, reference, s),
             **_reach_marks(workspace_map, s)})
    for _, kind, name, figure in CHANGE_HEAT_MAPS if reference.change else ():
        for s in others:
            figures[map_figure_file(kind, s.name)] = (
                lambda shown, s=s, name=name: s.change_figure(name, shown), f"{figure} change [µm]",
                f"{figure} from {start} to {end}, end − start, {s.name} (near 0: drifts least){shared}",
                {"cmap": "RdBu_r", "centre": 0.0, "norm": changes.get(name), "bases": _bases(workspace_map, s)})
    if others:
        names = list(workspace_map.scenarios)
        several = workspace_map.robot_count > 1
        figures["map_winner.png"] = (
            lambda shown: np.where(workspace_map.reached_by_any(shown), workspace_map.winners(shown), np.nan),
            "scenario with the smallest RP_l", "which scenario has the smallest RP_l" + (
                ", among those whose robot reaches the target" if several else ""),
            {"cmap": _categorical(len(names)), "norm": BoundaryNorm(np.arange(-1.5, len(names)), len(names) + 1),
             "categories": ["tie"] + names, "bases": _bases(workspace_map, *workspace_map.scenarios.values()),
             **({"grey": "reached by no scenario"} if several else {})})
    return figures


def _bases(workspace_map: MapResult, *scenarios: ScenarioMap) -> dict[str, np.ndarray]:
    """Where the bases of the robots ``scenarios`` are measured with lie in the world, label -> (3,) [m]: one
    ``"robot base"`` when they all share one place, else ``"<scenario>, ... base"`` per place."""
    places: dict[tuple[float, ...], list[str]] = {}
    for s in scenarios:
        places.setdefault(tuple(workspace_map.grids[s.robot].base_m), []).append(s.name)
    if len(places) == 1:
        return {"robot base": np.array(next(iter(places)))}
    return {f"{', '.join(names)} base": np.array(place) for place, names in places.items()}


def _reach_marks(workspace_map: MapResult, scenario: ScenarioMap) -> dict:
    """The options of :func:`grid_image` that set apart, on a comparison of ``scenario`` with the reference
    measured with another robot, the targets only one of the two robots reaches (none when they share the robot)."""
    reference = workspace_map.reference
    if scenario.robot == reference.robot:
        return {}
    codes = np.array([{"this only": 0, "reference only": 1}.get(who, -1) for who in REACHED_BY])
    return {"marks": Marks(lambda shown: codes[workspace_map.reached_by(scenario, shown)],
                           (f"reached by {scenario.name} only", f"reached by {reference.name} only")),
            "grey": "reached by neither"}


def map_figure_names(workspace_map: MapResult) -> list[str]:
    """The file names :func:`save_map_figures` writes, in the order a reader follows."""
    return list(_map_figures(workspace_map, "", None))


def save_map_figures(workspace_map: MapResult, folder: Path, study_name: str,
                     names: Collection[str] | None = None) -> list[Path]:
    """``map_RP_l.png`` and ``map_dominant_joint.png`` (reference scenario); with scenarios, each other
    scenario's RP_l (all RP_l maps on one colour scale, :func:`rp_l_norm`), its ratio and difference to
    the reference, comparing two states each one's changes (each change's maps on one scale, :func:`change_norms`),
    and ``map_winner.png`` (which scenario has the smallest RP_l); returns their paths in that order. Only those
    of file ``names`` (:func:`map_figure_names`) where given: the same bytes as drawn with the others."""
    figures = _map_figures(workspace_map, study_name, rp_l_norm(workspace_map), change_norms(workspace_map))
    drawn = [name for name in figures if names is None or name in names]
    for name in drawn:
        values, label, title, options = figures[name]
        save_grid_image(workspace_map.grid, values, folder / name, label, f"{study_name}: {title}", **options)
    return [folder / name for name in drawn]


def map_figures_drawn(workspace_map: MapResult, study_name: str) -> dict[str, Figure]:
    """The figures :func:`save_map_figures` writes, by file name in the same order, as matplotlib Figures."""
    figures = _map_figures(workspace_map, study_name, rp_l_norm(workspace_map), change_norms(workspace_map))
    return {name: grid_image(workspace_map.grid, values, label, f"{study_name}: {title}", **options)
            for name, (values, label, title, options) in figures.items()}
