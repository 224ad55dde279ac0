"""The ``tribokin`` command.

Bad input prints one line, ``tribokin: error: <file>: <key>: <what to fix>``,
and exits with status 2; nothing is written.
"""

from __future__ import annotations

import argparse
import sys

from tribokin.errors import InputError


class _Parser(argparse.ArgumentParser):
    """argparse, with usage errors on one line and exit status 2."""

    def error(self, message):
        raise InputError(message, "command line")


def _run(args) -> None:
    from tribokin.output import check_output_folder, write_results
    from tribokin.study import run_study

    check_output_folder(args.out, args.force)
    result = run_study(args.study, cycles=args.cycles, seed=args.seed)
    out = write_results(result, args.out, args.force, report=args.report)
    print(f"{'pose':<10} {'RP_l [µm]':>10} {'AP_p [µm]':>10} {'vAP_p [µm]':>11}")
    for pose in result.poses:
        row = pose.report_row()
        vap = "-" if row["vAP_p_um"] is None else f"{row['vAP_p_um']:.3f}"
        print(f"{pose.name:<10} {row['RP_l_um']:>10.3f} {row['AP_p_um']:>10.3f} {vap:>11}")
    print(f"results in {out}/ (summary.json, poses.csv, samples.npz, field_*.png)")
    if args.report != "none":
        import numpy as np

        magnification = float(np.load(out / "scene.npz")["magnification"])
        size_mb = (out / "report.html").stat().st_size / 1e6
        print(f"report: {out / 'report.html'} ({size_mb:.1f} MB, {args.report} meshes, clouds ×{magnification:g}); "
              f"live viewer: tribokin view {out}")


def _view(args) -> None:
    from tribokin.viz.live import start_live_scene, wait_until_interrupted

    vis, info = start_live_scene(args.folder, args.meshes)
    for note in info.notes:
        print(f"note: {note}")
    print(f"clouds magnified ×{info.magnification:g}")
    print(f"scene at {vis.url()} (meshcat-server pid {vis.window.server_proc.pid}; Ctrl-C to stop)", flush=True)
    if not wait_until_interrupted(vis):
        raise InputError("meshcat-server stopped unexpectedly; run `tribokin view` again", "meshcat-server")
    print("viewer stopped")


def _robots(args) -> None:
    from tribokin.robot import TESTED_ROBOTS, example_robot_names

    for name in example_robot_names():
        print(f"{name}{'  (tested)' if name in TESTED_ROBOTS else ''}")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="tribokin", description="Friction-induced pose repeatability (ISO 9283) of robots.")
    commands = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    run = commands.add_parser("run", help="run a study file and write its results")
    run.add_argument("study", help="study file (TOML)")
    run.add_argument("--out", required=True, help="output folder (must not exist, unless --force)")
    run.add_argument("--cycles", type=int, help="cycles per pose (overrides the file)")
    run.add_argument("--seed", type=int, help="random seed (overrides the file)")
    run.add_argument("--force", action="store_true", help="replace an existing output folder")
    run.add_argument("--report", choices=("full", "light", "none"), default="full",
                     help="report.html with the robot's visual meshes (full, default), its collision meshes "
                          "(light, far smaller) or no report")
    run.set_defaults(handler=_run)

    view = commands.add_parser("view", help="show an output folder's scene in a live meshcat viewer")
    view.add_argument("folder", help="output folder written by `tribokin run`")
    view.add_argument("--meshes", choices=("full", "light"), default="full",
                      help="robot visual meshes (full, default) or collision meshes (light)")
    view.set_defaults(handler=_view)

    robots = commands.add_parser("robots", help="list the robot names [robot] name = ... accepts")
    robots.set_defaults(handler=_robots)
    return parser


def main(argv=None) -> int:
    """Entry point of the ``tribokin`` command; returns the exit status."""
    try:
        args = build_parser().parse_args(argv)
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
