"""fit_friction(): the laws fitted to a tribometer log as a frozen result that writes the command's folder byte for
byte; its table is fit.json's fits."""

from __future__ import annotations

import json

import pytest

from conftest import ROOT
from helpers.folders import assert_frozen, assert_same_files
from tribokin import FrictionFitResult, fit_friction
from tribokin.cli import main
from tribokin.tribology.tribometer import read_log

LOG = ROOT / "studies/data/tribometer-42CD4-treated-150N.csv"


@pytest.fixture(scope="module")
def fitted(tmp_path_factory):
    folder = tmp_path_factory.mktemp("fit")
    assert main(["fit-friction", LOG, "--out", folder / "command", "--running-in", "300"]) == 0
    return fit_friction(LOG, running_in=300), folder


def test_the_result_is_frozen_and_writes_the_command_s_folder(fitted):
    result, folder = fitted
    assert isinstance(result, FrictionFitResult)
    assert_frozen(result)
    assert result.write(folder / "library") == folder / "library"
    assert_same_files(folder / "library", folder / "command")


def test_the_result_holds_the_steady_state_and_the_fits_ranked_by_aic(fitted):
    result, _ = fitted
    assert result.running_in_cycles == 300 and result.running_in == "given"
    assert result.steady.size == result.mu.size - 300 and result.steady[0] == result.mu[300]
    aics = [fit.aic for fit in result.fits]
    assert aics == sorted(aics) and result.chosen is result.fits[0]
    assert result.inline.startswith(f'{{ law = "{result.chosen.law}", ')
    assert fit_friction(read_log(LOG), running_in=300).summary() == result.summary()  # a log read, or its file


def test_to_pandas_holds_fit_json_s_fits(fitted):
    pytest.importorskip("pandas")
    result, folder = fitted
    fits = json.loads((folder / "command" / "fit.json").read_text())["fits"]
    frame = result.to_pandas()
    assert list(frame["law"]) == [fit["law"] for fit in fits]
    for column in ("log_likelihood", "aic", "ks_pvalue"):
        assert frame[column].tolist() == [fit[column] for fit in fits]
