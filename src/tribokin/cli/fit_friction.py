"""``tribokin fit-friction``: friction laws fitted to a tribometer log, written to a folder and printed."""

from __future__ import annotations

from tribokin.cli.options import claimed


def add_parser(commands) -> None:
    """The ``fit-friction`` command's arguments."""
    parser = commands.add_parser("fit-friction", help="fit friction laws to a tribometer log (CSV)")
    parser.add_argument("log", help="CSV with columns cycle, mu or friction_force_N, normal_force_N")
    parser.add_argument("--out", default="friction-fit", help="output folder (must not exist, unless --force)")
    parser.add_argument("--running-in", type=int, help="cycles to trim at the start (default: detected)")
    parser.add_argument("--force", action="store_true", help="replace an existing output folder")
    parser.set_defaults(handler=fit_friction)



def fit_friction(args) -> None:
    """Fit the log's laws, write the folder, print the fits and the chosen law."""
    from tribokin.output.tribology import write_friction_fit
    from tribokin.tribology.friction_fit import fit_friction

    with claimed(args.out, args.force):
        result = fit_friction(args.log, args.running_in)
        write_friction_fit(result, args.out, args.force)
    print(f"{result.mu.size} cycles, {result.running_in_cycles} running-in ({result.running_in}), "
          f"{result.steady.size} fitted")
    print(f"{'law':<10} {'AIC':>12} {'KS p':>8}")
    for fit in result.fits:
        print(f"{fit.law:<10} {fit.aic:>12.2f} {fit.ks_pvalue:>8.3g}")
    ar1, box, run_in = result.ar1, result.ljung_box, result.run_in_fit
    print(f"steady cycles: lag-one autocorrelation {ar1.value:.3g} (95 % {ar1.low:.3g} to {ar1.high:.3g}); Ljung-Box "
          f"Q = {box.q:.4g} over {box.lags} lags, p = {box.pvalue:.3g}: "
          f"{'consistent' if box.independent else 'not consistent'} with independent cycles")
    if run_in is not None:
        print(f"running-in (AR(1) noise, phi = {run_in.noise_ar1:.3g}): start = {run_in.start.value:.4g} "
              f"({run_in.start.low:.4g} to {run_in.start.high:.4g}), mu_inf = {run_in.mu_inf.value:.4g} "
              f"({run_in.mu_inf.low:.4g} to {run_in.mu_inf.high:.4g}), tau = {run_in.tau_cycles.value:.3g} cycles "
              f"({run_in.tau_cycles.low:.3g} to {run_in.tau_cycles.high:.3g}), 95 % intervals")
    print(f"chosen: friction = {result.inline}")
    print(f"results in {args.out}/ (law.toml, fit.json, mu_cycles.png, mu_histogram.png)")
