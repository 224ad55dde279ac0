"""Names a study gives: the rules for study, pose and scenario names, and the files each pose and scenario
writes (the writers take these file names from here, so the checks see exactly what will be written).

Pose and scenario names become parts of file names (``field_<pose>.png``, ``map_RP_l_ratio_<scenario>.png``)
and pose names folders in ``samples.npz`` (``<pose>/positions_m``); a study name names the map's layer
in the 3-D scene (a path whose parts ``/`` separates) and the figures' titles.
"""

from __future__ import annotations

from collections.abc import Callable

from tribokin.errors import InputError

#: Longest name [characters]: most file systems hold at most 255 bytes per file name, prefix included
#: (``map_RP_l_ratio_``, ``.png``); 100 characters leave room for both even at two bytes a character
#: (wider characters are caught by ``MAX_FILE_NAME_BYTES``).
MAX_NAME_CHARACTERS = 100
#: Longest file name [bytes of UTF-8] on Linux (ext4, tmpfs...) and macOS (APFS).
MAX_FILE_NAME_BYTES = 255
#: Figures of each scenario other than the reference: ``map_<kind>_<scenario>.png``.
SCENARIO_FIGURES = ("RP_l", "RP_l_ratio", "RP_l_diff")
#: The figures of every scenario of a map comparing two states (``map.compare``): its RP_l's and AP_p's change,
#: ``map_<kind>.png`` for the reference, ``map_<kind>_<scenario>.png`` for the others (as :data:`SCENARIO_FIGURES`).
CHANGE_MAP_KINDS = ("RP_l_change", "AP_p_change")
#: The reference's change heat maps.
CHANGE_MAP_FILES = tuple(f"map_{kind}.png" for kind in CHANGE_MAP_KINDS)
#: The heat maps of an expected map's own figures, by the figure set that draws them (``MapSpec.figure_set``): its
#: RP_l band's high end; with the directional figures, vAP_p and RP_l_multi too.
EXPECTED_MAP_FILES = {"expected": ("map_RP_l_hi.png",),
                      "directional": ("map_RP_l_hi.png", "map_vAP_p.png", "map_RP_l_multi.png")}


def pose_figure_file(pose: str) -> str:
    """``field_<pose>.png``: the repeatability field of a pose."""
    return f"field_{pose}.png"


def drift_figure_file(pose: str) -> str:
    """``drift_<pose>.png``: a pose's simulated drift test against time (a study with ``[drift]``)."""
    return f"drift_{pose}.png"


def cloud_figure_file(pose: str) -> str:
    """``clouds_<pose>.png``: a calibrated pose's measured clouds beside the model's."""
    return f"clouds_{pose}.png"


#: The formats a map's tables can be written in (``tribokin run --table-format``), their files' extensions; the
#: default first.
TABLE_FORMATS = ("csv", "parquet")


def map_table_file(scenario: str | None, extension: str = "csv") -> str:
    """``map.csv`` for the reference scenario (``None``), ``map_<scenario>.csv`` for the others (or ``.parquet``...:
    ``extension``)."""
    return f"map.{extension}" if scenario is None else f"map_{scenario}.{extension}"


def map_figure_file(kind: str, scenario: str) -> str:
    """``map_<kind>_<scenario>.png``: a figure of a scenario other than the reference (``SCENARIO_FIGURES``,
    ``CHANGE_MAP_KINDS``)."""
    return f"map_{kind}_{scenario}.png"


def scenario_files(scenario: str, change: bool = False) -> list[str]:
    """The files a scenario other than the reference writes (the reference's names hold no scenario name); ``change``:
    in a map comparing two states, its change heat maps too (``CHANGE_MAP_KINDS``)."""
    kinds = SCENARIO_FIGURES + (CHANGE_MAP_KINDS if change else ())
    return [map_table_file(scenario)] + [map_figure_file(kind, scenario) for kind in kinds]


def _shown(name: str) -> str:
    return repr(name if len(name) <= 40 else name[:40] + "…")


def check_name(name: str, source, key: str) -> None:
    """Refuse a name with ``/``, characters that are not printable (NUL, tab, line break...), or more than
    ``MAX_NAME_CHARACTERS`` characters."""
    if "/" in name:
        problem = "contains '/', which separates folders and the parts of the 3-D scene"
    elif not name.isprintable():
        problem = "contains a character that is not printable (such as NUL, a tab or a line break)"
    elif len(name) > MAX_NAME_CHARACTERS:
        problem = (f"has {len(name)} characters; a name may have at most {MAX_NAME_CHARACTERS} (names become parts "
                   f"of file names, which hold at most {MAX_FILE_NAME_BYTES} bytes)")
    else:
        return
    raise InputError(f"{_shown(name)} {problem}; choose another name", source, key)


def check_file_name_part(name: str, source, key: str) -> None:
    """:func:`check_name`, and refuse a leading ``.`` (a hidden name; ``.`` and ``..`` are folders, and pose
    names name folders in ``samples.npz``)."""
    check_name(name, source, key)
    if name.startswith("."):
        raise InputError(f"{_shown(name)} starts with '.' (a hidden name, or the folders '.' and '..'); choose "
                         "another name", source, key)


def check_files_apart(files: list[tuple[str, str]], source) -> None:
    """Refuse file names (``(key, file name)``, the key naming what writes it) longer than
    ``MAX_FILE_NAME_BYTES`` or equal to another's, case aside (one file on macOS and Windows)."""
    seen = {}
    for key, file in files:
        if len(file.encode()) > MAX_FILE_NAME_BYTES:
            raise InputError(f"its file {_shown(file)} has {len(file.encode())} bytes, more than the "
                             f"{MAX_FILE_NAME_BYTES} a file name may hold; choose a shorter name", source, key)
        other_key, other_file = seen.setdefault(file.casefold(), (key, file))
        if other_key != key:
            case = "" if other_file == file else (f" ({other_file}; names that differ only in case are one file on "
                                                  "macOS and Windows)")
            raise InputError(f"writes {file}, as {other_key} does{case}, so one would overwrite the other; rename "
                             "one of them", source, key)


def check_measured_pose_names(names: list[str], source, file_name: Callable[[str], str]) -> None:
    """Refuse the pose names of a measurement file (its ``pose`` column) that cannot name the files ``file_name(pose)``
    a command writes for them: :func:`check_file_name_part`, and no two that are one file (:func:`check_files_apart`,
    case aside)."""
    for name in names:
        check_file_name_part(name, source, "pose")
    check_files_apart([(f"pose '{name}'", file_name(name)) for name in names], source)


def calibrated_pose_names(study_poses: list[tuple[str, str]], measured: list[str], source) -> list[str]:
    """The names ``calibrated.toml`` gives the measured poses beside the study's own (``(key, name)``: its
    ``[[poses]]``, then its ISO cube's): each its own name, or ``measured-<name>`` where the study holds that name.
    Refused in one line naming the measurement file's ``pose`` (before any fit) where that name breaks the study's
    own rules (:func:`check_file_name_part`), is the study's too, or writes a study pose's file (case aside)."""
    taken = {name for _, name in study_poses}
    written = []
    for name in measured:
        new = f"measured-{name}" if name in taken else name
        key = f"pose '{name}'"
        if new != name:
            if new in taken:
                raise InputError(f"the study holds '{name}' and '{new}' already, so calibrated.toml cannot name this "
                                 "measured pose either way; rename it in the measurement file", source, key)
            try:
                check_file_name_part(new, source, key)
            except InputError as error:
                raise InputError(f"the study holds '{name}' too, so calibrated.toml would name this measured pose "
                                 f"{error.message}", source, key) from None
        written.append((key, new))
    files = [(f"the study's {key}", pose_figure_file(name)) for key, name in study_poses]
    check_files_apart(files + [(key, pose_figure_file(new)) for key, new in written], source)
    return [new for _, new in written]
