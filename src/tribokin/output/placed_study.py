"""``best.toml``: the user's study file with the robot's base at the placement search's best candidate.

The study's own text is kept (its comments and layout, through ``tomlkit``: :mod:`tribokin.study.calibrated_study`),
its relative paths rewritten to name the same files from the output folder, ``robot.base_xyz_m`` and
``robot.base_rpy_deg`` set, and ``[placement]`` removed: ``tribokin run best.toml`` maps the task region (the
``[map]``) with the robot placed there.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import tomlkit

from tribokin.errors import InputError
from tribokin.output.provenance import __version__
from tribokin.placement.result import PlacementResult
from tribokin.study.calibrated_study import moved_study_document, with_header

#: The file name of the placed study.
BEST_STUDY = "best.toml"


def placed_study_text(study_text: str, source_dir: Path, out: Path, header: list[str],
                      base_xyz_m: tuple[float, float, float], base_rpy_deg: tuple[float, float, float]) -> str:
    """The placed study (module docstring).

    Args:
        study_text: the study file's text.
        source_dir: the folder its relative paths resolve against.
        out: the folder ``best.toml`` is written to.
        header: comment lines (without ``#``) put first.
        base_xyz_m: the base's position in the world [m].
        base_rpy_deg: its roll, pitch, yaw [deg].
    """
    document = moved_study_document(study_text, source_dir, out)
    document.pop("placement", None)
    robot = document["robot"]
    for key, value, comment in (("base_xyz_m", base_xyz_m, "the best placement's base position [m]"),
                                ("base_rpy_deg", base_rpy_deg, "its roll, pitch, yaw [deg]")):
        item = tomlkit.item(list(value))
        item.comment(comment)
        robot[key] = item
    return with_header(document, header)


def best_study_text(placement: PlacementResult, out: Path) -> str:
    """``best.toml`` of a search written to ``out``: the study file's text (the file read again, and refused if it
    changed since the search read it), or a study given as a mapping written as TOML, placed at the best candidate."""
    study, best = placement.study, placement.best
    if study.sha256 is None:
        text = tomlkit.dumps(study.mapping)
    else:
        content = Path(study.source).read_bytes()
        if hashlib.sha256(content).hexdigest() != study.sha256:
            raise InputError("the study file changed while the search ran, so best.toml cannot be written from it; "
                             "run the search again", study.source, "placement")
        text = content.decode("utf-8")
    row = placement.describe(best)
    figures = ", ".join(f"{name} {value:.4g}" for name, value in row["RP_l_um"].items() if value is not None)
    header = [f"{BEST_STUDY}: {study.source} with the robot's base at the best of {len(placement.candidates)} "
              f"placements searched (tribokin {__version__})",
              f"candidate {best.index}: base at ({', '.join(f'{v:g}' for v in best.base_xyz_m)}) m, yaw "
              f"{best.yaw_deg:g}° added; reaches {row['reachable_targets']} of {placement.target_count} targets; "
              f"expected RP_l over them [µm]: {figures or 'none'} (ranked by {placement.spec.objective})",
              f"[placement] removed: `tribokin run {BEST_STUDY} --out DIR` maps the task region ([map]) from this base"]
    return placed_study_text(text, study.base_dir, out, header, best.base_xyz_m, placement.rpy_deg(best))
