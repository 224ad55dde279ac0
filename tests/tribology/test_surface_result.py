"""analyse_surface(): a profile's asperity statistics and eq. (6)'s count as a frozen result that writes the
command's folder byte for byte; its options' errors name the argument, which the command names as its option."""

from __future__ import annotations

import math

import pytest

from conftest import ROOT
from helpers.folders import assert_frozen, assert_same_files
from tribokin import SurfaceResult, analyse_surface
from tribokin.cli import main
from tribokin.errors import SettingsError

PROFILE = ROOT / "src/tribokin/data/profiles/intermediate.csv"


def test_the_result_is_frozen_and_writes_the_command_s_folder(tmp_path):
    assert main(["surface", PROFILE, "--out", tmp_path / "command", "--z-range-m", "0", "1e-5"]) == 0
    result = analyse_surface(PROFILE, z_range_m=(0.0, 1e-5))
    assert isinstance(result, SurfaceResult)
    assert_frozen(result)
    assert result.z_range_m == (0.0, 1e-5) and 0 < result.count < result.statistics.summit_density_m2 * 1e-6
    assert result.summary()["asperity_count"]["radius_range_m"] == [0.0, None]  # JSON has no infinity
    result.write(tmp_path / "library")
    assert_same_files(tmp_path / "library", tmp_path / "command")


@pytest.mark.parametrize(("options", "argument", "command_line"), [
    ({"area_m2": 0.0}, "area_m2", ["--area-m2", "0"]),
    ({"z_range_m": (math.nan, 1.0)}, "z_range_m[0]", ["--z-range-m", "nan", "1"]),
    ({"radius_range_m": (-1e-6, 1e-6)}, "radius_range_m", ["--radius-range-m", "-0.000001", "0.000001"])])
def test_a_bad_option_names_the_argument_and_the_command_its_option(options, argument, command_line, tmp_path,
                                                                     capsys):
    with pytest.raises(SettingsError) as error:
        analyse_surface(PROFILE, **options)
    assert error.value.argument == argument
    assert main(["surface", PROFILE, "--out", tmp_path / "s", *command_line]) == 2
    option = "--" + argument.replace("_", "-")
    assert capsys.readouterr().err == f"tribokin: error: command line: {option}: {error.value.message}\n"
    assert not (tmp_path / "s").exists()
