"""The folders of ``tribokin fit-friction`` (``law.toml``, ``fit.json``, ``mu_cycles.png``, ``mu_histogram.png``)
and ``tribokin surface`` (``surface.json``, ``profile.png``, ``p_z_R.png``), each written all at once."""

from __future__ import annotations

from pathlib import Path

from tribokin.output.dispatch import folder_writer
from tribokin.output.folder import atomic_folder
from tribokin.output.json_files import write_json
from tribokin.tribology.friction_fit import FrictionFitResult
from tribokin.tribology.surface_result import SurfaceResult
from tribokin.tribology.surfaces import find_peaks


@folder_writer.register(FrictionFitResult)
def write_friction_fit(result: FrictionFitResult, out, force: bool = False) -> Path:
    """``law.toml``, ``fit.json`` and the figures of the log's mu per cycle and of its steady state's histogram with
    the fitted laws, written to ``out`` all at once."""
    from tribokin.viz.tribology import save_mu_histogram, save_mu_per_cycle

    with atomic_folder(out, force) as folder:
        (folder / "law.toml").write_text(result.law_toml(), encoding="utf-8")
        write_json(result.summary(), folder / "fit.json")
        save_mu_per_cycle(result.cycle, result.mu, result.running_in_cycles, folder / "mu_cycles.png", result.name)
        save_mu_histogram(result.steady, list(result.fits), folder / "mu_histogram.png",
                          f"{result.name}: steady state")
    return Path(out)


@folder_writer.register(SurfaceResult)
def write_surface(result: SurfaceResult, out, force: bool = False) -> Path:
    """``surface.json`` and the figures of the levelled profile with its peaks and of p(z, R), written to ``out``
    all at once."""
    from tribokin.viz.tribology import save_asperity_density, save_profile

    with atomic_folder(out, force) as folder:
        write_json(result.summary(), folder / "surface.json")
        save_profile(result.x_m, result.levelled_m, find_peaks(result.levelled_m), folder / "profile.png", result.name)
        save_asperity_density(result.statistics, folder / "p_z_R.png", f"{result.name}: p(z, R)")
    return Path(out)
