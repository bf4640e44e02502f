"""Sequential against one-shot comparison: budgets, errors against the truth and the
measurements, the rows read from study directories, the table and the figure."""

import json
import math
import os

import pandas as pd
import pytest

from demcal.core.config import load_config
from demcal.core.experiments import load_experiment
from demcal.sequential.comparison import (
    comparison_figure,
    comparison_markdown,
    comparison_row,
    oneshot_row,
    oneshot_sets,
    parameter_errors,
    reuse_cases,
    sequential_rows,
    truth_row,
    verification_deviations,
)
from tests.figures import colour_mask, read_png

RANGES = {"coefficientFriction": [0.1, 1.0], "density": [2500.0, 3500.0]}
TRUTH = {"coefficientFriction": 0.55, "density": 3000.0}


@pytest.fixture
def config(tmp_path):
    path = tmp_path / "c.yaml"
    path.write_text(
        "profile: quick\n"
        "design: {kind: sobol, n: 8, seed: 1, ranges: {coefficientFriction: [0.1, 1.0],"
        " density: [2500.0, 3500.0]}}\n"
        "shear_cell: {normal_stresses: [1068.0, 2029.0, 10070.0], P: [0.5, 1.0],"
        " separate_runs: false}\n"
        "verification: {seeds: 3}\n"
        "screening: {tolerance: 0.05}\n"
    )
    return load_config(path)


def _identified(friction, density):
    return {
        "group": "SSC+AoR",
        "parameters": {
            "coefficientFriction": {"mean": friction, "min": 0.4, "max": 0.7},
            "density": {"mean": density, "min": 2800.0, "max": 3200.0},
        },
    }


def test_oneshot_sets_fit_the_budget_after_the_verification(config):
    # 3 shear decks and a heap per set, 3 seeds x 4 runs of verification
    assert oneshot_sets(config, 100) == 22
    assert oneshot_sets(config, 60) == 12
    assert oneshot_sets(config, 27) == 3
    with pytest.raises(ValueError, match="budget of 23 DEM runs leaves 2 parameter sets"):
        oneshot_sets(config, 23)


def test_parameter_errors_are_fractions_of_the_design_range():
    errors = parameter_errors(_identified(0.64, 2900.0), TRUTH, RANGES)
    assert errors["coefficientFriction"] == pytest.approx(0.09 / 0.9)
    assert errors["density"] == pytest.approx(0.1)
    nothing = parameter_errors({"parameters": {}}, TRUTH, RANGES)
    assert all(math.isnan(v) for v in nothing.values())


def test_rows_name_the_worst_value_and_judge_the_tolerance():
    table = pd.DataFrame(
        {
            "observable": ["mu_psh", "rho_b", "aor"],
            "normal_stress": [2029.0, 2029.0, float("nan")],
            "P": [1.0, 1.0, float("nan")],
            "deviation_configured": [0.031, 0.012, 0.062],
        }
    )
    deviations = verification_deviations(table)
    assert deviations == {"mu_psh@2029Pa,P=1": 0.031, "rho_b@2029Pa,P=1": 0.012, "aor": 0.062}
    row = comparison_row(
        "m", "one-shot", 100, _identified(0.55, 3300.0), deviations, TRUTH, RANGES, 0.05
    )
    assert row["worst_bulk_value"] == "aor" and row["worst_bulk_deviation"] == 0.062
    assert row["max_parameter_error"] == pytest.approx(0.3)
    assert row["median_bulk_deviation"] == 0.031
    assert row["share_within"] == pytest.approx(2 / 3)
    assert not row["within"]
    deviations["aor"] = 0.049
    assert comparison_row(
        "m", "one-shot", 100, _identified(0.55, 3000.0), deviations, TRUTH, RANGES, 0.05
    )["within"]
    empty = comparison_row("m", "one-shot", 88, {"parameters": {}}, {}, TRUTH, RANGES, 0.05)
    assert not empty["within"] and math.isnan(empty["max_parameter_error"])


def _write_round(root, r, runs_total, deviation, friction):
    folder = root / "results" / "sequential" / f"round_{r}"
    (folder / "identification").mkdir(parents=True)
    state = {
        "runs_total": runs_total,
        "verification": {
            "mu_psh@2029Pa,P=1": {"dem": 0.6, "measured": 0.6, "deviation": deviation}
        },
    }
    (folder / "state.json").write_text(json.dumps(state))
    (folder / "identification" / "identified_parameters.json").write_text(
        json.dumps(_identified(friction, 3000.0))
    )


def test_study_directories_give_one_row_per_round_and_per_budget(tmp_path, config):
    seq = tmp_path / "sequential"
    _write_round(seq, 0, 44, 0.09, 0.73)
    _write_round(seq, 1, 72, 0.03, 0.58)
    rows = sequential_rows(seq, "m", TRUTH, RANGES, 0.05)
    assert [(r["label"], r["runs"], r["within"]) for r in rows] == [
        ("round 0", 44, False),
        ("round 1", 72, True),
    ]
    assert rows[1]["error_coefficientFriction"] == pytest.approx(0.03 / 0.9)
    one = tmp_path / "oneshot"
    (one / "results" / "identification").mkdir(parents=True)
    (one / "results" / "verification").mkdir(parents=True)
    (one / "results" / "identification" / "identified_parameters.json").write_text(
        json.dumps(_identified(0.4, 3000.0))
    )
    pd.DataFrame(
        {"observable": ["aor"], "normal_stress": [None], "P": [None], "deviation_configured": [0.2]}
    ).to_csv(one / "results" / "verification" / "verification.csv", index=False)
    row = oneshot_row(one, "m", config, TRUTH)
    # 8 sets x 4 runs and the 12 verification runs
    assert (row["runs"], row["label"], row["worst_bulk_deviation"]) == (44, "8 sets", 0.2)
    (one / "results" / "identification" / "identified_parameters.json").write_text(
        json.dumps({"parameters": {}})
    )
    assert oneshot_row(one, "m", config, TRUTH)["runs"] == 32


def test_table_and_figure_report_the_fewest_runs_within_tolerance(tmp_path):
    rows = [
        {
            "material": "a",
            "design": "sequential",
            "label": "round 0",
            "runs": 44,
            "max_parameter_error": 0.2,
            "worst_bulk_deviation": 0.09,
            "within": False,
        },
        {
            "material": "a",
            "design": "sequential",
            "label": "round 1",
            "runs": 72,
            "max_parameter_error": 0.05,
            "worst_bulk_deviation": 0.03,
            "within": True,
        },
        {
            "material": "a",
            "design": "one-shot",
            "label": "22 sets",
            "runs": 100,
            "max_parameter_error": 0.1,
            "worst_bulk_deviation": 0.07,
            "within": False,
        },
    ]
    rows.append(
        {
            "material": "a",
            "design": "truth",
            "label": "3 seeds, `dem_engine -in {deck}`",
            "runs": 15,
            "max_parameter_error": 0.0,
            "worst_bulk_deviation": 0.045,
            "worst_bulk_value": "aor",
            "share_within": 1.0,
            "within": True,
        }
    )
    table = pd.DataFrame(rows)
    text = comparison_markdown(table, 0.05, "python scripts/sequential_comparison.py")
    assert "sequential: 72 DEM runs (of 72 spent)" in text
    assert "one-shot: not within tolerance (of 100 spent)" in text
    # the truth is the floor, not a design that spent runs
    assert "truth: " not in text
    assert (
        "the truth itself (3 seeds, `dem_engine -in {deck}`): worst deviation 0.045 (aor)" in text
    )
    (line,) = [x for x in text.splitlines() if "round 0" in x]
    assert "0.090" in line and "0.200" in line
    comparison_figure(table, 0.05, tmp_path / "c.png")
    image = read_png(tmp_path / "c.png")
    assert image.shape == (768, 504, 3)  # 4.2 x 6.4 in at 120 dpi, one material
    # both designs drawn: the sequential line in C0, the one-shot line in C3
    assert colour_mask(image, "#1f77b4").sum() > 100
    assert colour_mask(image, "#d62728").sum() > 100
    # the truth's floor as a line of its own (C2)
    assert colour_mask(image, "#2ca02c").sum() > 50


def _truth_bulk():
    """Two replicates of the truth: a heap and one shear-cell deck at 1068 Pa each."""
    return pd.DataFrame(
        {
            "case_id": ["truth0", "truth0_s1", "truth1", "truth1_s1"],
            "test": ["angle_of_repose", "shear_cell"] * 2,
            "normal_stress": [math.nan, 1068.0] * 2,
            "P": [math.nan, 1.0] * 2,
            "aor": [29.6, math.nan, 30.4, math.nan],
            "mu_psh": [math.nan, 1.0, math.nan, 1.04],
            "mu_sh": [math.nan, 0.8, math.nan, 0.8],
            "rho_b": [math.nan, 1570.0, math.nan, 1584.0],
        }
    )


def _experiment(tmp_path, conditions):
    path = tmp_path / "measured.yaml"
    record = {
        "material": "m",
        "source": "test",
        "angle_of_repose": {"value": 32.0, "sd": 0.6},
        "shear_cell": conditions,
    }
    path.write_text(json.dumps(record))
    return load_experiment(path)


def test_truth_row_judges_the_truth_runs_like_a_verification(tmp_path):
    experiment = _experiment(
        tmp_path,
        [{"normal_stress": 1068.0, "P": 1.0, "mu_psh": 0.99, "mu_psh_sd": 0.05, "rho_b": 1577.0}],
    )
    row = truth_row("a", _truth_bulk(), experiment, TRUTH, RANGES, 0.05, "x")
    assert row["design"] == "truth" and row["label"] == "x"
    # 4 engine executions (2 heaps, 2 shear decks), not bulk-value rows
    assert row["runs"] == 4
    assert row["max_parameter_error"] == 0.0
    # means over the replicates: AoR 30.0 vs 32, mu_psh 1.02 vs 0.99, rho_b 1577 vs 1577;
    # mu_sh was run but not measured, so it is not judged
    assert row["worst_bulk_value"] == "aor"
    assert row["worst_bulk_deviation"] == pytest.approx(0.0625)
    assert row["median_bulk_deviation"] == pytest.approx(0.03 / 0.99)
    assert row["share_within"] == pytest.approx(2 / 3)
    assert not row["within"]


def test_truth_row_counts_a_measured_value_without_runs_as_missed(tmp_path):
    experiment = _experiment(
        tmp_path,
        [
            {"normal_stress": 1068.0, "P": 1.0, "rho_b": 1577.0},
            {"normal_stress": 2029.0, "P": 1.0, "mu_psh": 0.93},
        ],
    )
    row = truth_row("a", _truth_bulk(), experiment, TRUTH, RANGES, 0.5, "x")
    # AoR and rho_b within 50 %, mu_psh at 2029 Pa never run: not within, as in a verification
    assert row["share_within"] == pytest.approx(2 / 3)
    assert not row["within"]


def test_reused_cases_are_those_of_the_target_design_and_newer_than_it(tmp_path):
    source, target = tmp_path / "a", tmp_path / "b"
    for case in ("shear_cell/c0001_s1", "shear_cell/c0012_s1", "angle_of_repose/c0001"):
        d = source / "results" / "cases" / case
        d.mkdir(parents=True)
        for name in ("in.deck", "status.json", "bulk.csv"):
            (d / name).write_text(case)
    design = target / "results" / "design" / "cases.csv"
    design.parent.mkdir(parents=True)
    design.write_text("case_id,density\nc0001,3000\nc0002,3100\n")
    os.utime(design, (1.0e9, 1.0e9))
    reuse_cases(source, target)
    cases = target / "results" / "cases"
    # c0012 is not in the target's design; c0002 was never run
    assert sorted(p.relative_to(cases).as_posix() for p in cases.glob("*/*")) == [
        "angle_of_repose/c0001",
        "shear_cell/c0001_s1",
    ]
    case = cases / "shear_cell" / "c0001_s1"
    assert (case / "bulk.csv").read_text() == "shear_cell/c0001_s1"
    # stamped in the order of the rules, all after the design table
    times = [(case / n).stat().st_mtime for n in ("in.deck", "status.json", "bulk.csv")]
    assert design.stat().st_mtime < times[0] < times[1] < times[2]
