"""``placement.png``: the placement search's objective over the base positions (x–y plane of the world), the task
region outlined, candidates reaching fewer than ``min_reachable`` of the targets hatched, the best marked."""

from __future__ import annotations

import math
import textwrap
from pathlib import Path

import matplotlib
import numpy as np
from matplotlib.collections import PatchCollection
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Patch, Polygon, Rectangle

from tribokin.placement.result import PlacementResult
from tribokin.study.map_spec import BoxMap, MapSpec
from tribokin.viz.canvas import NO_MATH, agg_figure, save_png
from tribokin.viz.maps import PANELS, TITLE_CHARACTERS_PER_IN, UNREACHABLE_GREY, value_norm

PLACEMENT_FIGURE = "placement.png"


def task_outline_m(task: MapSpec) -> np.ndarray:
    """(k, 2) corners of the task region's outline in the world's x–y plane [m]: a box's rectangle, or a plane's
    parallelogram (its edge on view where the plane is vertical)."""
    if isinstance(task, BoxMap):
        (x0, y0, _), (x1, y1, _) = task.min_m, task.max_m
        return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])
    origin, u, v = (np.asarray(a, dtype=float) for a in (task.origin_m, task.axis_u, task.axis_v))
    (u0, u1), (v0, v1) = task.extent_u_m, task.extent_v_m
    return np.array([origin + a * u + b * v for a, b in ((u0, v0), (u1, v0), (u1, v1), (u0, v1))])[:, :2]


def _cell_m(values: np.ndarray) -> float | None:
    """The smallest gap between distinct ``values`` [m]; ``None`` for one value."""
    gaps = np.diff(np.unique(np.round(values, 9)))
    return float(gaps.min()) if len(gaps) else None


def panels(placement: PlacementResult) -> tuple[list[tuple[str, np.ndarray]], str]:
    """The panels: (title, indices of the candidates drawn), one per height and yaw of the candidates when there are
    at most ``PANELS`` of them, else one showing at each (x, y) the best-ranked candidate over heights and yaws;
    and a note saying which."""
    candidates = placement.candidates
    keys = [(c.base_xyz_m[2], c.yaw_deg) for c in candidates]
    groups = sorted(set(keys))
    heights, yaws = {z for z, _ in groups}, {yaw for _, yaw in groups}
    if len(groups) <= PANELS:
        title = lambda z, yaw: ", ".join(  # noqa: E731
            part for part, shown in ((f"z = {z:.4g} m", len(heights) > 1), (f"yaw +{yaw:g}°", len(yaws) > 1)) if shown)
        return [(title(*group), np.array([i for i, key in enumerate(keys) if key == group])) for group in groups], ""
    best: dict[tuple, int] = {}
    for index in placement.order:
        best.setdefault(tuple(np.round(candidates[index].base_xyz_m[:2], 9)), int(index))
    return [("", np.array(sorted(best.values())))], (f"; {len(groups)} heights and yaws: each (x, y) shows its "
                                                      "best-ranked candidate over them")


@matplotlib.rc_context(NO_MATH)
def save_placement_figure(placement: PlacementResult, path: Path, title: str) -> None:
    """:func:`placement_figure` written to ``path`` (``placement.png``)."""
    save_png(placement_figure(placement, title), path)


@matplotlib.rc_context(NO_MATH)
def placement_figure(placement: PlacementResult, title: str) -> Figure:
    """Draw ``placement.png`` (module docstring): each candidate a cell at its base's (x, y) [m] coloured by the
    objective [µm] (grey: no target reached), one panel per height and yaw (:func:`panels`)."""
    drawn, note = panels(placement)
    objective = placement.objective_um
    positions = np.array([c.base_xyz_m[:2] for c in placement.candidates])
    cell_x, cell_y = _cell_m(positions[:, 0]), _cell_m(positions[:, 1])
    outline = task_outline_m(placement.study.map)
    span = float(np.ptp(np.vstack([positions, outline]), axis=0).max()) or 1.0
    cell_x = cell_x or cell_y or 0.1 * span
    cell_y = cell_y or cell_x
    norm = value_norm(objective)
    cmap = matplotlib.colormaps.get_cmap("viridis").with_extremes(bad=UNREACHABLE_GREY)
    across = math.ceil(math.sqrt(len(drawn)))
    down = math.ceil(len(drawn) / across)
    width_in = 1.5 + 4.6 * across
    fig = agg_figure(figsize=(width_in, 1.4 + 3.9 * down), constrained_layout=True)
    axes = fig.subplots(down, across, squeeze=False)
    best = placement.best.index
    collection = None
    for ax, (panel_title, indices) in zip(axes.flat, drawn, strict=False):
        cells = lambda shown: [  # noqa: E731
            Rectangle((x - 0.45 * cell_x, y - 0.45 * cell_y), 0.9 * cell_x, 0.9 * cell_y) for x, y in positions[shown]]
        collection = PatchCollection(cells(indices), cmap=cmap, norm=norm, edgecolor="white", linewidth=0.5)
        collection.set_array(np.ma.masked_invalid(objective[indices]))
        ax.add_collection(collection)
        short = indices[~placement.meets_min_reachable[indices]]
        ax.add_collection(PatchCollection(cells(short), facecolor="none", edgecolor="black", linewidth=0.0,
                                          hatch="xxx"))
        ax.add_patch(Polygon(outline, closed=True, fill=False, linestyle="--", edgecolor="crimson", linewidth=1.5))
        if best in indices:
            ax.plot(*positions[best], marker="*", ms=16, color="white", mec="black", mew=1.2, ls="none")
        half = [cell_x / 2, cell_y / 2]
        corners = np.vstack([positions[indices] - half, positions[indices] + half, outline])
        low, high = corners.min(axis=0), corners.max(axis=0)
        margin = 0.05 * float((high - low).max())
        ax.set_xlim(low[0] - margin, high[0] + margin)
        ax.set_ylim(low[1] - margin, high[1] + margin)
        ax.set_aspect("equal")
        ax.set_xlabel("base x (world) [m]")
        ax.set_ylabel("base y (world) [m]")
        if panel_title:
            ax.set_title(panel_title, fontsize=9)
    for ax in list(axes.flat)[len(drawn):]:
        ax.set_visible(False)
    spec = placement.spec
    fig.colorbar(collection, ax=axes, shrink=0.9, label=f"RP_l {spec.objective} over the reached targets [µm]")
    handles = [Line2D([], [], marker="*", ms=12, color="white", mec="black", ls="none", label="best"),
               Patch(facecolor="none", edgecolor="black", hatch="xxx",
                     label=f"reaches < {100 * spec.min_reachable:g} % of the targets"),
               Patch(facecolor=UNREACHABLE_GREY, label="reaches no target"),
               Line2D([], [], color="crimson", ls="--", label="task region ([map])")]
    fig.legend(handles=handles, loc="outside lower center", ncols=4, fontsize=8, frameon=False)
    text = (f"{title}: expected RP_l {spec.objective} over the task's {placement.target_count} targets, per base "
            f"position ({len(placement.candidates)} candidates){note}")
    fig.suptitle(textwrap.fill(text, int(TITLE_CHARACTERS_PER_IN * width_in)), fontsize=10)
    return fig
