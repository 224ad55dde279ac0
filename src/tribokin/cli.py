"""The ``tribokin`` command: arguments, printing, the map's progress bar.

Bad input prints one line, ``tribokin: error: <file>: <key>: <what to fix>``,
and exits with status 2; nothing is written.
"""

from __future__ import annotations

import argparse
import gc
import sys
import warnings
from contextlib import contextmanager
from pathlib import Path

from tqdm import tqdm

from tribokin.errors import InputError
from tribokin.kinematics.urdf_meshes import WITHOUT_MESHES


class _Parser(argparse.ArgumentParser):
    """argparse, with usage errors on one line and exit status 2."""

    def error(self, message):
        raise InputError(message, "command line")


@contextmanager
def _claimed(out, force: bool):
    """Check the output folder, hold its lock (``<out>.lock``) while the block runs, and first delete the
    temporary folders a killed run left beside it (or move back an output folder it had moved aside)."""
    from tribokin.output.folder import check_output_folder, remove_leftovers
    from tribokin.output.lock import output_lock

    check_output_folder(out, force)
    with output_lock(out):
        restored = remove_leftovers(out)
        if restored is not None:
            print(f"note: moved '{out}' back from '{restored}', where a killed --force run had left it")
            check_output_folder(out, force)
        yield


@contextmanager
def _option_named(argument: str, instead: str):
    """Within the block, an :class:`InputError` whose remedy is the library's ``argument`` (``meshes=False reads no
    mesh``) gives the command's remedy ``instead`` (``--report none reads no mesh``)."""
    try:
        yield
    except InputError as error:
        if argument not in error.message:
            raise
        raise InputError(error.message.replace(argument, instead), error.source, error.key) from None


#: Chunks finished after the warm-up before the progress bar shows a rate and an ETA.
ETA_SAMPLES = 4


class ProgressBar(tqdm):
    """tqdm whose rate, hence ETA, is the average since its first ``warm_up`` updates (the chunks that paid for
    start-up: worker processes, first calls), shown once ``samples`` more are in (``?`` until then); and without
    tqdm's monitor thread, which would outlive the bar and keep later runs from forking workers."""

    monitor_interval = 0

    def __init__(self, *args, warm_up: int = 1, samples: int = ETA_SAMPLES, **kwargs):
        self.warm_up, self.samples, self.updates = warm_up, samples, 0
        self.clock_start: tuple[float, float] | None = None  # (time [s], count) at the end of the warm-up
        super().__init__(*args, **kwargs)

    def update(self, n=1):
        self.updates += 1
        super().update(n)
        if self.updates == self.warm_up and not self.disable:
            self.clock_start = (self._time(), self.n)

    @property
    def format_dict(self) -> dict:
        shown = super().format_dict
        shown["rate"] = 0.0  # tqdm shows "?"
        if self.clock_start is not None and self.updates >= self.warm_up + self.samples:
            start_s, start_n = self.clock_start
            shown["rate"] = (self.n - start_n) / max(self._time() - start_s, 1e-9)
        return shown


#: What the map's progress says first when numba compiles the kernels before its chunks run (:func:`map_progress`).
COMPILING = ("map: numba compiles tribokin's kernels first, once after installing or changing tribokin "
             "(TRIBOKIN_KERNELS=numpy runs without them)")


def kernels_to_compile() -> bool:
    """Whether a run compiles its kernels: on the compiled path (:func:`~tribokin.compiled.use_compiled`), with none
    of tribokin's kernels (its modules ``*_kernels``) in numba's cache (:func:`~tribokin.compiled.cache_is_empty`)."""
    from tribokin.compiled import cache_is_empty, use_compiled

    if not use_compiled():
        return False
    import importlib
    import pkgutil

    import tribokin

    names = [module.name for module in pkgutil.walk_packages(tribokin.__path__, "tribokin.")
             if module.name.endswith("_kernels")]
    return cache_is_empty([importlib.import_module(name) for name in names])


@contextmanager
def map_progress(warm_up: int, compiling: bool = False):
    """A ``progress(done_targets, total_targets)`` callback drawing the map's :class:`ProgressBar`, made at
    its first call (after the run's checks, before its chunks), and when ``compiling`` (:func:`kernels_to_compile`,
    asked before the run) first saying so on stderr; the bar is closed when the block ends."""
    bar = None

    def report(done: int, total: int) -> None:
        nonlocal bar
        if bar is None:
            if compiling:
                print(COMPILING, file=sys.stderr, flush=True)
            bar = ProgressBar(total=total, initial=done, unit="target", desc="map", warm_up=warm_up)
        else:
            bar.update(done - bar.n)

    try:
        yield report
    finally:
        if bar is not None:
            bar.close()


def _run(args) -> None:
    from tribokin.output.views_process import ViewsProcess

    views = ViewsProcess.start(args.study, args.cycles, args.seed, args.report)  # first: it imports meanwhile
    try:
        from tribokin.execution import executor_for

        with executor_for(args.workers, args.scheduler) as executor, _claimed(args.out, args.force):
            result, out = _compute_and_write(args, executor, views)
    finally:
        if views is not None:
            views.close()
    files = []
    if result.poses:
        _print_poses(result)
        files += ["poses.csv", "samples.npz", "field_*.png"]
    if result.map is not None:
        _print_map(result.map.summary())
        files += ["map*.csv", "map_*.png"]
    if result.placement is not None:
        _print_placement(result.placement.summary(), out)
        files += ["placement.csv", "placement.png", "best.toml"]
    settings = result.settings
    how = "robot.tool_frame" if settings["robot_spec"]["tool_frame"] else "the default: the end of the longest chain"
    print(f"tool frame: {settings['tool_frame']} ({how}), moved by {', '.join(settings['joints'])}")
    print(f"results in {out}/ (summary.json, {', '.join(files)})")
    if args.report != "none":
        import numpy as np

        magnification = float(np.load(out / "scene.npz")["magnification"])
        size_mb = (out / "report.html").stat().st_size / 1e6
        robot = f"{args.report} meshes"
        if result.robot.read_geometry is None:
            from tribokin.viz.scene import RobotDrawn

            print(f"note: {RobotDrawn('skeleton', missing=result.robot.missing_meshes).skeleton_text()}")
            robot = "robot drawn as a skeleton"
        print(f"report: {out / 'report.html'} ({size_mb:.1f} MB, {robot}, clouds ×{magnification:g}); "
              f"live viewer: tribokin view {out}")


def _compute_and_write(args, executor, views=None):
    """Run the study (resuming from ``<out>.chunks`` if asked) and write its output folder, its views drawn by
    ``views`` (:class:`~tribokin.output.views_process.ViewsProcess`) if given. A refusal deletes the chunk folder this
    run created, never one an interrupted run left for ``--resume``."""
    from tribokin.maps.store import check_chunk_folder, chunk_folder, discard
    from tribokin.output.writers import import_views, write_results
    from tribokin.run import run_study

    chunks = chunk_folder(args.out)
    if args.force and not args.resume:
        discard(chunks)
    check_chunk_folder(chunks, args.resume)
    resumed = chunks.exists()
    try:
        with map_progress(warm_up=args.workers, compiling=kernels_to_compile()) as progress, \
                _option_named(WITHOUT_MESHES, "--report none reads no mesh"):
            result = run_study(args.study, cycles=args.cycles, seed=args.seed, executor=executor, checkpoint=chunks,
                               resume=args.resume, progress=progress, meshes=args.report != "none",
                               meanwhile=None if views is not None else import_views)
        result.reproduce["command"] = ["tribokin", *args.argv]
        out = write_results(result, args.out, args.force, report=args.report, executor=executor, views=views)
    except InputError:
        if not resumed:
            discard(chunks)
        raise
    discard(chunks)
    return result, out


def _print_poses(result) -> None:
    width = max(10, *(len(pose.name) for pose in result.poses))
    print(f"{'pose':<{width}} {'direction':<9} {'RP_l [µm]':>10} {'AP_p [µm]':>10} {'vAP_p [µm]':>11}")
    for row in (row for pose in result.poses for row in pose.direction_rows()):
        vap = "-" if row["vAP_p_um"] is None else f"{row['vAP_p_um']:.3f}"
        print(f"{row['name']:<{width}} {row['direction']:<9} {row['RP_l_um']:>10.3f} {row['AP_p_um']:>10.3f} "
              f"{vap:>11}")


def _spread_um(spread: dict) -> str:
    if spread["min"] is None:
        return "-"
    return f"{spread['min']:.3f} / {spread['median']:.3f} / {spread['max']:.3f}"


def _print_map(summary: dict) -> None:
    shape = " x ".join(str(n) for n in summary["shape"][::-1] if n > 1) or "1"
    print(f"map ({summary['kind']}, {shape}): {summary['reachable']} of {summary['count']} targets reachable, "
          f"{summary['cycles']} cycles each")
    scenarios = summary.get("scenarios") or [{"name": "", "RP_l_um": summary["RP_l_um"]}]
    width = max(len(s["name"]) for s in scenarios)
    reach = "reached_by_any" in summary  # the scenarios' robots differ: each reaches its own targets
    print(f"{'':<{width}} {'RP_l min / median / max [µm]':>30}" + (f" {'wins':>7}" if "wins" in summary else "")
          + (f" {'reachable':>9}" if reach else ""))
    for scenario in scenarios:
        wins = f" {summary['wins'][scenario['name']]:>7}" if "wins" in summary else ""
        reachable = f" {scenario['reachable']:>9}" if reach else ""
        print(f"{scenario['name']:<{width}} {_spread_um(scenario['RP_l_um']):>30}{wins}{reachable}")


def _print_placement(summary: dict, out: Path) -> None:
    best, targets = summary["best"], summary["targets"]
    print(f"placement: {summary['candidates']} candidates, {summary['meeting_min_reachable']} reach at least "
          f"{100 * summary['min_reachable']:g} % of the task's {targets} targets; ranked by expected RP_l "
          f"{summary['objective']}")
    figures = " / ".join("-" if best["RP_l_um"][name] is None else f"{best['RP_l_um'][name]:.3f}"
                         for name in ("mean", "p95", "max"))
    print(f"best: candidate {best['candidate']}, base at ({', '.join(f'{v:g}' for v in best['base_xyz_m'])}) m, "
          f"yaw +{best['yaw_deg']:g}° (base roll, pitch, yaw {', '.join(f'{v:g}' for v in best['base_rpy_deg'])}°): "
          f"reaches {best['reachable_targets']} of {targets}, RP_l mean / p95 / max {figures} µm")
    if not best["meets_min_reachable"]:
        print(f"warning: no candidate reaches {100 * summary['min_reachable']:g} % of the targets; the best reaches "
              f"{best['reachable_targets']} of them")
    print(f"the study placed there: {out / 'best.toml'} (tribokin run {out / 'best.toml'} --out DIR maps the task "
          "region from it)")


def _view(args) -> None:
    from tribokin.viz.live import live_scene, stop_signals_interrupt

    try:
        with stop_signals_interrupt(), _option_named(WITHOUT_MESHES, "repair the file; a run with --report none "
                                                     "reads no mesh"), \
                live_scene(args.folder, args.meshes) as (server, info):
            notes = info.notes + ([info.robot.skeleton_text()] if info.robot.geometry == "skeleton" else [])
            for note in notes:
                print(f"note: {note}")
            print(f"clouds magnified ×{info.magnification:g}")
            print(f"scene at {server.web_url} (meshcat-server pid {server.process.pid}; Ctrl-C to stop)", flush=True)
            server.process.wait()
    except KeyboardInterrupt:  # Ctrl-C, SIGTERM or SIGHUP; live_scene has stopped the server
        print("viewer stopped")
        return
    raise InputError("meshcat-server stopped unexpectedly; run `tribokin view` again", "meshcat-server")


def _robots(args) -> None:
    from tribokin.errors import located
    from tribokin.kinematics.robot import TESTED_ROBOTS, candidate_tool_frames, example_robot_names

    if args.frames is None:
        for name in example_robot_names():
            print(f"{name}{'  (tested)' if name in TESTED_ROBOTS else ''}")
        return
    with located("command line", "--frames"):
        frames = candidate_tool_frames(args.frames)
    if frames.default is None:
        print(f"no default tool frame: {frames.why_none}")
    marked = "" if frames.default is None else (" (* the default: the end of the longest chain; robot.tool_frame = "
                                                "... picks another)")
    print(f"tool frames of {args.frames}, with the joints that move each{marked}:")
    width = max(len(name) for name, _ in frames.frames)
    for name, joints in frames.frames:
        print(f"{'*' if name == frames.default else ' '} {name:<{width}}  {joints} joints")


def _fit_friction(args) -> None:
    from tribokin.tribology_reports import fit_friction

    with _claimed(args.out, args.force):
        report = fit_friction(args.log, args.out, args.running_in, args.force)
    print(f"{report['cycles']} cycles, {report['running_in_cycles']} running-in ({report['running_in']}), "
          f"{report['steady_cycles']} fitted")
    print(f"{'law':<10} {'AIC':>12} {'KS p':>8}")
    for fit in report["fits"]:
        print(f"{fit['law']:<10} {fit['aic']:>12.2f} {fit['ks_pvalue']:>8.3g}")
    print(f"chosen: friction = {report['inline']}")
    print(f"results in {args.out}/ (law.toml, fit.json, mu_cycles.png, mu_histogram.png)")


def _surface(args) -> None:
    from tribokin.tribology_reports import surface_report

    with _claimed(args.out, args.force):
        report = surface_report(args.profile, args.out, args.area_m2, args.z_range_m, args.radius_range_m,
                                args.force)
    print(f"{report['peaks']} peaks, AR = {report['AR_m'] * 1e6:.2f} µm, D_s = 1.2/AR² = "
          f"{report['summit_density_m2'] * 1e-6:.1f} per mm²")
    print(f"Alt = {report['Alt_m'] * 1e6:.3f} µm, SAlt = {report['SAlt_m'] * 1e6:.3f} µm, "
          f"radius lognormal a = {report['radius_a']:.3f}, b = {report['radius_b']:.3f} (R* = R / 1 µm)")
    print(f"asperities (eq. 6) on {args.area_m2:g} m²: {report['asperity_count']['count']:.1f}")
    print(f"results in {args.out}/ (surface.json, profile.png, p_z_R.png)")


def _measure(args) -> None:
    from tribokin.measurement_reports import Segmenting, measure

    extra = [key for key, value in (("--dwell-radius-m", args.dwell_radius_m), ("--dwell-min-s", args.dwell_min_s),
                                    ("--match-radius-m", args.match_radius_m)) if value is not None]
    if extra and not args.segment:
        raise InputError("applies to a raw stream only; add --segment or leave it out", "command line", extra[0])
    segmenting = None
    if args.segment:
        given = {"radius_m": args.dwell_radius_m, "min_duration_s": args.dwell_min_s,
                 "match_radius_m": args.match_radius_m}
        segmenting = Segmenting(**{key: value for key, value in given.items() if value is not None})
    with _claimed(args.out, args.force):
        summary = measure(args.file, args.out, args.force, args.seed, segmenting, args.noise_floor, args.report)
    settings = summary["settings"]
    if settings["segmentation"] is not None:
        seg = settings["segmentation"]
        print(f"dwells: radius {seg['dwell_radius_m']:g} m for {seg['dwell_min_duration_s']:g} s, matched within "
              f"{seg['match_radius_m']:g} m: {seg['dwells']} found, {len(seg['unmatched'])} unmatched")
        for dwell in seg["unmatched"]:
            print(f"  unmatched dwell {dwell['start_s']:g}-{dwell['end_s']:g} s at "
                  f"{', '.join(f'{v:.6g}' for v in dwell['position_m'])} m (its position is visited once)")
    rows = [(pose, label, d) for pose in summary["poses"] for label, d in pose["directions"].items()]
    width = max(10, *(len(pose["name"]) for pose, _, _ in rows))
    print(f"{'pose':<{width}} {'direction':<15} {'cycles':>6} {'RP_l [µm]':>10} {'95 % [µm]':>17} {'AP_p [µm]':>10} "
          f"{'vAP_p [µm]':>11} {'RP_l all [µm]':>14}")
    number = lambda value, size: f"{'-' if value is None else f'{value:.3f}':>{size}}"  # noqa: E731
    for pose, label, d in rows:
        interval = "too short" if d["RP_l_95_um"] is None else f"{d['RP_l_95_um'][0]:.3f}-{d['RP_l_95_um'][1]:.3f}"
        print(f"{pose['name']:<{width}} {label:<15} {d['cycles']:>6} {number(d['RP_l_um'], 10)} {interval:>17} "
              f"{number(d['AP_p_um'], 10)} {number(pose['vAP_p_um'], 11)} {number(pose['RP_l_all_directions_um'], 14)}")
    registration, correction = settings["registration"], settings["commanded_correction"]
    print(f"registration: rms residual {registration['rms_residual_um']:.3f} µm over "
          f"{len(registration['poses'])} poses" if registration["made"] else f"registration: {registration['why']}")
    if correction["largest_spread_um"] is not None:
        print(f"re-taught points: {correction['why']} (largest spread {correction['largest_spread_um']:.3f} µm)")
    flags = [f"{pose['name']} {label} {name}" for pose in summary["poses"] for label, d in pose["directions"].items()
             for name in d["noise_flags"]] + [f"{pose['name']} {name}" for pose in summary["poses"]
                                              for name in pose["noise_flags"]]
    if settings["noise_floor"] is not None:
        print(f"within 2x the noise floor ({settings['noise_floor']['RP_l_um']:.3f} µm): "
              f"{', '.join(flags) if flags else 'none'}")
    files = "summary.json, poses.csv, field_*.png" + (", drift.png" if (Path(args.out) / "drift.png").exists() else "")
    print(f"results in {args.out}/ ({files}{', report.html' if args.report != 'none' else ''})")


def _calibrate(args) -> None:
    from tribokin.calibration_reports import calibrate
    from tribokin.execution import executor_for

    with executor_for(args.workers, None) as executor, _claimed(args.out, args.force), \
            map_progress(warm_up=args.workers, compiling=kernels_to_compile()) as progress:
        summary = calibrate(args.study, args.measurements, args.out, args.force, args.report, args.seed, executor,
                            progress)
    registration = summary["registration"]
    print(f"frame: registered, rms residual {registration['rms_residual_um']:.1f} µm (the robot's geometric error)"
          if registration["made"] else f"frame: not registered; {registration['why']}")
    for item in summary["settings"]["left_out"]:
        print(f"left out: {item['pose']} '{item['direction']}' ({item['cycles']} cycles): {item['why']}")
    width = max(len(p["name"]) for p in summary["parameters"])
    print(f"{'parameter':<{width}} {'value':>12} {'std error':>12}  95 % interval (profile likelihood)")
    for p in summary["parameters"]:
        if not p["identifiable"]:
            print(f"{p['name']:<{width}} {'not identifiable':>25}  {p['hint']}")
            continue
        ends = " – ".join("unbounded" if v is None else f"{v:.4g}" for v in p["ci95"])
        print(f"{p['name']:<{width}} {p['value']:>12.4g} {p['std_error']:>12.4g}  {ends} {p['unit']}")
    information = summary["information"]
    print(f"log L {summary['log_likelihood']:.6g}, AIC {summary['aic']:.6g}; information rank {information['rank']} "
          f"of {information['free_parameters']}")
    print("held out one pose at a time: measured / predicted [95 % interval] RP_l [µm]")
    for pose in summary["cross_validation"]:
        shown = [f"{d} {f['measured_um']:.2f} / {f['predicted_um']:.2f} [{f['ci95_um'][0]:.2f}, {f['ci95_um'][1]:.2f}]"
                 for d, f in pose["RP_l"].items() if f is not None]
        print(f"  {pose['pose']}: {'; '.join(shown)}")
    print(f"results in {args.out}/ (calibration.json, comparison.csv, calibrated.toml, parity.png, clouds_*.png"
          f"{', report.html' if args.report != 'none' else ''}); predict with: tribokin run {args.out}/calibrated.toml "
          "--out predicted")


def build_parser() -> argparse.ArgumentParser:
    from tribokin import __version__
    from tribokin.measurement.figures import BOOTSTRAP_SEED
    from tribokin.measurement.segmentation import DWELL_MIN_DURATION_S, DWELL_RADIUS_M, MATCH_RADIUS_M

    parser = _Parser(prog="tribokin", description="Friction-induced pose repeatability (ISO 9283) of robots.")
    parser.add_argument("--version", action="version", version=f"tribokin {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, parser_class=_Parser, title="commands",
                                     metavar="COMMAND")

    run = commands.add_parser("run", help="run a study file and write its results")
    run.add_argument("study", help="study file (TOML)")
    run.add_argument("--out", required=True, help="output folder (must not exist, unless --force)")
    run.add_argument("--cycles", type=int, help="cycles per pose (overrides the file)")
    run.add_argument("--seed", type=int, help="random seed (overrides the file)")
    run.add_argument("--force", action="store_true", help="replace an existing output folder")
    run.add_argument("--report", choices=("full", "light", "none"), default="full",
                     help="report.html with the robot's visual meshes (full, default), its collision meshes "
                          "(light, far smaller) or no report")
    run.add_argument("--workers", type=int, default=1,
                     help="local processes computing the map's chunks or the placement's candidates (default 1)")
    run.add_argument("--scheduler", help="address of a dask.distributed scheduler computing the map's chunks or the "
                     "placement's candidates")
    run.add_argument("--resume", action="store_true",
                     help="finish an interrupted map or placement search: reuse the chunks (candidates) "
                          "saved in <out>.chunks/")
    run.set_defaults(handler=_run)

    measure = commands.add_parser("measure", help="ISO 9283 figures of measured data (a laser tracker's CSV)")
    measure.add_argument("file", help="measurement CSV: pose, cycle, [direction,] x_m, y_m, z_m or x_mm, ... "
                                      "(README: Measured data)")
    measure.add_argument("--out", default="measured", help="output folder (must not exist, unless --force)")
    measure.add_argument("--force", action="store_true", help="replace an existing output folder")
    measure.add_argument("--seed", type=int, default=BOOTSTRAP_SEED,
                         help=f"seed of the bootstrap intervals of RP_l (default {BOOTSTRAP_SEED})")
    measure.add_argument("--noise-floor", metavar="FILE",
                         help="readings of the robot standing still (x, y, z columns): flag figures within 2x of "
                              "the instrument's spread")
    measure.add_argument("--segment", action="store_true",
                         help="FILE is a raw stream (t_s and positions, no pose): find its settled dwells")
    measure.add_argument("--dwell-radius-m", type=float,
                         help=f"with --segment: a dwell holds still within this radius (default {DWELL_RADIUS_M:g} m)")
    measure.add_argument("--dwell-min-s", type=float,
                         help=f"with --segment: for at least this long (default {DWELL_MIN_DURATION_S:g} s)")
    measure.add_argument("--match-radius-m", type=float,
                         help=f"with --segment: dwells this close are one pose (default {MATCH_RADIUS_M:g} m)")
    measure.add_argument("--report", choices=("full", "none"), default="full",
                         help="report.html with the table and figures (full, default) or no report")
    measure.set_defaults(handler=_measure)

    calibrate = commands.add_parser("calibrate", help="fit a study's joint model to measured data ([calibration])")
    calibrate.add_argument("study", help="study file (TOML) with a [calibration] section")
    calibrate.add_argument("--measurements", required=True, metavar="FILE",
                           help="measurement CSV (README: Measured data), with q_<joint> or commanded positions")
    calibrate.add_argument("--out", default="fit", help="output folder (must not exist, unless --force)")
    calibrate.add_argument("--force", action="store_true", help="replace an existing output folder")
    calibrate.add_argument("--seed", type=int, default=9283,
                           help="seed of the predictions' simulated tests (default 9283)")
    calibrate.add_argument("--report", choices=("full", "none"), default="full",
                           help="report.html with the tables and figures (full, default) or no report")
    calibrate.add_argument("--workers", type=int, default=1,
                           help="local processes computing the calibrated study's map, if it has one (default 1)")
    calibrate.set_defaults(handler=_calibrate)

    view = commands.add_parser("view", help="show an output folder's scene in a live meshcat viewer")
    view.add_argument("folder", help="output folder written by `tribokin run`")
    view.add_argument("--meshes", choices=("full", "light"), default="full",
                      help="robot visual meshes (full, default) or collision meshes (light)")
    view.set_defaults(handler=_view)

    fit = commands.add_parser("fit-friction", help="fit friction laws to a tribometer log (CSV)")
    fit.add_argument("log", help="CSV with columns cycle, mu or friction_force_N, normal_force_N")
    fit.add_argument("--out", default="friction-fit", help="output folder (must not exist, unless --force)")
    fit.add_argument("--running-in", type=int, help="cycles to trim at the start (default: detected)")
    fit.add_argument("--force", action="store_true", help="replace an existing output folder")
    fit.set_defaults(handler=_fit_friction)

    surface = commands.add_parser("surface", help="asperity statistics of a surface profile (CSV)")
    surface.add_argument("profile", help="CSV with columns x_m, z_m")
    surface.add_argument("--out", default="surface", help="output folder (must not exist, unless --force)")
    surface.add_argument("--area-m2", type=float, default=1e-6, help="apparent area A_a of eq. (6) [m²]")
    surface.add_argument("--z-range-m", type=float, nargs=2, default=(-float("inf"), float("inf")),
                         metavar=("Z1", "Z2"), help="summit altitude range of eq. (6) [m]")
    surface.add_argument("--radius-range-m", type=float, nargs=2, default=(0.0, float("inf")),
                         metavar=("R1", "R2"), help="radius range of eq. (6) [m]")
    surface.add_argument("--force", action="store_true", help="replace an existing output folder")
    surface.set_defaults(handler=_surface)

    robots = commands.add_parser("robots", help="list the robot names [robot] name = ... accepts")
    robots.add_argument("--frames", metavar="ROBOT", help="list the candidate tool frames of a robot name or a URDF "
                        "file instead, the default first")
    robots.set_defaults(handler=_robots)
    return parser


def entry() -> int:
    """The ``tribokin`` command (``python -m tribokin``): :func:`main`, then every object it leaves frozen
    (:func:`gc.freeze`), so that the interpreter's exit does not search them for garbage before the process ends
    (0.4 s after a 600 x 600 map); its exit handlers still run."""
    status = main()
    gc.freeze()
    return status


def _show_warning(message, category, filename, lineno, file=None, line=None, shown=warnings.showwarning):
    """A :class:`~tribokin.compiled.CacheWarning` as one line, ``tribokin: note: ...``; other warnings as Python
    shows them."""
    from tribokin.compiled import CacheWarning

    if issubclass(category, CacheWarning):
        print(f"tribokin: note: {message}", file=sys.stderr if file is None else file)
    else:
        shown(message, category, filename, lineno, file, line)


def main(argv=None) -> int:
    """Entry point of the ``tribokin`` command; returns the exit status (2 for a bare ``tribokin``, which
    prints the help: a command is missing, a usage error as for argparse)."""
    warnings.showwarning = _show_warning
    try:
        argv = sys.argv[1:] if argv is None else [str(arg) for arg in argv]
        parser = build_parser()
        if not argv:
            parser.print_help(sys.stderr)
            return 2
        args = parser.parse_args(argv)
        args.argv = argv
        args.handler(args)
    except InputError as error:
        print(f"tribokin: error: {error.one_line()}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("tribokin: interrupted; nothing was written", file=sys.stderr)
        return 130
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
