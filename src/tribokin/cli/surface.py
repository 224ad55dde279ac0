"""``tribokin surface``: a surface profile's asperity statistics, written to a folder and printed."""

from __future__ import annotations

from tribokin.cli.options import claimed, options_located

#: The command-line option of each argument of :func:`~tribokin.tribology.surface_result.analyse_surface`.
OPTIONS = {"area_m2": "--area-m2", "z_range_m": "--z-range-m", "radius_range_m": "--radius-range-m"}


def add_parser(commands) -> None:
    """The ``surface`` command's arguments."""
    parser = commands.add_parser("surface", help="asperity statistics of a surface profile (CSV)")
    parser.add_argument("profile", help="CSV with columns x_m, z_m")
    parser.add_argument("--out", default="surface", help="output folder (must not exist, unless --force)")
    parser.add_argument("--area-m2", type=float, default=1e-6, help="apparent area A_a of eq. (6) [m²]")
    parser.add_argument("--z-range-m", type=float, nargs=2, default=(-float("inf"), float("inf")),
                         metavar=("Z1", "Z2"), help="summit altitude range of eq. (6) [m]")
    parser.add_argument("--radius-range-m", type=float, nargs=2, default=(0.0, float("inf")),
                         metavar=("R1", "R2"), help="radius range of eq. (6) [m]")
    parser.add_argument("--force", action="store_true", help="replace an existing output folder")
    parser.set_defaults(handler=surface)



def surface(args) -> None:
    """Analyse the profile, write the folder, print its statistics and eq. (6)'s count."""
    from tribokin.output.tribology import write_surface
    from tribokin.tribology.surface_result import analyse_surface

    with claimed(args.out, args.force):
        with options_located(OPTIONS):
            result = analyse_surface(args.profile, args.area_m2, args.z_range_m, args.radius_range_m)
        write_surface(result, args.out, args.force)
    statistics = result.statistics
    print(f"{statistics.peaks} peaks, AR = {statistics.AR_m * 1e6:.2f} µm, D_s = 1.2/AR² = "
          f"{statistics.summit_density_m2 * 1e-6:.1f} per mm²")
    print(f"Alt = {statistics.Alt_m * 1e6:.3f} µm, SAlt = {statistics.SAlt_m * 1e6:.3f} µm, "
          f"radius lognormal a = {statistics.radius_a:.3f}, b = {statistics.radius_b:.3f} (R* = R / 1 µm)")
    print(f"asperities (eq. 6) on {args.area_m2:g} m²: {result.count:.1f}")
    print(f"results in {args.out}/ (surface.json, profile.png, p_z_R.png)")
