"""``tribokin run``: a study's results written to its folder, its figures printed."""

from __future__ import annotations

import math
from pathlib import Path

from tribokin.cli.options import claimed, option_named
from tribokin.cli.progress import kernels_to_compile, map_progress
from tribokin.errors import InputError
from tribokin.kinematics.urdf_meshes import WITHOUT_MESHES
from tribokin.units import um


def add_parser(commands) -> None:
    """The ``run`` command's arguments."""
    from tribokin.study.names import TABLE_FORMATS

    parser = commands.add_parser("run", help="run a study file and write its results")
    parser.add_argument("study", help="study file (TOML)")
    parser.add_argument("--out", required=True, help="output folder (must not exist, unless --force)")
    parser.add_argument("--cycles", type=int, help="cycles per pose (overrides the file)")
    parser.add_argument("--seed", type=int, help="random seed (overrides the file)")
    parser.add_argument("--force", action="store_true", help="replace an existing output folder")
    parser.add_argument("--report", choices=("full", "light", "none"), default="full",
                     help="report.html with the robot's visual meshes (full, default), its collision meshes "
                          "(light, far smaller) or no report")
    parser.add_argument("--workers", type=int, default=1,
                     help="local processes computing the map's chunks or the placement's candidates (default 1)")
    parser.add_argument("--scheduler", help="address of a dask.distributed scheduler computing the map's chunks or the "
                     "placement's candidates")
    parser.add_argument("--resume", action="store_true",
                     help="finish an interrupted map or placement search: reuse the chunks (candidates) "
                          "saved in <out>.chunks/")
    parser.add_argument("--table-format", choices=TABLE_FORMATS, default=TABLE_FORMATS[0],
                     help="the map's tables as CSV (map*.csv, default) or Parquet (map*.parquet; needs pyarrow: "
                          "pip install 'tribokin[data]')")
    parser.set_defaults(handler=run)



def run(args) -> None:
    """Run the study (its views drawn by a forked process meanwhile), write the folder, print its figures."""
    from tribokin.errors import import_extra, located
    from tribokin.output.views_process import ViewsProcess

    if args.table_format == "parquet":
        with located("command line", "--table-format"):
            import_extra("pyarrow.parquet", "--table-format parquet")

    views = ViewsProcess.start(args.study, args.cycles, args.seed, args.report)  # first: it imports meanwhile
    try:
        from tribokin.execution import executor_for

        with executor_for(args.workers, args.scheduler) as executor, claimed(args.out, args.force):
            result, out = _compute_and_write(args, executor, views)
    finally:
        if views is not None:
            views.close()
    files = []
    if result.poses:
        _print_poses(result.poses)
        files += ["poses.csv", "samples.npz", "field_*.png"] + (["drift_*.png"] if result.drifts else [])
    if result.map is not None:
        _print_map(result.map)
        files += [f"map*.{args.table_format}", "map_*.png"]
    if result.placement is not None:
        _print_placement(result.placement, out)
        files += ["placement.csv", "placement.png", "best.toml"]
    how = "robot.tool_frame" if result.study.robot.tool_frame else "the default: the end of the longest chain"
    print(f"tool frame: {result.robot.tool_frame} ({how}), moved by {', '.join(result.robot.joint_names)}")
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
                option_named(WITHOUT_MESHES, "--report none reads no mesh"):
            result = run_study(args.study, cycles=args.cycles, seed=args.seed, executor=executor, checkpoint=chunks,
                               resume=args.resume, progress=progress, meshes=args.report != "none",
                               meanwhile=None if views is not None else import_views)
        result.reproduce["command"] = ["tribokin", *args.argv]
        out = write_results(result, args.out, args.force, report=args.report, executor=executor, views=views,
                            table_format=args.table_format)
    except InputError:
        if not resumed:
            discard(chunks)
        raise
    discard(chunks)
    return result, out


def _print_poses(poses) -> None:
    """Each pose's RP_l, AP_p and vAP_p [µm], a row per approach direction."""
    width = max(10, *(len(pose.name) for pose in poses))
    print(f"{'pose':<{width}} {'direction':<9} {'RP_l [µm]':>10} {'AP_p [µm]':>10} {'vAP_p [µm]':>11}")
    for pose in poses:
        vap = "-" if pose.metrics.vAP_p_m is None else f"{um(pose.metrics.vAP_p_m):.3f}"
        for label, figures in pose.metrics.directions.items():
            print(f"{pose.name:<{width}} {label:<9} {um(figures.RP_l_m):>10.3f} {um(figures.AP_p_m):>10.3f} "
                  f"{vap:>11}")


def _print_map(workspace_map) -> None:
    """The map's targets reached, each scenario's RP_l (its wins and its robot's reach where they differ), and the
    change between two states."""
    from tribokin.maps.result import DIRECTIONS_NOTE

    statistics, grid, reference = workspace_map.statistics(), workspace_map.grid, workspace_map.reference
    shape = " x ".join(str(n) for n in grid.shape[::-1] if n > 1) or "1"
    print(f"map ({grid.kind}, {shape}): {statistics.reachable} of {statistics.count} targets reachable, "
          f"{reference.cycles} cycles each")
    several, reach = len(statistics.scenarios) > 1, statistics.reached_by_any is not None  # reach: robots differ
    names = [scenario.name if several else "" for scenario in statistics.scenarios]  # one: its row unnamed
    width = max(len(name) for name in names)
    print(f"{'':<{width}} {'RP_l min / median / max [µm]':>30}" + (f" {'wins':>7}" if several else "")
          + (f" {'reachable':>9}" if reach else ""))
    for name, scenario in zip(names, statistics.scenarios, strict=True):
        wins = f" {scenario.wins:>7}" if several else ""
        reachable = f" {scenario.reachable:>9}" if reach else ""
        print(f"{name:<{width}} {scenario.RP_l_um.as_text():>30}{wins}{reachable}")
    if reference.both_directions:
        print(f"approached from both directions: {DIRECTIONS_NOTE}")
    if statistics.RP_l_change_um is not None:  # [map] compare: from the map's state to the second one
        print(f"change from map.state to map.compare, min / median / max [µm]: RP_l "
              f"{statistics.RP_l_change_um.as_text()}, AP_p {statistics.AP_p_change_um.as_text()}")
        rests_on = workspace_map.change_rests_on()
        if rests_on is not None:  # expected figures: what the changes rest on
            print(f"  largest Monte Carlo standard error / engine bound [µm]: {rests_on}")


def _print_placement(placement, out: Path) -> None:
    """The candidates meeting min_reachable, the best one's base, reach and RP_l, and the study placed there."""
    spec, best, targets = placement.spec, placement.best, placement.target_count
    print(f"placement: {len(placement.candidates)} candidates, {placement.meeting_min_reachable} reach at least "
          f"{100 * spec.min_reachable:g} % of the task's {targets} targets; ranked by expected RP_l {spec.objective}")
    figures = " / ".join("-" if math.isnan(value) else f"{value:.3f}" for value in placement.RP_l_um[best.index])
    reachable = placement.reachable[best.index]
    print(f"best: candidate {best.index}, base at ({', '.join(f'{v:g}' for v in best.base_xyz_m)}) m, "
          f"yaw +{best.yaw_deg:g}° (base roll, pitch, yaw {', '.join(f'{v:g}' for v in placement.rpy_deg(best))}°): "
          f"reaches {reachable} of {targets}, RP_l mean / p95 / max {figures} µm")
    if not placement.meets_min_reachable[best.index]:
        print(f"warning: no candidate reaches {100 * spec.min_reachable:g} % of the targets; the best reaches "
              f"{reachable} of them")
    print(f"the study placed there: {out / 'best.toml'} (tribokin run {out / 'best.toml'} --out DIR maps the task "
          "region from it)")
