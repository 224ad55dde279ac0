"""Heat maps of workspace maps (PNG): one image per layer of the grid, a colour bar with units,
unreachable targets in grey."""

from __future__ import annotations

import math
import textwrap
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.colors import BoundaryNorm, ListedColormap, Normalize, TwoSlopeNorm  # noqa: E402

from tribokin.results import MapResult  # noqa: E402
from tribokin.targets import GridAxis, TargetGrid  # noqa: E402

UNREACHABLE_GREY = "#c8c8c8"


def _span(axis: GridAxis | None) -> tuple[float, float]:
    """Outer edges of the cells around an axis' evenly spaced values (a single value gets a cell of width 1)."""
    if axis is None or len(axis.values) == 1:
        centre = 0.0 if axis is None else axis.values[0]
        return centre - 0.5, centre + 0.5
    half = (axis.values[1] - axis.values[0]) / 2
    return axis.values[0] - half, axis.values[-1] + half


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


def save_grid_image(grid: TargetGrid, values, path: Path, label: str, title: str, cmap="viridis",
                    norm: Normalize | None = None, centre: float | None = None,
                    categories: list[str] | None = None) -> None:
    """``values`` as images over the grid's columns and rows, one panel per layer, for the targets
    :func:`shown_targets` picks.

    Args:
        values: ``values(indices)`` of the targets ``indices`` (an integer array of any shape).
        label: colour-bar label with its unit, e.g. ``"RP_l [µm]"``.
        norm: colour scale (default: the shown finite values' range, centred on ``centre`` when they straddle it).
        categories: names of the integer values -1, 0, 1, ... (a categorical colour bar).
    """
    shown, strides = shown_targets(grid)
    columns, rows, layers = (None if axis is None else GridAxis(axis.name, axis.unit, axis.values[::stride])
                             for axis, stride in zip(grid.axes, strides[::-1]))
    n_layers = shown.shape[0]
    data = np.asarray(values(shown.ravel()), dtype=float).reshape(shown.shape)
    images = np.ma.masked_invalid(data)
    cmap = plt.get_cmap(cmap).with_extremes(bad=UNREACHABLE_GREY)
    norm = norm or value_norm(data, centre)
    panels_across = math.ceil(math.sqrt(n_layers))
    panels_down = math.ceil(n_layers / panels_across)
    width_in = 1.5 + 4.6 * panels_across
    fig, axes = plt.subplots(panels_down, panels_across, figsize=(width_in, 0.8 + 3.9 * panels_down),
                             squeeze=False, constrained_layout=True)
    mesh = None
    for layer, ax in enumerate(axes.flat):
        if layer >= n_layers:
            ax.set_visible(False)
            continue
        mesh = ax.imshow(images[layer], extent=(*_span(columns), *_span(rows)), origin="lower", cmap=cmap, norm=norm,
                         interpolation="nearest", aspect="equal" if grid.kind != "joint" and rows is not None else "auto")
        ax.set_xlabel(columns.label)
        if rows is not None:
            ax.set_ylabel(rows.label)
        else:
            ax.set_yticks([])
        if layers is not None:
            ax.set_title(f"{layers.name} = {layers.values[layer]:.4g} {layers.unit}", fontsize=9)
    bar = fig.colorbar(mesh, ax=axes, label=label, shrink=0.9)
    if categories:
        bar.set_ticks(np.arange(-1, len(categories) - 1), labels=categories)
    thinned = shown.size < grid.size
    unreachable = int(images.mask.sum()) if np.ndim(images.mask) else 0
    note = f" (grey: {unreachable} unreachable{' of those shown' if thinned else ''})" if unreachable else ""
    if thinned:
        note += (f"; shown: {shown.size:,} of {grid.size:,} targets, 1 in {strides[2]} along rows and columns"
                 + (f", 1 in {strides[0]} layers" if strides[0] > 1 else "") + "; map.csv has them all")
    fig.suptitle(textwrap.fill(f"{title}{note}", int(TITLE_CHARACTERS_PER_IN * width_in)), fontsize=10)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _categorical(count: int) -> ListedColormap:
    """White for the value -1 (none, tie), then one tab10 colour per category 0 .. count - 1."""
    return ListedColormap(["#ffffff"] + [plt.get_cmap("tab10")(i % 10) for i in range(count)])


def save_map_figures(workspace_map: MapResult, folder: Path, study_name: str) -> list[Path]:
    """``map_RP_l.png`` and ``map_dominant_joint.png`` (reference scenario); with scenarios, per other
    scenario its RP_l, ratio and difference to the reference, and ``map_winner.png`` (which scenario
    has the smallest RP_l)."""
    grid, reference = workspace_map.grid, workspace_map.reference
    paths = []

    def save(name, values, label, title, **options):
        paths.append(folder / name)
        save_grid_image(grid, values, paths[-1], label, f"{study_name}: {title}", **options)

    compared = f", {reference.name}" if len(workspace_map.scenarios) > 1 else ""
    save("map_RP_l.png", lambda shown: reference.figure("RP_l_um", shown), "RP_l [µm]",
         f"position repeatability RP_l, {reference.cycles} cycles per target{compared}")
    joints = workspace_map.joint_names
    save("map_dominant_joint.png",
         lambda shown: np.where(workspace_map.read("reachable", shown), reference.read("dominant_joint", shown), np.nan),
         "joint with the largest share of the position variance", f"dominant joint{compared}",
         cmap=_categorical(len(joints)), norm=BoundaryNorm(np.arange(-1.5, len(joints)), len(joints) + 1),
         categories=["none"] + joints)
    for scenario in list(workspace_map.scenarios.values())[1:]:
        save(f"map_RP_l_{scenario.name}.png", lambda shown, s=scenario: s.figure("RP_l_um", shown), "RP_l [µm]",
             f"RP_l, {scenario.name}")
        save(f"map_RP_l_ratio_{scenario.name}.png", lambda shown, s=scenario: workspace_map.ratio_RP_l(s, shown),
             f"RP_l {scenario.name} / {reference.name} [-]", f"RP_l ratio {scenario.name} / {reference.name}",
             cmap="RdBu_r", centre=1.0)
        save(f"map_RP_l_diff_{scenario.name}.png", lambda shown, s=scenario: workspace_map.diff_RP_l_um(s, shown),
             f"RP_l {scenario.name} − {reference.name} [µm]",
             f"RP_l difference {scenario.name} − {reference.name}", cmap="RdBu_r", centre=0.0)
    if len(workspace_map.scenarios) > 1:
        names = list(workspace_map.scenarios)
        save("map_winner.png",
             lambda shown: np.where(workspace_map.read("reachable", shown), workspace_map.winners(shown), np.nan),
             "scenario with the smallest RP_l", "which scenario has the smallest RP_l",
             cmap=_categorical(len(names)), norm=BoundaryNorm(np.arange(-1.5, len(names)), len(names) + 1),
             categories=["tie"] + names)
    return paths
