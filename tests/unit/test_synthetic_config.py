"""The truth runs of a synthetic experiment: another engine and other normal stresses than the
profile's, without touching the profile."""

from pathlib import Path

import pytest

from demcal.bulk.synthetic import truth_run_config
from demcal.core.config import load_config
from demcal.design.cases import load_condition, shear_suffixes

ROOT = Path(__file__).resolve().parents[2]


def test_normal_stresses_replace_the_profiles_for_the_truth_runs_only():
    config = load_config(ROOT / "config" / "config.yaml")
    assert config["shear_cell"]["normal_stresses"] == [1068.0, 2029.0, 10070.0]
    truth = truth_run_config(config, "liggghts -in {deck}", [2029])
    # One four-cycle deck instead of three, at the stress asked for.
    assert shear_suffixes(truth) == ["_s1"]
    assert load_condition(truth, "reference_s1") == {"normal_stress": 2029.0}
    assert truth["engine"]["command"] == "liggghts -in {deck}"
    # The rest of the cell and the profile itself are unchanged.
    assert truth["shear_cell"]["P"] == config["shear_cell"]["P"]
    assert config["shear_cell"]["normal_stresses"] == [1068.0, 2029.0, 10070.0]
    assert config["engine"]["command"] != "liggghts -in {deck}"


def test_without_options_the_truth_runs_use_the_profile():
    config = load_config(ROOT / "config" / "tiny.yaml")
    truth = truth_run_config(config)
    assert truth["engine"] == config["engine"]
    assert truth["shear_cell"] == config["shear_cell"]


@pytest.mark.parametrize("stresses", [[], [0.0], [-2029.0], [float("nan")], [2029.0, float("inf")]])
def test_unphysical_normal_stresses_are_refused_before_any_run(stresses):
    config = load_config(ROOT / "config" / "tiny.yaml")
    with pytest.raises(ValueError, match="--normal-stresses"):
        truth_run_config(config, None, stresses)
