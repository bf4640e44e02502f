"""The statistics of the engine comparison (no engine runs): Welch's t-test, the Bonferroni
level, the flagging of a real difference, and the Markdown table."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from demcal.bulk.engine_comparison import (
    parameter_sets,
)
from demcal.bulk.engine_statistics import (
    compare_engines,
    compare_groups,
    markdown_table,
    spread_test,
    welch_test,
)


def test_welch_p_value_matches_scipy() -> None:
    a, b = [0.50, 0.55, 0.52, 0.58], [0.60, 0.66, 0.59, 0.70]
    expected = stats.ttest_ind(a, b, equal_var=False).pvalue
    assert welch_test(a, b) == pytest.approx(expected)


def test_welch_edge_cases() -> None:
    assert math.isnan(welch_test([1.0], [1.0, 2.0]))
    assert welch_test([1.0, 1.0], [1.0, 1.0]) == 1.0
    assert welch_test([1.0, 1.0], [2.0, 2.0]) == 0.0
    assert welch_test([1.0, 2.0, math.nan], [1.5, 1.6]) == pytest.approx(
        stats.ttest_ind([1.0, 2.0], [1.5, 1.6], equal_var=False).pvalue
    )


def test_bonferroni_level_and_flagging() -> None:
    rng = np.random.default_rng(0)
    same = rng.normal(0.6, 0.05, 6), rng.normal(0.6, 0.05, 6)
    shifted = rng.normal(0.4, 0.05, 6), rng.normal(0.9, 0.05, 6)
    pairs = {("s1", "mu_psh"): same, ("s2", "mu_psh"): shifted, ("s3", "aor"): same}
    comparison = compare_groups(pairs, alpha=0.03)
    assert comparison.per_test_alpha == pytest.approx(0.01)
    assert not comparison.all_passed
    assert comparison.flagged["set"].tolist() == ["s2"]
    row = comparison.table.set_index("set").loc["s2"]
    assert row["difference"] == pytest.approx(np.mean(shifted[1]) - np.mean(shifted[0]))


def test_spread_test_is_brown_forsythe_and_stays_out_of_pass_or_fail() -> None:
    a, b = [36.3, 38.1, 34.6, 37.9, 35.2], [37.0, 36.2, 36.9, 37.4, 36.6]
    expected = stats.levene(a, b, center="median").pvalue
    assert spread_test(a, b) == pytest.approx(expected)
    assert spread_test([1.0, 1.0], [2.0, 2.0]) == 1.0
    assert math.isnan(spread_test([1.0], [1.0, 2.0]))
    # Thirty heaps a side, the same mean, one side scattering three times as much: the means
    # pass, the spread test sees it; with equal scatter it does not.
    rng = np.random.default_rng(4)
    narrow, wide, alike = (rng.normal(37.0, sd, 30) for sd in (0.6, 1.8, 0.6))
    comparison = compare_groups(
        {("wide", "aor"): (narrow, wide), ("alike", "aor"): (narrow, alike)}
    )
    rows = comparison.table.set_index("set")
    assert comparison.all_passed
    assert rows.loc["wide", "p_spread"] < 0.01 < 0.05 < rows.loc["alike", "p_spread"]
    text = markdown_table(comparison)
    assert "| result | p spread |" in text
    assert f"| pass | {rows.loc['wide', 'p_spread']:.2g} |" in text


def test_too_few_samples_fail() -> None:
    comparison = compare_groups({("s", "aor"): ([30.0], [30.0, 31.0])})
    assert not comparison.all_passed


def test_compare_engines_on_a_long_table() -> None:
    rows = []
    for engine, shift in (("liggghts", 0.0), ("engine", 0.01)):
        for seed, noise in enumerate((-0.02, 0.0, 0.02)):
            for quantity, value in (("mu_psh", 0.6), ("rho_b", 1400.0), ("aor", 20.0)):
                rows.append(
                    {
                        "set": "low",
                        "engine": engine,
                        "seed": seed,
                        "quantity": quantity,
                        "value": value * (1 + shift + noise),
                    }
                )
    comparison = compare_engines(pd.DataFrame(rows), alpha=0.01)
    assert comparison.table["quantity"].tolist() == ["mu_psh", "rho_b", "aor"]
    assert comparison.all_passed
    text = markdown_table(comparison)
    assert "Bonferroni over 3 comparisons" in text
    assert text.count("| pass |") == 3


def test_parameter_sets_have_cohesion() -> None:
    sets = parameter_sets("tiny")
    assert sets["cohesion"]["cohesionEnergyDensity"] > 0.0
    assert sets["low"]["coefficientFriction"] == 0.3
    assert sets["high"]["coefficientFriction"] == 0.9
    assert parameter_sets("quick")["cohesion"]["cohesionEnergyDensity"] == 100000.0
