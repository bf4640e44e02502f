"""Tests of the cross-validation by parameter set (demcal.surrogates.cross_validation), its
folds (demcal.surrogates.data_split) and Table 4 (demcal.surrogates.table4, train_output)."""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from threadpoolctl import threadpool_limits

from demcal.core.experiments import Experiment, MeasuredCondition
from demcal.surrogates.baselines import bayesian_linear_regression
from demcal.surrogates.cross_validation import cross_validate, effective_folds
from demcal.surrogates.data_split import grouped_folds, holdout_groups
from demcal.surrogates.table4 import acceptance_reference, write_table4_document
from demcal.surrogates.training import train_output

# Small networks and few epochs keep every test within a few seconds on one core.
MLP = {"max_epochs": 300, "patience": 20}


@pytest.fixture(autouse=True)
def _one_blas_thread() -> Iterator[None]:
    with threadpool_limits(limits=1):
        yield


def replicated(
    n_sets: int, reps: int, seed: int, noise: float = 0.01
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Two parameters per set, ``reps`` load levels per set, a smooth response.

    Returns X (n_sets * reps, 3), y (n_sets * reps,) and the set label of every row.
    """
    rng = np.random.default_rng(seed)
    params = np.repeat(rng.uniform(0.0, 1.0, (n_sets, 2)), reps, axis=0)
    load = np.tile(np.linspace(0.4, 1.0, reps), n_sets)
    X = np.column_stack([params, load])
    y = np.sin(2.0 * X[:, 0]) + X[:, 1] ** 2 + 0.3 * X[:, 2]
    y = y + noise * rng.standard_normal(y.size)
    return X, y, np.repeat([f"c{k:04d}" for k in range(n_sets)], reps)


# ------------------------------------------------------------------------------ folds


def test_grouped_folds_keep_sets_together_and_cover_every_row_once() -> None:
    rng = np.random.default_rng(0)
    groups = np.repeat([f"c{k:04d}" for k in range(17)], rng.integers(1, 6, 17))
    folds = grouped_folds(groups, 5, seed=4)
    assert len(folds) == 5
    every = np.concatenate(folds)
    assert sorted(every.tolist()) == list(range(groups.size))  # each row exactly once
    owner = {}
    for k, fold in enumerate(folds):
        for label in set(groups[fold]):
            assert owner.setdefault(label, k) == k, f"set {label} split between folds"
    assert sorted(len(set(groups[f])) for f in folds) == [3, 3, 3, 4, 4]
    again = grouped_folds(groups, 5, seed=4)
    assert all(np.array_equal(a, b) for a, b in zip(folds, again, strict=True))
    assert not all(
        np.array_equal(a, b) for a, b in zip(folds, grouped_folds(groups, 5, 5), strict=True)
    )


@pytest.mark.parametrize(("n_folds", "message"), [(1, ">= 2"), (6, "exceeds the 5")])
def test_grouped_folds_reject_bad_counts(n_folds: int, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        grouped_folds(np.repeat(np.arange(5), 2), n_folds, seed=0)


def test_holdout_groups_holds_out_whole_sets() -> None:
    groups = np.repeat(np.arange(12), 3)
    kept, held = holdout_groups(groups, seed=(3, 1), fraction=0.2)
    assert not set(groups[kept]) & set(groups[held])
    assert len(set(groups[held])) == 2 and kept.size + held.size == groups.size
    _, one = holdout_groups(np.array([0, 0, 1]), seed=0, fraction=0.01)
    assert one.size > 0  # at least one set, and at least one left to train on
    with pytest.raises(ValueError, match="at least 2 groups"):
        holdout_groups(np.zeros(4), seed=0, fraction=0.2)


@pytest.mark.parametrize(
    ("requested", "n_sets", "expected", "note"),
    [
        (0, 16, 0, ""),
        (5, 16, 5, ""),
        (5, 4, 4, "exceeds the 4"),
        (2, 3, 3, "fewer than 2 sets"),  # a fold of 2 sets would leave 1 to train on
        (5, 2, 0, "skipped"),
    ],
)
def test_effective_folds_clamps_with_a_note(
    requested: int, n_sets: int, expected: int, note: str
) -> None:
    n_folds, text = effective_folds(requested, n_sets)
    assert n_folds == expected
    assert (note in text) if note else text == ""
    if note:
        assert "surrogate.cv_folds" in text


@pytest.mark.parametrize("requested", [1, -2])
def test_effective_folds_rejects_one_fold_naming_the_key(requested: int) -> None:
    with pytest.raises(ValueError, match=r"surrogate\.cv_folds"):
        effective_folds(requested, 10)


# ------------------------------------------------------------------ cross-validation


def test_every_row_predicted_once_by_a_model_that_never_saw_its_set() -> None:
    X, y, groups = replicated(10, 3, seed=2)
    cv = cross_validate(X, y, groups, 4, hidden_size=3, seed=1, methods=("Bayesian",), **MLP)
    assert cv.n_folds == 4 and cv.n_sets == 10
    assert np.all(np.isfinite(cv.predictions["Bayesian"]))
    for label in set(groups):
        assert np.unique(cv.fold[groups == label]).size == 1  # its rows share one fold
    folds = cv.folds.set_index("fold")
    assert folds["test_rows"].sum() == y.size
    assert folds["test_sets"].sum() == 10
    # Training, generalisation and test sets of a fold are disjoint and together all sets.
    parts = folds[["train_sets", "generalisation_sets", "test_sets"]].sum(axis=1)
    assert (parts == 10).all()
    assert (folds["generalisation_sets"] >= 1).all()
    # A baseline's predictions of a fold are those of a model fitted on every row of the other
    # folds: it needs no generalisation set, and the one that screens learns from all rows.
    test = np.flatnonzero(cv.fold == 0)
    rest = np.flatnonzero(cv.fold != 0)
    refit = bayesian_linear_regression().fit(X[rest], y[rest])
    np.testing.assert_allclose(cv.predictions["Bayesian"][test], refit.predict(X[test]))
    kept, _ = holdout_groups(groups[rest], seed=(1, 0), fraction=0.15 / 0.85)
    without_generalisation = bayesian_linear_regression().fit(X[rest[kept]], y[rest[kept]])
    assert not np.allclose(
        cv.predictions["Bayesian"][test], without_generalisation.predict(X[test])
    )
    summary = cv.summary()
    assert summary.loc["Bayesian", "cv_rows"] == y.size
    # The row-weighted mean of the fold R^2 (against all rows' variance) is the pooled R^2.
    weights = folds["test_rows"] / folds["test_rows"].sum()
    pooled = cv.pooled("Bayesian")["r2"]
    np.testing.assert_allclose((weights * folds["r2_global"]).sum(), pooled)
    assert summary.loc["Bayesian", "cv_r2_min"] <= pooled <= summary.loc["Bayesian", "cv_r2_max"]


def test_smooth_function_cross_validates_well() -> None:
    X, y, groups = replicated(30, 3, seed=0)
    cv = cross_validate(X, y, groups, 5, hidden_size=5, seed=3, **MLP)
    summary = cv.summary()
    assert summary.loc["ANN", "cv_r2"] > 0.9, summary
    assert summary.loc["Gaussian", "cv_r2"] > 0.9, summary
    # The RMSE of the pooled predictions is small against the spread of y.
    assert summary.loc["ANN", "cv_rmse"] < 0.3 * np.std(y)
    assert list(summary.index) == ["Bayesian", "Gaussian", "ANN"]
    assert (summary["cv_folds"] == 5).all() and (summary["cv_sets"] == 30).all()


def test_noise_does_not_cross_validate_and_grouping_matters() -> None:
    """A value drawn at random per parameter set, repeated over its load conditions."""
    X, _, groups = replicated(24, 3, seed=1)
    rng = np.random.default_rng(11)
    y = np.repeat(rng.standard_normal(24), 3) + 0.01 * rng.standard_normal(72)
    cv = cross_validate(X, y, groups, 4, hidden_size=6, seed=3, **MLP)
    for method in cv.predictions:
        assert cv.pooled(method)["r2"] < 0.1, method
    # Folds by row let the Gaussian process memorise the other rows of the same set, which is
    # what grouping by parameter set prevents.
    by_row = cross_validate(
        X, y, np.arange(y.size), 4, hidden_size=6, seed=3, methods=("Gaussian",), **MLP
    )
    assert by_row.pooled("Gaussian")["r2"] > 0.5


# ----------------------------------------------------------------------------- Table 4


def bulk_dataset(n_sets: int, seed: int) -> pd.DataFrame:
    """A tidy dataset like results/bulk/dataset.csv: 4 shear loads and 1 AoR row per set."""
    rng = np.random.default_rng(seed)
    rows = []
    for k in range(n_sets):
        mu, mur, rho = rng.uniform(0.1, 1.0), rng.uniform(0.1, 1.0), rng.uniform(2500, 3500)
        design = {"design_id": f"c{k + 1:04d}", "coefficientFriction": mu}
        design |= {"coefficientRollingFriction": mur, "density": rho, "status": "ok"}
        for P in (0.4, 0.6, 0.8, 1.0):
            rows.append(
                design
                | {"test": "shear_cell", "normal_stress": 2029.0, "P": P}
                | {"rho_b": 0.55 * rho * (1.0 - 0.1 * mu) + 5.0 * P + rng.normal(0.0, 3.0)}
            )
        rows.append(design | {"test": "angle_of_repose", "aor": 20.0 + 15.0 * mu + 5 * mur})
    return pd.DataFrame(rows)


SETTINGS = {
    "hidden_sizes": [3, 4],
    "split": [0.7, 0.15, 0.15],
    "seed": 5,
    "max_epochs": 200,
    "patience": 15,
}


def test_train_output_writes_split_sizes_and_cross_validation(tmp_path: Path) -> None:
    data = bulk_dataset(14, seed=0)
    trained = train_output(data, "rho_b", SETTINGS | {"cv_folds": 4}, tmp_path / "rho_b")
    table = pd.read_csv(tmp_path / "rho_b" / "table4.csv", index_col="method")
    assert list(table.index) == ["Bayesian", "Gaussian", "ANN"]
    row = table.loc["ANN"]
    assert (row["train_sets"], row["generalisation_sets"], row["test_sets"]) == (10, 2, 2)
    assert (row["train_rows"], row["generalisation_rows"], row["test_rows"]) == (40, 8, 8)
    assert (row["cv_folds"], row["cv_sets"], row["cv_rows"]) == (4, 14, 56)
    assert row["cv_r2"] > 0.9 and row["cv_r2_min"] <= row["cv_r2"] <= row["cv_r2_max"]
    assert row["hidden_size"] == trained.sweep.selected_size
    # rho_b scatters by 3 kg/m^3 about its mean response: the process's white noise finds it,
    # and the ceiling of R^2 follows from it and the rows' variance (the same on every method).
    assert row["noise_sd"] == pytest.approx(3.0, rel=0.3)
    rho_rows = data[data["test"] == "shear_cell"]["rho_b"]
    ceiling = 1.0 - row["noise_sd"] ** 2 / np.var(rho_rows)
    assert table["r2_ceiling"].to_numpy() == pytest.approx(np.full(3, ceiling), rel=1e-6)
    assert row["cv_r2"] <= row["r2_ceiling"] + 0.01
    folds = pd.read_csv(tmp_path / "rho_b" / "cv_folds.csv")
    assert len(folds) == 4 * 3 and folds.groupby("method")["test_sets"].sum().eq(14).all()
    meta = json.loads((tmp_path / "rho_b" / "model.pt.json").read_text())["metadata"]
    assert meta["split_sets"] == [10, 2, 2] and meta["cv_metrics"]["folds"] == 4

    # More folds than AoR sets: clamped to leave-one-set-out, noted in the table.
    aor = train_output(bulk_dataset(6, 1), "aor", SETTINGS | {"cv_folds": 10}, tmp_path / "aor")
    assert aor.cv is not None and aor.cv.n_folds == 6 and "exceeds the 6" in aor.cv_note
    assert "exceeds the 6" in (tmp_path / "aor" / "table4.md").read_text()
    off = train_output(bulk_dataset(6, 1), "aor", SETTINGS | {"cv_folds": 0}, tmp_path / "off")
    assert off.cv is None and (off.table4["cv_folds"] == 0).all()

    experiment = tmp_path / "experiment.yaml"
    experiment.write_text(
        "material: m\nsource: s\nangle_of_repose:\n  value: 30.0\nshear_cell:\n"
        "  - {normal_stress: 2029, P: 1.0, mu_psh: 0.8}\n"
    )
    md = tmp_path / "table4.md"
    combined = write_table4_document(
        ["rho_b", "aor"],
        [tmp_path / "rho_b" / "table4.csv", tmp_path / "off" / "table4.csv"],
        [tmp_path / "rho_b" / "sweep.csv", tmp_path / "off" / "sweep.csv"],
        md,
        csv=tmp_path / "all.csv",
        experiment=experiment,
        tolerance=0.05,
    )
    written = pd.read_csv(tmp_path / "all.csv", index_col="method")
    assert list(written["output"]) == ["rho_b"] * 3 + ["aor"] * 3
    # rho_b was not measured: 5 % of its data mean; aor: 5 % of the measured 30 deg.
    rho = written[written["output"] == "rho_b"].iloc[0]
    assert rho["tolerance_basis"] == "data mean"
    np.testing.assert_allclose(rho["tolerance_abs"], 0.05 * rho["y_mean"])
    aor_rows = written[written["output"] == "aor"]
    np.testing.assert_allclose(aor_rows["tolerance_abs"], 1.5)
    expected = aor_rows["test_rmse"] < 1.5
    assert list(aor_rows["test_rmse_below_tolerance"]) == list(expected)
    assert aor_rows["cv_rmse_below_tolerance"].isna().all()  # no cross-validation
    rho_rows = written[written["output"] == "rho_b"]
    expected = rho_rows["cv_rmse"] < rho_rows["tolerance_abs"]
    assert list(rho_rows["cv_rmse_below_tolerance"]) == list(expected)
    assert list(combined["cv_rmse_below_tolerance"].iloc[:3]) == list(expected)
    text = md.read_text()
    assert "CV folds (sets/rows)" in text and "| ANN | 10/2/2 | 40/8/8 |" in text
    assert "4 (14/56)" in text and "Cross-validation: off." in text
    assert f"would score an R^2 of at most {rho['r2_ceiling']:.3g}" in text
    # The last table of every section keeps the paper's layout (metrics by method).
    for section in text.split("\n## ")[1:]:
        last = section.strip().splitlines()[-6:]
        assert last[0] == "| metric | Bayesian | Gaussian | ANN |"
        assert [line.split("|")[1].strip() for line in last[2:]] == ["R^2", "RMSE", "MAE", "MSE"]


def test_acceptance_reference_uses_the_smallest_measured_value() -> None:
    experiment = Experiment(
        material="m",
        source="s",
        shear_conditions=[
            MeasuredCondition({"rho_b": 1800.0}, normal_stress=1000.0, P=1.0),
            MeasuredCondition({"rho_b": 1700.0, "mu_psh": 0.6}, normal_stress=2000.0, P=1.0),
        ],
        angle_of_repose=35.0,
    )
    assert acceptance_reference("rho_b", experiment, 1500.0) == (1700.0, "measured")
    assert acceptance_reference("aor", experiment, 20.0) == (35.0, "measured")
    assert acceptance_reference("mu_sh", experiment, -0.4) == (0.4, "data mean")
    assert acceptance_reference("aor", None, 20.0) == (20.0, "data mean")
