"""``report.html``: one self-contained page — 3-D scene, colour bar, ISO table, map statistics, figures.

The scene is meshcat's static page built without any server
(:mod:`tribokin.viz.static`) and embedded through an ``<iframe srcdoc>``; the
PNG figures of the output folder are embedded as base64. The page makes no
network request (no CDN, no web fonts).
"""

from __future__ import annotations

import base64
import html
import os
from pathlib import Path

import numpy as np

from tribokin.results import StudyResult
from tribokin.robot import Robot
from tribokin.viz.colours import ColourScale
from tribokin.viz.scene import Cube, MapLayer, SceneInfo, build_scene
from tribokin.viz.static import static_visualizer

REPORT_FILE = "report.html"
REPORT_CHOICES = ("full", "light", "none")

#: columns of the ISO table: (direction_rows key, header with unit)
ISO_COLUMNS = (("name", "pose"), ("direction", "direction"), ("cycles", "cycles"), ("RP_l_um", "RP_l [µm]"),
               ("AP_p_um", "AP_p [µm]"), ("vAP_p_um", "vAP_p [µm]"),
               ("RP_l_all_directions_um", "RP_l all directions [µm]"), ("RP_a_mdeg", "RP_a [mdeg]"),
               ("RP_b_mdeg", "RP_b [mdeg]"), ("RP_c_mdeg", "RP_c [mdeg]"), ("AP_a_mdeg", "AP_a [mdeg]"),
               ("AP_b_mdeg", "AP_b [mdeg]"), ("AP_c_mdeg", "AP_c [mdeg]"))

STYLE = """
body { font-family: sans-serif; margin: 1.5em; color: #222; max-width: 1200px; }
iframe { width: 100%; height: 640px; border: 1px solid #bbb; }
table { border-collapse: collapse; margin: 0.5em 0 1.5em; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: right; }
th:first-child, td:first-child { text-align: left; }
.colourbar { width: 420px; height: 18px; border: 1px solid #888; }
.scale { display: flex; justify-content: space-between; width: 422px; font-size: 0.9em; }
.swatch { display: inline-block; width: 14px; height: 14px; vertical-align: middle; border: 1px solid #888; }
img { max-width: 100%; }
"""


def _cell(value) -> str:
    if value is None:
        return "–"
    if isinstance(value, float):
        return f"{value:.3f}"
    return html.escape(str(value))


def _table(headers: list[str], rows: list[list]) -> str:
    head = "".join(f"<th>{html.escape(h)}</th>" for h in headers)
    body = "".join("<tr>" + "".join(f"<td>{_cell(v)}</td>" for v in row) + "</tr>" for row in rows)
    return f"<table><tr>{head}</tr>{body}</table>"


def iso_table(result: StudyResult) -> str:
    """The ISO 9283 figures (µm, mdeg) per pose and approach direction as an HTML table."""
    rows = [[row[key] for key, _ in ISO_COLUMNS] for pose in result.poses for row in pose.direction_rows()]
    return _table([header for _, header in ISO_COLUMNS], rows)


def map_statistics(layers: dict[str, MapLayer]) -> str:
    """Per layer: reachable targets and min/median/max RP_l [µm]; with several layers, the change of the
    median from the first layer (the baseline scenario)."""
    baseline = None
    rows = []
    for layer in layers.values():
        finite = layer.values_um[np.isfinite(layer.values_um)]
        stats = [finite.min(), np.median(finite), finite.max()] if finite.size else [None] * 3
        baseline = stats[1] if baseline is None else baseline
        change = (None if len(layers) < 2 or stats[1] is None or not baseline
                  else f"{100 * (stats[1] / baseline - 1):+.1f} %")
        rows.append([layer.label, f"{finite.size} / {len(layer.values_um)}", *stats, change])
    headers = ["scenario", "reachable targets", "min RP_l [µm]", "median RP_l [µm]", "max RP_l [µm]",
               "median vs first"]
    if len(layers) < 2:
        headers, rows = headers[:-1], [row[:-1] for row in rows]
    return _table(headers, rows)


def thinning_note(layers: dict[str, MapLayer]) -> str:
    """Says so when the scene and the statistics cover every k-th target of a map only."""
    stride = max(layer.stride for layer in layers.values())
    if stride == 1:
        return ""
    return (f"<p>The map is large: the scene and this table cover 1 in {stride} targets along each grid axis. "
            "summary.json and map.csv cover all of them.</p>")


def colour_bar(scale: ColourScale) -> str:
    """The map colour bar, labelled with its range in µm, and the grey of unreachable targets."""
    return (f'<div><b>RP_l [µm]</b> ({scale.name})</div><div class="colourbar" '
            f'style="background: {scale.css_gradient()}"></div><div class="scale"><span>{scale.low_um:.3f} µm'
            f'</span><span>{scale.high_um:.3f} µm</span></div><div><span class="swatch" style="background: '
            f'rgb(158,158,158)"></span> unreachable target</div>')


def embedded_figures(folder: Path) -> str:
    """Every PNG of ``folder`` as an ``<img>`` with a base64 data URI."""
    parts = []
    for png in sorted(Path(folder).glob("*.png")):
        data = base64.b64encode(png.read_bytes()).decode("ascii")
        parts.append(f'<h3>{html.escape(png.name)}</h3><img alt="{html.escape(png.stem)}" '
                     f'src="data:image/png;base64,{data}">')
    return "".join(parts)


def report_html(result: StudyResult, scene_page: str, info: SceneInfo, layers: dict[str, MapLayer],
                folder: Path, variant: str) -> str:
    """The report page around ``scene_page`` (a full meshcat static page)."""
    srcdoc = scene_page.replace("&", "&amp;").replace('"', "&quot;")
    maps = (f"<h2>RP_l maps</h2>{colour_bar(info.colour_scale)}<h3>Map statistics</h3>{thinning_note(layers)}"
            f"{map_statistics(layers)}" if layers else "")
    notes = "".join(f"<p><b>Note:</b> {html.escape(n)}</p>" for n in info.notes)
    title = html.escape(f"tribokin — {result.name}")
    return f"""<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>{title}</title><style>{STYLE}</style></head>
<body><h1>{title}</h1>
<p>Robot {html.escape(str(result.settings.get("robot", "")))}, tool frame
{html.escape(str(result.settings.get("tool_frame", "")))}, {result.settings.get("cycles", "")} cycles per pose,
approach {html.escape(str(result.settings.get("approach", "")))}; robot meshes: {variant}.</p>
<h2>Scene</h2>
<p>Cycle clouds and their 3σ covariance ellipsoids are drawn around their barycenter, magnified
<b>×{info.magnification:g}</b>. Open Controls (top right) toggles the robot, each map and each pose.</p>
<iframe title="3-D scene" srcdoc="{srcdoc}"></iframe>
{notes}{maps}
<h2>ISO 9283 figures per pose</h2>{iso_table(result)}
<h2>Figures</h2>{embedded_figures(folder)}
</body></html>
"""


def write_report(result: StudyResult, robot: Robot, folder, map_layers: dict[str, MapLayer] | None = None,
                 cube: Cube | None = None, variant: str = "full") -> tuple[Path, SceneInfo]:
    """Write ``folder/report.html`` (a temporary name, then renamed); returns its path and what the scene drew.

    Args:
        result: the study's results; the robot is drawn at ``result.display_configuration()``.
        robot: the robot the study ran.
        folder: the output folder (its PNG figures are embedded).
        map_layers: RP_l maps by scenario. cube: the ISO 9283 test cube.
        variant: ``"full"`` (visual meshes) or ``"light"`` (collision meshes).
    """
    folder = Path(folder)
    layers = dict(map_layers or {})
    vis = static_visualizer()
    info = build_scene(vis, robot, result.display_configuration(), result.poses, layers, cube, variant=variant)
    page = report_html(result, vis.static_html(), info, layers, folder, variant)
    temporary = folder / f".{REPORT_FILE}.partial"
    temporary.write_text(page, encoding="utf-8")
    os.replace(temporary, folder / REPORT_FILE)
    return folder / REPORT_FILE, info
