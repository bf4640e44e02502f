"""Regression quality metrics and the method-comparison table (paper Table 4).

The paper compares the neural network with Bayesian linear regression and Gaussian process
regression on the held-out test set by R^2, root mean squared error, mean absolute error and
mean squared error. The errors carry the units of the predicted bulk value (for example
kg/m^3 for rho_b, degrees for the angle of repose, none for the friction coefficients).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

import numpy as np
import numpy.typing as npt
import pandas as pd

METRIC_LABELS: dict[str, str] = {"r2": "R^2", "rmse": "RMSE", "mae": "MAE", "mse": "MSE"}
"""Row labels of the comparison table, keyed by the names returned by `regression_metrics`."""


def _as_vector(values: npt.ArrayLike, name: str) -> np.ndarray:
    array = np.asarray(values, dtype=np.float64)
    if array.ndim == 2 and array.shape[1] == 1:
        array = array[:, 0]
    if array.ndim != 1:
        raise ValueError(f"{name} must be one-dimensional, got shape {array.shape}")
    if array.size == 0:
        raise ValueError(f"{name} is empty")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} contains NaN or infinite values")
    return array


def regression_metrics(y_true: npt.ArrayLike, y_pred: npt.ArrayLike) -> dict[str, float]:
    """Coefficient of determination and error measures of a prediction.

    Parameters
    ----------
    y_true : array_like, shape (n,)
        Reference values (DEM results), in the units of the bulk value.
    y_pred : array_like, shape (n,)
        Predicted values in the same units.

    Returns
    -------
    dict
        ``r2`` (-), ``rmse``, ``mae`` (units of y) and ``mse`` (units of y squared).
        ``r2 = 1 - sum((y - yhat)^2) / sum((y - mean(y))^2)``; it is NaN when `y_true` is
        constant, because R^2 is undefined without variance.

    Raises
    ------
    ValueError
        If the arrays are empty, not one-dimensional, differ in length or are not finite.
    """
    truth = _as_vector(y_true, "y_true")
    pred = _as_vector(y_pred, "y_pred")
    if truth.shape != pred.shape:
        raise ValueError(f"y_true and y_pred differ in length: {truth.shape[0]} vs {pred.shape[0]}")
    residual = truth - pred
    mse = float(np.mean(residual**2))
    ss_tot = float(np.sum((truth - truth.mean()) ** 2))
    r2 = 1.0 - float(np.sum(residual**2)) / ss_tot if ss_tot > 0.0 else float("nan")
    return {
        "r2": r2,
        "rmse": float(np.sqrt(mse)),
        "mae": float(np.mean(np.abs(residual))),
        "mse": mse,
    }


def method_comparison_table(
    results: Mapping[str, tuple[npt.ArrayLike, npt.ArrayLike]],
) -> pd.DataFrame:
    """Table 4 of the paper: metrics (rows) per regression method (columns).

    Parameters
    ----------
    results : mapping of str to (y_true, y_pred)
        Method name (for example ``"Bayesian"``, ``"Gaussian"``, ``"ANN"``) to the test-set
        reference values and predictions, each of shape (n,). Column order follows the mapping.

    Returns
    -------
    pandas.DataFrame
        Index ``["R^2", "RMSE", "MAE", "MSE"]`` (named ``metric``), one float column per method.
    """
    if len(results) == 0:
        raise ValueError("method_comparison_table needs at least one method")
    columns: dict[str, list[float]] = {}
    for method, pair in results.items():
        if len(pair) != 2:
            raise ValueError(f"results[{method!r}] must be a pair (y_true, y_pred)")
        try:
            metrics = regression_metrics(pair[0], pair[1])
        except ValueError as error:
            raise ValueError(f"results[{method!r}]: {error}") from error
        columns[str(method)] = [metrics[key] for key in METRIC_LABELS]
    index = pd.Index(list(METRIC_LABELS.values()), name="metric")
    return pd.DataFrame(columns, index=index)


def _cell_text(value: object, formatter: Callable[[float], str]) -> str:
    if isinstance(value, bool | np.bool_):
        text = str(bool(value))
    elif isinstance(value, float | np.floating):
        text = formatter(float(value))
    else:
        text = str(value)
    # A literal pipe would split the cell.
    return text.replace("|", "\\|")


def to_markdown(df: pd.DataFrame, float_format: str | Callable[[float], str] = ".3f") -> str:
    """Render a DataFrame as a GitHub-flavoured Markdown table.

    Parameters
    ----------
    df : pandas.DataFrame
        Table to render; the index becomes the first column (headed by the index name).
    float_format : str or callable, default ".3f"
        Either a format specification applied with ``format(value, spec)`` or a function
        mapping a float to its text. Integers and strings are written with ``str``.

    Returns
    -------
    str
        Header row, alignment row (numeric columns right-aligned) and one row per index
        entry, joined by newlines, with a trailing newline.
    """
    if isinstance(float_format, str):
        spec = float_format
        try:
            format(1.0, spec)
        except ValueError as error:
            raise ValueError(f"float_format {spec!r} is not a valid format spec") from error

        def formatter(value: float) -> str:
            return format(value, spec)
    else:
        formatter = float_format

    header = [str(df.index.name) if df.index.name is not None else ""]
    header += [str(column) for column in df.columns]
    align = ["---"]
    for column in df.columns:
        numeric = pd.api.types.is_numeric_dtype(df[column]) and not pd.api.types.is_bool_dtype(
            df[column]
        )
        align.append("---:" if numeric else "---")
    lines = [
        "| " + " | ".join(cell.replace("|", "\\|") for cell in header) + " |",
        "| " + " | ".join(align) + " |",
    ]
    for label, row in zip(df.index, df.itertuples(index=False, name=None), strict=True):
        cells = [_cell_text(label, formatter)] + [_cell_text(value, formatter) for value in row]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"
