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
    from tribokin.checkpoint import check_chunk_folder, chunk_folder, discard
    from tribokin.executors import check_executor
    from tribokin.output import check_output_folder, write_results
    from tribokin.study import run_study

    check_executor(args.workers, args.scheduler)
    check_output_folder(args.out, args.force)
    chunks = chunk_folder(args.out)
    if args.force and not args.resume:
        discard(chunks)
    check_chunk_folder(chunks, args.resume)
    result = run_study(args.study, cycles=args.cycles, seed=args.seed, workers=args.workers,
                       scheduler=args.scheduler, checkpoint=chunks, resume=args.resume, progress=True)
    out = write_results(result, args.out, args.force)
    discard(chunks)
    files = []
    if result.poses:
        _print_poses(result)
        files += ["poses.csv", "samples.npz", "field_*.png"]
    if result.map is not None:
        _print_map(result.map.summary())
        files += ["map*.csv", "map_*.png"]
    print(f"results in {out}/ (summary.json, {', '.join(files)})")


def _print_poses(result) -> None:
    print(f"{'pose':<10} {'RP_l [µm]':>10} {'AP_p [µm]':>10} {'vAP_p [µm]':>11}")
    for pose in result.poses:
        row = pose.report_row()
        vap = "-" if row["vAP_p_um"] is None else f"{row['vAP_p_um']:.3f}"
        print(f"{pose.name:<10} {row['RP_l_um']:>10.3f} {row['AP_p_um']:>10.3f} {vap:>11}")


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
    print(f"{'':<{width}} {'RP_l min / median / max [µm]':>30}" + (f" {'wins':>7}" if "wins" in summary else ""))
    for scenario in scenarios:
        wins = f" {summary['wins'][scenario['name']]:>7}" if "wins" in summary else ""
        print(f"{scenario['name']:<{width}} {_spread_um(scenario['RP_l_um']):>30}{wins}")


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
    run.add_argument("--workers", type=int, default=1, help="local processes computing the map's chunks (default 1)")
    run.add_argument("--scheduler", help="address of a dask.distributed scheduler computing the map's chunks")
    run.add_argument("--resume", action="store_true",
                     help="finish an interrupted map: reuse the chunks saved in <out>.chunks/")
    run.set_defaults(handler=_run)

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
