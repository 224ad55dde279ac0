"""``tribokin measure``: a measurement file's ISO 9283 figures, written to a folder and printed."""

from __future__ import annotations

from tribokin.cli.options import (
    add_registration_options,
    claimed,
    options_located,
    registration_choice,
    registration_noted,
    warn_registration,
)
from tribokin.errors import InputError
from tribokin.units import um

#: The command-line option of each :class:`~tribokin.measured.iso_figures.Segmenting` field.
SEGMENTING_OPTIONS = {"radius_m": "--dwell-radius-m", "min_duration_s": "--dwell-min-s",
                      "match_radius_m": "--match-radius-m"}


def add_parser(commands) -> None:
    """The ``measure`` command's arguments."""
    from tribokin.measurement.figures import BOOTSTRAP_SEED
    from tribokin.measurement.segmentation import DWELL_MIN_DURATION_S, DWELL_RADIUS_M, MATCH_RADIUS_M

    parser = commands.add_parser("measure", help="ISO 9283 figures of measured data (a laser tracker's CSV)")
    parser.add_argument("file", help="measurement CSV: pose, cycle, [direction,] x_m, y_m, z_m or x_mm, ... "
                                      "(docs/measurement.md)")
    parser.add_argument("--out", default="measured", help="output folder (must not exist, unless --force)")
    parser.add_argument("--force", action="store_true", help="replace an existing output folder")
    parser.add_argument("--seed", type=int, default=BOOTSTRAP_SEED,
                         help=f"seed of the bootstrap intervals of RP_l (default {BOOTSTRAP_SEED})")
    parser.add_argument("--noise-floor", metavar="FILE",
                         help="readings of the robot standing still (x, y, z columns): flag figures within 2x of "
                              "the instrument's spread")
    parser.add_argument("--segment", action="store_true",
                         help="FILE is a raw stream (t_s and positions, no pose): find its settled dwells")
    parser.add_argument("--dwell-radius-m", type=float,
                         help=f"with --segment: a dwell holds still within this radius (default {DWELL_RADIUS_M:g} m)")
    parser.add_argument("--dwell-min-s", type=float,
                         help=f"with --segment: for at least this long (default {DWELL_MIN_DURATION_S:g} s)")
    parser.add_argument("--match-radius-m", type=float,
                         help=f"with --segment: dwells this close are one pose (default {MATCH_RADIUS_M:g} m)")
    parser.add_argument("--report", choices=("full", "none"), default="full",
                         help="report.html with the table and figures (full, default) or no report")
    add_registration_options(parser)
    parser.set_defaults(handler=measure)



def measure(args) -> None:
    """Measure the file (a raw stream with ``--segment``), write the folder, print the figures."""
    from tribokin.measured.iso_figures import Segmenting, measure
    from tribokin.output.measured import write_measurement

    given = {"radius_m": args.dwell_radius_m, "min_duration_s": args.dwell_min_s, "match_radius_m": args.match_radius_m}
    extra = [SEGMENTING_OPTIONS[key] for key, value in given.items() if value is not None]
    if extra and not args.segment:
        raise InputError("applies to a raw stream only; add --segment or leave it out", "command line", extra[0])
    segmenting = None
    if args.segment:
        segmenting = Segmenting(**{key: value for key, value in given.items() if value is not None})
    registration = registration_choice(args)
    with claimed(args.out, args.force):
        with options_located({"seed": "--seed", **SEGMENTING_OPTIONS}), registration_noted():
            result = measure(args.file, args.seed, segmenting, args.noise_floor, registration=registration)
        warn_registration(result.frame)
        write_measurement(result, args.out, args.force, args.report)
    _print(result, args)


def _print(result, args) -> None:
    """The segmentation, the figures' table, the registration and correction, and the noise flags."""
    segmentation = result.segmentation
    if segmentation is not None:
        options = segmentation.options
        print(f"dwells: radius {options.radius_m:g} m for {options.min_duration_s:g} s, matched within "
              f"{options.match_radius_m:g} m: {len(segmentation.dwells)} found, {len(segmentation.unmatched)} "
              "unmatched")
        for dwell in segmentation.unmatched:
            print(f"  unmatched dwell {dwell.start_s:g}-{dwell.end_s:g} s at "
                  f"{', '.join(f'{v:.6g}' for v in dwell.position_m.tolist())} m (its position is visited once)")
    rows = [(pose, d) for pose in result.figures for d in pose.directions]
    width = max(10, *(len(pose.pose) for pose, _ in rows))
    print(f"{'pose':<{width}} {'direction':<15} {'cycles':>6} {'RP_l [µm]':>10} {'95 % [µm]':>17} {'AP_p [µm]':>10} "
          f"{'vAP_p [µm]':>11} {'RP_l all [µm]':>14}")
    number = lambda value, size: f"{'-' if value is None else f'{um(value):.3f}':>{size}}"  # noqa: E731
    for pose, d in rows:
        interval = "too short" if d.RP_l_ci95_m is None else f"{um(d.RP_l_ci95_m[0]):.3f}-{um(d.RP_l_ci95_m[1]):.3f}"
        print(f"{pose.pose:<{width}} {d.direction:<15} {d.cycles:>6} {number(d.RP_l_m, 10)} {interval:>17} "
              f"{number(d.AP_p_m, 10)} {number(pose.vAP_p_m, 11)} {number(pose.RP_l_all_directions_m, 14)}")
    correction = result.correction
    print(f"registration ({result.frame.choice}): {result.frame.describe()}")
    if correction.largest_spread_um is not None:
        print(f"re-taught points: {correction.why} (largest spread {correction.largest_spread_um:.3f} µm)")
    flags = [f"{pose.pose} {d.direction} {name}" for pose, d in rows
             for name in result.flag_names(pose.pose, d.direction)]
    flags += [f"{pose.pose} {name}" for pose in result.figures for name in result.flag_names(pose.pose, None)]
    if result.floor is not None:
        print(f"within 2x the noise floor ({um(result.floor.RP_l_m):.3f} µm): {', '.join(flags) if flags else 'none'}")
    files = "summary.json, poses.csv, field_*.png" + (", drift.png" if result.timed else "")
    print(f"results in {args.out}/ ({files}{', report.html' if args.report != 'none' else ''})")
