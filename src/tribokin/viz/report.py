"""``report.html``: one self-contained page — 3-D scene, colour bar, ISO table, map statistics, figures.

The scene is meshcat's static page built without any server
(:mod:`tribokin.viz.static`) and embedded through an ``<iframe srcdoc>``; the
PNG figures of the output folder are embedded as base64. The page makes no
network request (no CDN, no web fonts).
"""

from __future__ import annotations

import base64
import html
import json
import os
from pathlib import Path

import numpy as np

from tribokin.kinematics.robot import Robot
from tribokin.maps.grid import TargetGrid
from tribokin.maps.result import MapResult
from tribokin.run import StudyResult
from tribokin.study.map_spec import BoxMap, MapSpec
from tribokin.study.names import drift_figure_file
from tribokin.viz.colours import ColourScale
from tribokin.viz.scene import Cube, MapLayer, RobotDrawn, SceneInfo, build_scene
from tribokin.viz.static import static_visualizer

REPORT_FILE = "report.html"
REPORT_CHOICES = ("full", "light", "none")

#: columns of the ISO table: (direction_rows key, header with unit)
ISO_COLUMNS = (("name", "pose"), ("direction", "direction"), ("cycles", "cycles"), ("RP_l_um", "RP_l [µm]"),
               ("AP_p_um", "AP_p [µm]"), ("vAP_p_um", "vAP_p [µm]"),
               ("RP_l_all_directions_um", "RP_l all directions [µm]"), ("RP_a_mdeg", "RP_a [mdeg]"),
               ("RP_b_mdeg", "RP_b [mdeg]"), ("RP_c_mdeg", "RP_c [mdeg]"), ("AP_a_mdeg", "AP_a [mdeg]"),
               ("AP_b_mdeg", "AP_b [mdeg]"), ("AP_c_mdeg", "AP_c [mdeg]"))

#: columns of the drift table: (key of a direction's ``drift`` in ``summary.json``, header with unit)
DRIFT_COLUMNS = (("dAP_p_um", "dAP_p [µm]"), ("dRP_l_um", "dRP_l [µm]"), ("dRP_a_mdeg", "dRP_a [mdeg]"),
                 ("dRP_b_mdeg", "dRP_b [mdeg]"), ("dRP_c_mdeg", "dRP_c [mdeg]"))

STYLE = """
body { font-family: sans-serif; margin: 1.5em; color: #222; max-width: 1200px; }
iframe { width: 100%; height: 560px; border: 1px solid #bbb; }
table { border-collapse: collapse; margin: 0.5em 0 1.5em; }
th, td { border: 1px solid #ccc; padding: 0.25em 0.6em; text-align: right; }
th:first-child, td:first-child { text-align: left; }
.colourbar { width: 420px; height: 18px; border: 1px solid #888; }
.scale { display: flex; justify-content: space-between; width: 422px; font-size: 0.9em; }
.swatch { display: inline-block; width: 14px; height: 14px; vertical-align: middle; border: 1px solid #888; }
img { max-width: 100%; }
table.inputs th, table.inputs td, th.text { text-align: left; }
td.text { text-align: left; font-size: 0.85em; max-width: 36em; white-space: pre-line; }
"""

#: columns of the joint-model table: (``summary.json`` key, header, unit of a prismatic joint, of a revolute one)
JOINT_COLUMNS = (("stiffness", "stiffness", "N/m", "N·m/rad"), ("normal_force_N", "normal force", "N", "N"),
                 ("friction_radius_m", "friction radius", None, "m"), ("bearing_span_m", "bearing span", "m", "m"),
                 ("backlash", "backlash", "m", "rad"), ("offset", "offset ε_t", "m", "rad"),
                 ("noise_std", "noise σ", "m", "rad"))


def _cell(value) -> str:
    if value is None:
        return "–"
    if isinstance(value, float):
        return f"{value:.3f}"
    return html.escape(str(value))


def html_table(headers: list[str], rows: list[list], text_columns: tuple[int, ...] = ()) -> str:
    """An HTML table; ``text_columns`` hold prose (left-aligned, line breaks kept)."""
    head = "".join(f'<th class="text">{html.escape(h)}</th>' if i in text_columns else f"<th>{html.escape(h)}</th>"
                   for i, h in enumerate(headers))
    body = "".join("<tr>" + "".join(f'<td class="text">{_cell(v)}</td>' if i in text_columns else f"<td>{_cell(v)}</td>"
                                    for i, v in enumerate(row)) + "</tr>" for row in rows)
    return f"<table><tr>{head}</tr>{body}</table>"


def key_value_table(rows: dict[str, str]) -> str:
    """A two-column HTML table: a name (header cell) and its value per row."""
    body = "".join(f"<tr><th>{html.escape(key)}</th><td>{_cell(value)}</td></tr>" for key, value in rows.items())
    return f'<table class="inputs">{body}</table>'


def iso_table(result: StudyResult) -> str:
    """The ISO 9283 figures (µm, mdeg) per pose and approach direction as an HTML table."""
    rows = [[row[key] for key, _ in ISO_COLUMNS] for pose in result.poses for row in pose.direction_rows()]
    return html_table([header for _, header in ISO_COLUMNS], rows)


def drift_section(result: StudyResult, folder: Path) -> str:
    """ISO 9283's drift test as the study simulated it (``[drift]``): what its figures rest on, per pose and approach
    direction each figure's mean ± its Monte Carlo standard error (``summary.json``'s ``drift``), and each pose's
    drift figure (``drift_<pose>.png`` of ``folder``); empty without ``[drift]``."""
    if not result.drifts:
        return ""
    test, cycle_time_s = result.drifts[0].test, result.drifts[0].cycle_time_s
    rows = []
    for pose in result.poses:
        for label in pose.metrics.directions:
            drift = pose.direction_figures(label)["drift"]
            rows.append([pose.name, label, *(f"{drift[key]:.3f} ± {drift[key] * drift['mc_errors'][key]:.3f}"
                                             for key, _ in DRIFT_COLUMNS)])
    text = (f"Each pose approached once every {cycle_time_s:g} s for {test.span_cycles} cycles "
            f"({test.span_cycles * cycle_time_s:g} s) from a {test.start} start, its first and last sets of "
            f"{test.set_cycles} cycles compared (ISO 9283:1998 §7.2.3); each figure is the mean ± Monte Carlo standard "
            f"error over {test.tests} simulated tests of the joints' friction model, so it rests on friction-induced "
            "change only (the friction's time series and warm-up), not on the thermal expansion of links or gears.")
    table = html_table(["pose", "direction", *(header for _, header in DRIFT_COLUMNS)], rows)
    figures = embedded_figures(folder, [drift_figure_file(drift.pose) for drift in result.drifts])
    return f"<h2>ISO 9283 drift, simulated</h2><p>{html.escape(text)}</p>{table}{figures}"


def map_statistics(workspace_map: MapResult) -> str:
    """Per scenario: reachable targets and the min, exact median and max of RP_l [µm] over every target, as
    ``summary.json`` gives them (:meth:`~tribokin.maps.result.MapResult.summary`); an expected map's engines (targets
    per engine) and their largest bound against exact FK; with several scenarios, the change of the median from the
    first (the reference)."""
    summary = workspace_map.summary()
    scenarios = summary.get("scenarios") or [{"RP_l_um": summary["RP_l_um"]}]
    computed = summary.get("computed")
    baseline = scenarios[0]["RP_l_um"]["median"]
    rows = []
    for name, scenario in zip(workspace_map.scenarios, scenarios, strict=True):
        spread = scenario["RP_l_um"]
        change = (None if spread["median"] is None or not baseline
                  else f"{100 * (spread['median'] / baseline - 1):+.1f} %")
        reachable = scenario.get("reachable", summary["reachable"])  # its robot's, when the robots differ
        engines = [] if computed is None else [engine_counts(computed[name]), engine_bounds(computed[name])]
        rows.append([name, f"{reachable} / {summary['count']}", spread["min"], spread["median"], spread["max"],
                     *engines, change])
    headers = ["scenario", "reachable targets", "min RP_l [µm]", "median RP_l [µm]", "max RP_l [µm]",
               *(["engines (targets)", "largest engine bound [nm, nrad]"] if computed is not None else []),
               "median vs first"]
    if len(rows) < 2:
        headers, rows = headers[:-1], [row[:-1] for row in rows]
    note = (f"<p>Approached from both directions: {html.escape(summary['unsuffixed_figures'])}.</p>"
            if "unsuffixed_figures" in summary else "")
    return html_table(headers, rows, text_columns=(5,) if computed is not None else ()) + note + change_note(
        workspace_map)


def change_note(workspace_map: MapResult) -> str:
    """A map comparing two states (``map.compare``): the change of the first scenario's RP_l and AP_p [µm] (min,
    median and max over the targets) and, for expected figures, their largest Monte Carlo standard error and engine
    bound, as the command prints them; empty otherwise."""
    statistics = workspace_map.statistics()
    if statistics.RP_l_change_um is None:
        return ""
    stated = workspace_map.change_rests_on()
    rests_on = "" if stated is None else f"; largest Monte Carlo standard error / engine bound [µm]: {stated}"
    return (f"<p>Change from map.state to map.compare{' (the first scenario)' * (len(statistics.scenarios) > 1)}, "
            f"min / median / max [µm]: RP_l {statistics.RP_l_change_um.as_text()}, AP_p "
            f"{statistics.AP_p_change_um.as_text()}{html.escape(rests_on)}.</p>")


def engine_counts(computed: dict) -> str:
    """``first-order 120, fast-2 3``: the targets per engine their figures rest on (those with any)."""
    return ", ".join(f"{engine} {count}" for engine, count in computed["engine_targets"].items() if count)


def engine_bounds(computed: dict) -> str:
    """The largest bound of the engines used against exact FK, in position [nm] and angle [nrad]."""
    return f"{computed['engine_max_deviation_nm']:.3g}, {computed['engine_max_angle_deviation_nrad']:.3g}"


def thinning_note(layers: dict[str, MapLayer]) -> str:
    """Says so when the scene shows every k-th target of a map only."""
    stride = max((layer.stride for layer in layers.values()), default=1)
    if stride == 1:
        return ""
    return (f"<p>The map is large: the scene covers 1 in {stride} targets along each grid axis. This table, "
            "summary.json and map.csv cover all of them.</p>")


def colour_bar(quantity: str, scale: ColourScale) -> str:
    """The colour bar of a map quantity (``RP_l``...), labelled with its range in µm, and the grey of unreachable
    targets."""
    return (f'<div><b>{html.escape(quantity)} [µm]</b> ({scale.name})</div><div class="colourbar" '
            f'style="background: {scale.css_gradient()}"></div><div class="scale"><span>{scale.low_um:.3f} µm'
            f'</span><span>{scale.high_um:.3f} µm</span></div><div><span class="swatch" style="background: '
            f'rgb(158,158,158)"></span> unreachable target</div>')


def shown_path(path) -> str:
    """A path as the report shows it: absolute, without ``..`` or symbolic links."""
    return str(Path(path).resolve())


def _number(value: float, unit: str | None) -> str:
    """``value`` to 4 significant digits with its unit (``1e5``, not ``1e+05``); no unit: the value does
    not apply (–)."""
    if unit is None:
        return "–"
    mantissa, _, exponent = f"{value:.4g}".partition("e")
    return f"{mantissa}e{int(exponent)} {unit}" if exponent else f"{mantissa} {unit}"


def _friction(law: dict) -> str:
    """A friction law as the study wrote it, its moments and where it comes from."""
    skipped = ("law", "mean", "std", "support", "provenance")
    parameters = ", ".join(f"{k} {v:g}" if isinstance(v, float) else f"{k} {v}" for k, v in law.items()
                           if k not in skipped)
    return (f"{law['law']}{f' ({parameters})' if parameters else ''}: mean {law['mean']:.4g}, std {law['std']:.3g}"
            + (f" — {law['provenance']}" if law.get("provenance") else ""))


def joint_table(settings: dict, prismatic) -> str:
    """The joints' error models (friction law and the ``[joints]`` values, with their units), one row per
    model: joints with the same model share a row; the last column is headed "friction law" where a joint's law
    is of its friction torque or force."""
    models = settings["joint_models"]
    of_torque = any("quantity" in law for law in settings["friction"].values())
    headers = ["joints", "type", *(header for _, header, _, _ in JOINT_COLUMNS),
               "friction law" if of_torque else "friction coefficient μ"]
    rows: dict[tuple, list[str]] = {}
    for name, is_prismatic in zip(settings["joints"], prismatic, strict=True):
        model = models[name]
        cells = tuple(_number(model[key], prismatic_unit if is_prismatic else revolute_unit)
                      if key != "normal_force_N" or model[key] is not None else "from statics"
                      for key, _, prismatic_unit, revolute_unit in JOINT_COLUMNS)
        rows.setdefault(("prismatic" if is_prismatic else "revolute", *cells, _friction(settings["friction"][name])),
                        []).append(name)
    return html_table(headers, [[", ".join(names), *row] for row, names in rows.items()],
                      text_columns=(len(headers) - 1,))


def _overrides(overrides: dict, prefix: str = "") -> list[str]:
    """Nested override tables as dotted ``key = value`` lines (values in JSON, as TOML writes them)."""
    lines = []
    for key, value in overrides.items():
        if isinstance(value, dict):
            lines += _overrides(value, f"{prefix}{key}.")
        else:
            lines.append(f"{prefix}{key} = {json.dumps(value, ensure_ascii=False)}")
    return lines


def _vector(values) -> str:
    return f"({', '.join(f'{v:g}' for v in values)})"


def map_targets(grid: TargetGrid) -> str:
    """Where a map's targets are: the grid's axes, their ranges and counts, and the orientation held."""
    axes = [a for a in grid.axes if a is not None]
    directions = [f" along {_vector(d)}" for d in grid.directions] if grid.kind == "plane" else [""] * 3
    where = f"plane through {_vector(grid.origin_m)} m: " if grid.kind == "plane" else f"{grid.kind}: "
    ranges = "; ".join(f"{a.name}{d} {a.values[0]:g} to {a.values[-1]:g} {a.unit} ({len(a.values)} values)"
                       for a, d in zip(axes, directions, strict=False))
    rpy = grid.describe()["rpy_deg"]
    held = "" if rpy is None else f"; tool orientation held at roll, pitch, yaw {_vector(np.round(rpy, 6) + 0.0)}°"
    return where + ranges + held


def tool_offset(spec: dict, tool_point: str) -> str | None:
    """The tool point's offset of a ``robot_spec`` (``summary.json``) in the frame it is fixed to (the tool point's
    frame ``tool_point`` without its suffix ``_tool_point``): translation [m], roll, pitch, yaw [deg], zero where not
    set; ``None`` without a tool point."""
    offset_m, rpy_deg = spec.get("tool_offset_m"), spec.get("tool_offset_rpy_deg")
    if offset_m is None and rpy_deg is None:
        return None
    return (f"{_vector(offset_m or (0, 0, 0))} m, roll, pitch, yaw {_vector(rpy_deg or (0, 0, 0))}° in "
            f"{tool_point.removesuffix('_tool_point')}")


def input_values(result: StudyResult) -> dict[str, str]:
    """The study's settings by name: study file, robot, tool frame, tool point offset, payload, cycles, approach,
    seed, engine, the ISO cube and the map's targets (those it has)."""
    settings = result.settings
    spec, source = settings["robot_spec"], str(settings["source"])
    offset = tool_offset(spec, settings["tool_frame"])
    counted = [what for what, present in (("pose", result.poses), ("map target", result.map is not None),
                                          ("task target and placement", result.placement is not None)) if present]
    rows = {"study file": source if source.startswith("<") else shown_path(source),  # "<mapping>": no file
            "robot": f"{spec['name']} (example-robot-data)" if spec["name"] else shown_path(spec["urdf"]),
            **({"xacro arguments": ", ".join(f"{name} = {value}" for name, value in spec["xacro_args"].items())}
               if spec.get("xacro_args") else {}),
            "tool frame": settings["tool_frame"],
            **({"tool point offset": offset} if offset else {}),
            "payload": f"{settings['payload_kg']:g} kg",
            "cycles": f"{settings['cycles']} per {' and per '.join(counted)}", "approach": settings["approach"],
            "seed": str(settings["seed"]), "engine": settings["engine"]}
    if settings["iso_cube"]:
        cube = settings["iso_cube"]
        rows["ISO 9283 cube"] = f"centre {_vector(cube['center_m'])} m, side {cube['side_m']:g} m"
    if result.map is not None:
        rows["map targets"] = map_targets(result.map.grid)
    return rows


def task_region(task: MapSpec) -> str:
    """Where a placement's task targets are, in the world frame, as the ``[map]`` gives them (box or plane)."""
    counts = " × ".join(str(n) for n in task.resolution)
    if isinstance(task, BoxMap):
        return f"box from {_vector(task.min_m)} to {_vector(task.max_m)} m, {counts} targets"
    return (f"plane through {_vector(task.origin_m)} m along {_vector(task.axis_u)} from {task.extent_u_m[0]:g} to "
            f"{task.extent_u_m[1]:g} m and along {_vector(task.axis_v)} from {task.extent_v_m[0]:g} to "
            f"{task.extent_v_m[1]:g} m, {counts} targets")


def placement_section(result: StudyResult) -> str:
    """The placement search: what was searched, how it ranks, and the best placement (``summary.json``'s
    ``placement``), its heat map among the figures."""
    placement = result.placement
    if placement is None:
        return ""
    summary = placement.summary()
    best = summary["best"]
    spec = placement.spec
    figures = ", ".join(f"{name} {_cell(value)}" for name, value in best["RP_l_um"].items())
    rows = {"task region": task_region(placement.study.map),
            "candidates": f"{summary['candidates']} (base positions × yaw_deg {_vector(spec.yaw_deg)}°); "
                          f"{summary['meeting_min_reachable']} reach at least {100 * spec.min_reachable:g} % of the "
                          f"{summary['targets']} targets",
            "ranked by": f"expected RP_l {spec.objective} over the targets a candidate reaches; one reaching fewer "
                         f"than {100 * spec.min_reachable:g} % of them ranks after every one that does",
            "best placement": f"candidate {best['candidate']}: base at {_vector(best['base_xyz_m'])} m, roll, pitch, "
                              f"yaw {_vector(best['base_rpy_deg'])}° (yaw +{best['yaw_deg']:g}°)",
            "its targets": f"{best['reachable_targets']} of {summary['targets']} reached; expected RP_l [µm]: "
                           f"{figures}",
            "files": "placement.csv (every candidate, best first), best.toml (the study placed there)"}
    return f"<h2>Where to put the robot</h2>{key_value_table(rows)}"


def inputs_section(result: StudyResult, prismatic) -> str:
    """What the study was run with (:func:`input_values`), each joint's model and each scenario's overrides
    of the study."""
    parts = [f"<h2>Inputs</h2>{key_value_table(input_values(result))}<h3>Joint models</h3>"
             f"{joint_table(result.settings, prismatic)}"]
    scenarios = result.settings["scenarios"]
    if scenarios:
        scenario_rows = [[s["name"], "\n".join(_overrides(s["overrides"])) or "none: the study as written",
                          s.get("robot", f"{result.settings['robot']} (the study's)")] for s in scenarios]
        headers = ["scenario", "overrides of the study", "robot"]
        if not any("robot" in s for s in scenarios):  # every scenario measured with the study's robot
            headers, scenario_rows = headers[:-1], [row[:-1] for row in scenario_rows]
        parts.append("<h3>Scenarios</h3>" + html_table(headers, scenario_rows, (1,)))
    return "".join(parts)


def embedded_figures(folder: Path, names: list[str]) -> str:
    """The PNGs ``names`` of ``folder`` (those that exist), in that order, as ``<img>`` with base64 data URIs."""
    parts = []
    for name in names:
        png = Path(folder) / name
        if not png.is_file():
            continue
        data = base64.b64encode(png.read_bytes()).decode("ascii")
        parts.append(f'<h3>{html.escape(png.name)}</h3><img alt="{html.escape(png.stem)}" '
                     f'src="data:image/png;base64,{data}">')
    return "".join(parts)


def robot_geometry(drawn: RobotDrawn | None, variant: str) -> str:
    """What the scene drew of the robot: how many meshes of which geometry set (and primitive shapes), the mesh
    files listed below a toggle; or its skeleton, and why."""
    if drawn is not None and drawn.geometry == "skeleton":
        text = drawn.skeleton_text()
        return f"<p>{html.escape(text[:1].upper() + text[1:])}.</p>"
    if drawn is None or not drawn.meshes + drawn.shapes:
        geometry = "visual" if variant == "full" else "collision"
        return f"<p>Robot not drawn: no {geometry} geometry (--report {variant}).</p>"
    shapes = {kind: drawn.shapes.count(kind) for kind in sorted(set(drawn.shapes))}
    shown = ", ".join(f"{count} {kind}{'es' if kind.endswith('x') and count > 1 else 's' if count > 1 else ''}"
                      for kind, count in shapes.items())
    plural = "" if len(drawn.meshes) == 1 else "es"
    text = (f"Robot drawn from its {drawn.geometry} geometry (--report {variant}): {len(drawn.meshes)} mesh{plural}"
            + (f" and {shown}" if shown else "") + ".")
    files = "".join(f"<li>{html.escape(path)}</li>" for path in drawn.meshes)
    return f"<p>{html.escape(text)}</p>" + (f"<details><summary>Mesh files drawn</summary><ul>{files}</ul></details>"
                                           if files else "")


def report_html(result: StudyResult, scene_page: str, info: SceneInfo, layers: dict[str, MapLayer],
                folder: Path, figures: list[str], variant: str, prismatic) -> str:
    """The report page around ``scene_page`` (a full meshcat static page), embedding the PNGs ``figures`` of
    ``folder``; ``prismatic``: per joint, True for a prismatic one (the units of its model)."""
    statistics = (f"<h3>Map statistics</h3>{thinning_note(layers)}{map_statistics(result.map)}"
                  if result.map is not None else "")
    bars = "".join(colour_bar(quantity, scale) for quantity, scale in info.colour_scales.items())
    maps = f"<h2>RP_l maps</h2>{bars}{statistics}" if layers else ""
    notes = "".join(f"<p><b>Note:</b> {html.escape(n)}</p>" for n in info.notes)
    title = html.escape(f"tribokin — {result.name}")
    clouds = (f"Cycle clouds and their 3σ covariance ellipsoids are drawn around their barycenter, magnified "
              f"<b>×{info.magnification:g}</b>. " if result.poses else "")
    poses = f"<h2>ISO 9283 figures per pose</h2>{iso_table(result)}" if result.poses else ""
    inputs = input_values(result)
    summary = ", ".join(f"{name} {inputs[name]}" for name in ("robot", "tool frame", "payload", "cycles", "approach"))
    return f"""<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>{title}</title><style>{STYLE}</style></head>
<body><h1>{title}</h1>
<p>{html.escape(summary[:1].upper() + summary[1:])}. All inputs are listed below the scene.</p>
<h2>Scene</h2>
<p>{clouds}Open Controls (top right) toggles the robot, each map and each pose.</p>
{robot_geometry(info.robot, variant)}
{scene_frame(scene_page)}
{notes}
{maps}
{poses}{drift_section(result, folder)}
{placement_section(result)}
{inputs_section(result, prismatic)}
<h2>Figures</h2>{embedded_figures(folder, figures)}
</body></html>
"""


def write_report(result: StudyResult, robot: Robot, folder, figures: list[str] = (),
                 map_layers: dict[str, MapLayer] | None = None, cube: Cube | None = None,
                 variant: str = "full") -> tuple[Path, SceneInfo]:
    """Write ``folder/report.html`` (a temporary name, then renamed); returns its path and what the scene drew.

    Args:
        result: the study's results; the robot is drawn at ``result.display_configuration()``; its map's
            statistics are the exact ones of :meth:`~tribokin.maps.result.MapResult.summary`.
        robot: the robot the study ran.
        folder: the output folder.
        figures: its PNG figures to embed, in this order (those that exist).
        map_layers: RP_l maps by scenario.
        cube: the ISO 9283 test cube.
        variant: ``"full"`` (visual meshes) or ``"light"`` (collision meshes).
    """
    folder = Path(folder)
    layers = dict(map_layers or {})
    scene, info = static_scene(robot, result.display_configuration(), result.poses, layers, cube, variant)
    page = report_html(result, scene, info, layers, folder, list(figures), variant, robot.joint_is_prismatic)
    return write_page(folder, page), info


def static_scene(robot: Robot, q, poses, map_layers: dict[str, MapLayer] | None = None, cube: Cube | None = None,
                 variant: str = "full") -> tuple[str, SceneInfo]:
    """The scene :func:`~tribokin.viz.scene.build_scene` draws (same arguments) as one self-contained meshcat page,
    built without any server, and what it drew."""
    vis = static_visualizer()
    info = build_scene(vis, robot, q, poses, map_layers, cube, variant=variant)
    return vis.static_html(), info


def scene_frame(scene_page: str, style: str | None = None) -> str:
    """``scene_page`` (a full page) inside an ``<iframe srcdoc>``, its text escaped for the attribute: the frame
    holds the whole page and asks nothing of a server; ``style``: the frame's CSS (``None``: the page's)."""
    srcdoc = scene_page.replace("&", "&amp;").replace('"', "&quot;")
    styled = "" if style is None else f' style="{html.escape(style)}"'
    return f'<iframe title="3-D scene"{styled} srcdoc="{srcdoc}"></iframe>'


def write_page(folder, page: str) -> Path:
    """Write ``page`` as ``folder/report.html`` (a temporary name, then renamed); returns its path."""
    folder = Path(folder)
    temporary = folder / f".{REPORT_FILE}.partial"
    temporary.write_text(page, encoding="utf-8")
    os.replace(temporary, folder / REPORT_FILE)
    return folder / REPORT_FILE
