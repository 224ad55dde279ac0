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
    print(f"chosen: friction = {result.inline}")
    print(f"results in {args.out}/ (law.toml, fit.json, mu_cycles.png, mu_histogram.png)")
