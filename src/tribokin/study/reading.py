"""Reading a study: a TOML file, a mapping or a :class:`Study`, with the command line's overrides."""

from __future__ import annotations

import hashlib
from dataclasses import replace
from pathlib import Path

from tribokin.checks import seed_int, toml_mapping
from tribokin.confinement import regular_file
from tribokin.errors import InputError
from tribokin.study.spec import Study, cycle_count, parse_study


def read_study_file(path) -> Study:
    """Read and validate a TOML study file."""
    path = Path(path)
    content = regular_file(path, path, missing="study file not found").read_bytes()
    try:
        text = content.decode("utf-8")
    except UnicodeDecodeError as error:
        raise InputError(f"not valid TOML: not UTF-8 text ({error.reason} at byte {error.start})", path) from None
    study = parse_study_text(text, path, path.parent)
    return replace(study, sha256=hashlib.sha256(content).hexdigest())


def parse_study_text(text: str, source, base_dir: Path) -> Study:
    """Validate a study's TOML ``text`` (from ``source``, its relative paths resolving against ``base_dir``)."""
    return parse_study(toml_mapping(text, source), str(source), Path(base_dir))


def load_study(study, cycles: int | None = None, seed: int | None = None) -> Study:
    """A :class:`Study` from a path, a mapping or a Study, with ``cycles``/``seed`` overriding the file
    (a new Study: the one given is left as it is)."""
    if isinstance(study, dict):
        study = parse_study(study, "<mapping>", Path.cwd())
    elif not isinstance(study, Study):
        study = read_study_file(study)
    if cycles is not None:
        study = replace(study, cycles=cycle_count(cycles, "command line", "--cycles"))
    if seed is not None:
        study = replace(study, seed=seed_int(seed, "command line", "--seed"))
    scenarios = tuple(replace(s, study=_with_run_overrides(s.study, s.overrides.get("study", {}), study))
                      for s in study.scenarios)
    return replace(study, scenarios=scenarios)


def _with_run_overrides(scenario: Study, own: dict, base: Study) -> Study:
    """A scenario's study with the base's ``cycles`` and ``seed`` (command-line overrides included),
    unless the scenario sets its own."""
    return replace(scenario, cycles=own.get("cycles", base.cycles), seed=own.get("seed", base.seed))
