"""``tribokin calibrate``: a study's joint model fitted to measured data, written to a folder and printed."""

from __future__ import annotations

from tribokin.cli.options import (
    add_registration_options,
    claimed,
    options_located,
    registration_choice,
    registration_noted,
    warn_registration,
)
from tribokin.cli.progress import kernels_to_compile, map_progress
from tribokin.units import um


def add_parser(commands) -> None:
    """The ``calibrate`` command's arguments."""
    parser = commands.add_parser("calibrate", help="fit a study's joint model to measured data ([calibration])")
    parser.add_argument("study", help="study file (TOML) with a [calibration] section")
    parser.add_argument("--measurements", required=True, metavar="FILE",
                           help="measurement CSV (docs/measurement.md), with q_<joint> or commanded positions")
    parser.add_argument("--out", default="fit", help="output folder (must not exist, unless --force)")
    parser.add_argument("--force", action="store_true", help="replace an existing output folder")
    parser.add_argument("--seed", type=int, default=9283,
                           help="seed of the predictions' simulated tests (default 9283)")
    parser.add_argument("--report", choices=("full", "none"), default="full",
                           help="report.html with the tables and figures (full, default) or no report")
    parser.add_argument("--workers", type=int, default=1,
                           help="local processes computing the calibrated study's map, if it has one (default 1)")
    parser.add_argument("--intervals", choices=("profile", "wald"), default="profile",
                        help="the parameters' 95 %% intervals: profile likelihood (default; a few seconds of re-fits) "
                             "or Wald in log space (from the standard errors; no re-fit)")
    parser.add_argument("--fit-ar1", action="store_true",
                        help="also fit each joint friction group's lag-one autocorrelation (ar1) from the series' "
                             "time order (t_s, else cycle order; series of 10 or more cycles), into calibration.json "
                             "and calibrated.toml's friction, or say why the measurements allow none")
    add_registration_options(parser)
    parser.set_defaults(handler=calibrate)



def calibrate(args) -> None:
    """Calibrate the study, write the folder, print the fit and the held-out predictions."""
    from tribokin.execution import executor_for
    from tribokin.measured.calibrated import calibrate
    from tribokin.output.measured import write_calibration

    registration = registration_choice(args)
    with executor_for(args.workers, None) as executor, claimed(args.out, args.force), \
            map_progress(warm_up=args.workers, compiling=kernels_to_compile()) as progress:
        with options_located({"seed": "--seed"}), registration_noted():
            result = calibrate(args.study, args.measurements, args.seed, out=args.out, executor=executor,
                               progress=progress, registration=registration, intervals=args.intervals,
                               fit_ar1=args.fit_ar1)
        warn_registration(result.inputs.frame)
        write_calibration(result, args.out, args.force, args.report)
    _print(result, args)


def _print(result, args) -> None:
    """The frame, the series left out, the parameters with their intervals, the fit's figures and the held-out
    predictions."""
    from tribokin.measured.calibrated import INTERVALS, ar1_lines

    frame, calibration = result.inputs.frame, result.calibration
    if frame.registration is None:
        print(f"frame: not registered ({frame.choice}); {result.registration_why}")
    else:
        residual = "" if frame.registration.rms_residual_m is None else " (the residual: the robot's geometric error)"
        print(f"frame: registered ({frame.choice}): {frame.describe()}{residual}")
    for item in result.inputs.left_out:
        print(f"left out: {item.pose} '{item.direction}' ({item.cycles} cycles): {item.why}")
    width = max(len(p.name) for p in calibration.parameters)
    print(f"{'parameter':<{width}} {'value':>12} {'std error':>12}  95 % interval "
          f"({INTERVALS[result.interval_kind][1]})")
    for p in calibration.parameters:
        if not p.identifiable:
            print(f"{p.name:<{width}} {'not identifiable':>25}  {p.hint}")
            continue
        ends = " – ".join("unbounded" if v is None else f"{v:.4g}" for v in result.intervals[p.name])
        print(f"{p.name:<{width}} {p.value:>12.4g} {p.std_error:>12.4g}  {ends} {p.unit}")
    print(f"log L {calibration.log_likelihood:.6g}, AIC {calibration.aic:.6g}; information rank {calibration.rank} "
          f"of {len(calibration.parameters)}")
    if result.ar1 is not None:
        print("\n".join(ar1_lines(result.ar1)))
    print("held out one pose at a time: measured / predicted [95 % interval] RP_l [µm]")
    for pose in result.held_out:
        shown = [f"{d} {um(f.measured_m):.2f} / {um(f.predicted_m):.2f} [{um(f.interval_m[0]):.2f}, "
                 f"{um(f.interval_m[1]):.2f}]"
                 for d, f in zip(pose.directions, pose.RP_l, strict=True) if f is not None]
        print(f"  {pose.pose}: {'; '.join(shown)}")
    print(f"results in {args.out}/ (calibration.json, comparison.csv, calibrated.toml, parity.png, clouds_*.png"
          f"{', report.html' if args.report != 'none' else ''}); predict with: tribokin run {args.out}/calibrated.toml "
          "--out predicted")
