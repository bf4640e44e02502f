"""The bundled engine and LIGGGHTS 3.8 give the same bulk values, in the mean over seeds.

The tiny shear cell (2029 Pa, P = 0.8) and angle of repose are rendered for three parameter
sets of :func:`demcal.bulk.engine_comparison.parameter_sets` (``low``: mu_s 0.3, ``high``:
mu_s 0.9, ``cohesion``: mu_s 0.5 with cohesionEnergyDensity 20 kJ/m^3) and :data:`SEEDS`
insertion seeds, at 20 % of the Rayleigh time
(:data:`tests.engine.conftest.TEST_RAYLEIGH_FRACTION`), and every deck runs on both engines
(one thread / one rank, two runs at a time).

Statistical test: Welch's two-sample t-test of the engines' seed samples per set and bulk value
(mu_psh, mu_sh, rho_b, aor: 12 comparisons), Bonferroni-corrected so that the family-wise
false-alarm rate is :data:`ALPHA` (each test at ALPHA / 12). The engines agree when no comparison
is significant. That the test can fail is shown on the same runs: sliding friction 0.3 against
0.9 on one engine, and LIGGGHTS at mu_s 0.3 against the engine at mu_s 0.9, must be flagged
(the bulk density, about 100 kg/m^3 apart with a seed scatter of about 10 kg/m^3, is).

At 50 kJ/m^3 the tiny cohesive heaps stood as columns (aor about 100 deg) on both engines;
20 kJ/m^3 gives heaps of 38-59 deg.

Three seeds are too few: LIGGGHTS' rho_b of mu_s 0.3 against 0.9 (93 kg/m^3 apart, sd 5 and 16)
then gave p = 0.006, not below the 0.0025 of the test. About 3-4 minutes on two otherwise
idle cores (48 runs at 20 % of the Rayleigh time); more when the cores are shared. The quick
profile: `scripts/compare_engines.py`, docs/benchmarks.md.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd
import pytest

from demcal.bulk.engine_comparison import (
    BULK_VALUES,
    collect_values,
    parameter_sets,
    plan_runs,
    run_jobs,
)
from demcal.bulk.engine_statistics import (
    compare_engines,
    compare_groups,
    markdown_table,
)
from demcal.core.config import load_config
from tests.engine.conftest import TEST_RAYLEIGH_FRACTION

pytestmark = pytest.mark.liggghts

ROOT = Path(__file__).resolve().parents[2]
SETS = ("low", "high", "cohesion")
SEEDS = (1, 2, 3, 4)
ALPHA = 0.01
STRESS = 2029.0  # the tiny profile's pre-shear stress, Pa
P = 0.8


@pytest.fixture(scope="module")
def values(tmp_path_factory: pytest.TempPathFactory) -> pd.DataFrame:
    """Bulk values of every set, test, seed and engine (one row per run and bulk value)."""
    settings = load_config(ROOT / "config" / "tiny.yaml")
    settings["material"]["rayleigh_fraction"] = TEST_RAYLEIGH_FRACTION
    available = parameter_sets("tiny")
    jobs = plan_runs(
        settings,
        {name: available[name] for name in SETS},
        SEEDS,
        tmp_path_factory.mktemp("parity"),
        normal_stress=STRESS,
        P=P,
    )
    run_jobs(jobs, parallel=2, threads=1)
    return collect_values(jobs)


def test_every_run_gives_bulk_values(values: pd.DataFrame) -> None:
    bad = values[values["status"] != "ok"].drop_duplicates(["set", "engine", "seed", "test"])
    assert bad.empty, bad[["set", "engine", "seed", "test", "status"]].to_string()
    assert values["value"].notna().all()
    assert len(values) == len(SETS) * len(SEEDS) * 2 * 4


def test_engine_means_agree_with_liggghts(values: pd.DataFrame) -> None:
    comparison = compare_engines(values, reference="liggghts", other="engine", alpha=ALPHA)
    assert len(comparison.table) == len(SETS) * 4
    assert comparison.per_test_alpha == pytest.approx(ALPHA / 12)
    assert comparison.all_passed, "engine and LIGGGHTS differ:\n" + markdown_table(comparison)


@pytest.mark.parametrize("engine", ["liggghts", "engine"])
def test_a_real_difference_is_flagged(values: pd.DataFrame, engine: str) -> None:
    # mu_s 0.3 against 0.9 (everything else equal) on one engine, by the same test (Bonferroni
    # over the four bulk values): the looser packing of the rougher spheres (rho_b about
    # 100 kg/m^3 lower, seed scatter about 10 kg/m^3) must be called significant.
    sel = values[values["engine"] == engine]
    pairs = {
        ("low vs high", q): (
            sel.loc[(sel["set"] == "low") & (sel["quantity"] == q), "value"].to_numpy(),
            sel.loc[(sel["set"] == "high") & (sel["quantity"] == q), "value"].to_numpy(),
        )
        for q in BULK_VALUES
    }
    comparison = compare_groups(pairs, alpha=ALPHA, labels=("mu_s 0.3", "mu_s 0.9"))
    assert not comparison.all_passed, markdown_table(comparison)
    flagged = comparison.flagged.set_index("quantity")
    assert "rho_b" in flagged.index, markdown_table(comparison)
    assert flagged.loc["rho_b", "difference"] < 0.0
    table = comparison.table.set_index("quantity")
    assert table.loc["mu_psh", "difference"] > 0.0


def test_engine_comparison_fails_for_mismatched_parameters(values: pd.DataFrame) -> None:
    # The engine comparison itself, fed LIGGGHTS at mu_s 0.3 and the engine at mu_s 0.9 as if
    # they were the same set, must not pass: an engine with a friction error that large would
    # be caught.
    mismatched = pd.concat(
        [
            values[(values["engine"] == "liggghts") & (values["set"] == "low")],
            values[(values["engine"] == "engine") & (values["set"] == "high")].assign(set="low"),
        ]
    )
    comparison = compare_engines(mismatched, alpha=ALPHA)
    assert not comparison.all_passed, markdown_table(comparison)
    assert "rho_b" in set(comparison.flagged["quantity"]), markdown_table(comparison)
