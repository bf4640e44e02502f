"""Tests of demcal.surrogates.metrics: hand-computed cases, sklearn equivalence, tables."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from sklearn.metrics import mean_absolute_error, mean_squared_error, r2_score

from demcal.surrogates.metrics import method_comparison_table, regression_metrics, to_markdown


def test_hand_computed_case() -> None:
    # residuals (0, 0, 0, -1); mean of y_true 2.5, total sum of squares 5.
    m = regression_metrics([1.0, 2.0, 3.0, 4.0], [1.0, 2.0, 3.0, 5.0])
    assert m["mse"] == pytest.approx(0.25)
    assert m["rmse"] == pytest.approx(0.5)
    assert m["mae"] == pytest.approx(0.25)
    assert m["r2"] == pytest.approx(1.0 - 1.0 / 5.0)


def test_perfect_and_mean_predictions() -> None:
    y = np.array([0.3, 0.5, 0.9, 0.4])
    perfect = regression_metrics(y, y)
    assert perfect == {"r2": 1.0, "rmse": 0.0, "mae": 0.0, "mse": 0.0}
    at_mean = regression_metrics(y, np.full_like(y, y.mean()))
    assert at_mean["r2"] == pytest.approx(0.0, abs=1e-15)
    assert at_mean["mse"] == pytest.approx(np.var(y))


def test_constant_truth_gives_nan_r2() -> None:
    m = regression_metrics([2.0, 2.0, 2.0], [1.0, 2.0, 3.0])
    assert math.isnan(m["r2"])
    assert m["mse"] == pytest.approx(2.0 / 3.0)


def test_matches_sklearn_on_random_data() -> None:
    rng = np.random.default_rng(3)
    y = rng.normal(1760.0, 42.0, size=200)
    pred = y + rng.normal(0.0, 20.0, size=200)
    m = regression_metrics(y, pred)
    assert m["r2"] == pytest.approx(r2_score(y, pred), rel=1e-12)
    assert m["mse"] == pytest.approx(mean_squared_error(y, pred), rel=1e-12)
    assert m["mae"] == pytest.approx(mean_absolute_error(y, pred), rel=1e-12)
    assert m["rmse"] == pytest.approx(math.sqrt(mean_squared_error(y, pred)), rel=1e-12)


def test_column_vectors_are_accepted() -> None:
    y = np.array([[1.0], [2.0], [4.0]])
    assert regression_metrics(y, y[:, 0] + 1.0)["mae"] == pytest.approx(1.0)


@pytest.mark.parametrize(
    ("y_true", "y_pred", "message"),
    [
        ([1.0, 2.0], [1.0], "differ in length"),
        ([1.0, np.nan], [1.0, 2.0], "y_true contains NaN"),
        ([1.0, 2.0], [1.0, np.inf], "y_pred contains NaN"),
        ([], [], "y_true is empty"),
        (np.ones((2, 2)), np.ones((2, 2)), "one-dimensional"),
    ],
)
def test_bad_input_raises(y_true: object, y_pred: object, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        regression_metrics(y_true, y_pred)


def test_method_comparison_table_shape_and_values() -> None:
    y = np.array([1.0, 2.0, 3.0, 4.0])
    table = method_comparison_table(
        {"Bayesian": (y, [1.0, 2.0, 3.0, 5.0]), "Gaussian": (y, y), "ANN": (y, y + 0.5)}
    )
    assert list(table.index) == ["R^2", "RMSE", "MAE", "MSE"]
    assert list(table.columns) == ["Bayesian", "Gaussian", "ANN"]
    assert table.loc["R^2", "Bayesian"] == pytest.approx(0.8)
    assert table.loc["MSE", "Gaussian"] == 0.0
    assert table.loc["RMSE", "ANN"] == pytest.approx(0.5)
    assert table.loc["R^2", "ANN"] == pytest.approx(1.0 - 4 * 0.25 / 5.0)


def test_method_comparison_table_errors_name_the_method() -> None:
    with pytest.raises(ValueError, match="'ANN'"):
        method_comparison_table({"ANN": ([1.0, 2.0], [1.0])})
    with pytest.raises(ValueError, match="at least one"):
        method_comparison_table({})


def test_to_markdown_exact_text() -> None:
    df = pd.DataFrame(
        {"Bayesian": [0.86, 0.0571], "ANN": [0.959, 0.031], "note": ["a|b", "c"]},
        index=pd.Index(["R^2", "RMSE"], name="metric"),
    )
    expected = (
        "| metric | Bayesian | ANN | note |\n"
        "| --- | ---: | ---: | --- |\n"
        "| R^2 | 0.860 | 0.959 | a\\|b |\n"
        "| RMSE | 0.057 | 0.031 | c |\n"
    )
    assert to_markdown(df) == expected


def test_to_markdown_formats() -> None:
    df = pd.DataFrame({"x": [1234.5678], "n": [3]})
    assert to_markdown(df, ".1f").splitlines()[2] == "| 0 | 1234.6 | 3 |"
    assert to_markdown(df, lambda v: f"{v:.2e}").splitlines()[2] == "| 0 | 1.23e+03 | 3 |"
    with pytest.raises(ValueError, match="float_format"):
        to_markdown(df, "not a spec")
