"""Choice of the network size: one network per hidden size on the same split, scored on the
test set (the paper's sweep over 5..40 hidden neurons).

The size is selected by the lowest generalisation-set error, which does not look at the test
set; the size the paper's rule (highest test R^2) would pick is reported beside it.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt
import pandas as pd

from demcal.surrogates.metrics import regression_metrics
from demcal.surrogates.network import MLPSurrogate


@dataclass(frozen=True)
class SweepResult:
    """Outcome of `sweep_hidden_sizes`.

    Attributes
    ----------
    table : pandas.DataFrame
        One row per hidden size: ``hidden_size``, ``val_mse``, ``test_r2``, ``test_rmse``,
        ``test_mae``, ``test_mse``, ``epochs``, ``best_epoch``.
    selected_size : int
        Size with the lowest generalisation-set error (independent of the test set).
    paper_rule_size : int
        Size with the highest test R^2, the rule of the paper.
    model : MLPSurrogate
        Fitted network of `selected_size`.
    paper_rule_model : MLPSurrogate
        Fitted network of `paper_rule_size`.
    """

    table: pd.DataFrame
    selected_size: int
    paper_rule_size: int
    model: MLPSurrogate
    paper_rule_model: MLPSurrogate


def select_by_validation(table: pd.DataFrame) -> int:
    """Hidden size with the lowest ``val_mse`` (the smaller size on ties)."""
    ordered = table.sort_values(["val_mse", "hidden_size"], kind="stable")
    return int(ordered["hidden_size"].iloc[0])


def select_by_test_r2(table: pd.DataFrame) -> int:
    """Hidden size with the highest ``test_r2`` (the smaller size on ties)."""
    ordered = table.assign(_neg=-table["test_r2"]).sort_values(
        ["_neg", "hidden_size"], kind="stable"
    )
    return int(ordered["hidden_size"].iloc[0])


def _rows(data: Any, index: np.ndarray) -> Any:
    if isinstance(data, pd.DataFrame | pd.Series):
        return data.iloc[index]
    return np.asarray(data)[index]


def _check_split(n: int, parts: dict[str, np.ndarray]) -> None:
    seen: set[int] = set()
    for name, idx in parts.items():
        if idx.ndim != 1 or idx.size == 0:
            raise ValueError(f"index set {name!r} must be a non-empty 1-D array")
        if idx.min() < 0 or idx.max() >= n:
            raise ValueError(f"index set {name!r} has entries outside 0..{n - 1}")
        overlap = seen.intersection(idx.tolist())
        if overlap:
            raise ValueError(f"index set {name!r} overlaps another set at {sorted(overlap)[:5]}")
        seen.update(idx.tolist())


def sweep_hidden_sizes(
    X: npt.ArrayLike,
    y: npt.ArrayLike,
    train: npt.ArrayLike,
    val: npt.ArrayLike,
    test: npt.ArrayLike,
    sizes: Iterable[int] = range(5, 41),
    seed: int = 0,
    **mlp_params: Any,
) -> SweepResult:
    """Fit one network per hidden size on the same split and score it.

    Parameters
    ----------
    X : array_like or DataFrame, shape (n, n_features)
        Inputs of all samples.
    y : array_like, shape (n,)
        Bulk value of all samples.
    train, val, test : array_like of int
        Disjoint row indices (for example from `split_indices`).
    sizes : iterable of int, default range(5, 41)
        Hidden sizes to try (the paper's 36 networks).
    seed : int, default 0
        `random_state` of every network.
    **mlp_params
        Further `MLPSurrogate` parameters (max_epochs, patience, ...).

    Returns
    -------
    SweepResult
        Per-size table, both selected sizes and their fitted networks.
    """
    size_list = [int(s) for s in sizes]
    if not size_list:
        raise ValueError("sizes is empty")
    if len(set(size_list)) != len(size_list):
        raise ValueError(f"sizes contains duplicates: {size_list}")
    for key in ("hidden_size", "random_state"):
        if key in mlp_params:
            raise ValueError(f"{key} is set by sweep_hidden_sizes, not through mlp_params")
    n = len(X)  # type: ignore[arg-type]
    if len(y) != n:  # type: ignore[arg-type]
        raise ValueError(f"X has {n} rows but y has {len(y)}")  # type: ignore[arg-type]
    parts = {
        name: np.asarray(idx, dtype=np.int64)
        for name, idx in (("train", train), ("val", val), ("test", test))
    }
    _check_split(n, parts)
    X_tr, X_val, X_te = (_rows(X, parts[k]) for k in ("train", "val", "test"))
    y_tr, y_val, y_te = (np.asarray(_rows(y, parts[k]), dtype=np.float64) for k in parts)

    rows: list[dict[str, float | int]] = []
    models: dict[int, MLPSurrogate] = {}
    for size in size_list:
        model = MLPSurrogate(hidden_size=size, random_state=seed, **mlp_params)
        model.fit(X_tr, y_tr, X_val, y_val)
        metrics = regression_metrics(y_te, model.predict(X_te))
        rows.append(
            {
                "hidden_size": size,
                "val_mse": model.val_mse_,
                "test_r2": metrics["r2"],
                "test_rmse": metrics["rmse"],
                "test_mae": metrics["mae"],
                "test_mse": metrics["mse"],
                "epochs": model.n_epochs_,
                "best_epoch": model.best_epoch_,
            }
        )
        models[size] = model
    table = pd.DataFrame(rows)
    selected = select_by_validation(table)
    paper_rule = select_by_test_r2(table)
    return SweepResult(
        table=table,
        selected_size=selected,
        paper_rule_size=paper_rule,
        model=models[selected],
        paper_rule_model=models[paper_rule],
    )
