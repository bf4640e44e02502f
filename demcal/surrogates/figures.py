"""Figures of the surrogate stage: parity plots (paper Figs. 3-5) and R^2 against network size."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import numpy.typing as npt
import pandas as pd

from demcal.surrogates.hidden_size_sweep import select_by_test_r2, select_by_validation
from demcal.surrogates.metrics import regression_metrics


def parity_plot(y_true: npt.ArrayLike, y_pred: npt.ArrayLike, label: str, path: str | Path) -> Path:
    """Predicted against DEM values with the line y = x and R^2 in the title.

    Parameters
    ----------
    y_true : array_like, shape (n,)
        DEM values of the test samples (units of the bulk value).
    y_pred : array_like, shape (n,)
        Predictions for the same samples.
    label : str
        Method and quantity, for example ``"ANN, mu_psh"``; used in the title.
    path : str or Path
        PNG file to write (parent folders are created).

    Returns
    -------
    Path
        The written file.
    """
    truth = np.asarray(y_true, dtype=np.float64).ravel()
    pred = np.asarray(y_pred, dtype=np.float64).ravel()
    metrics = regression_metrics(truth, pred)
    low = float(min(truth.min(), pred.min()))
    high = float(max(truth.max(), pred.max()))
    pad = 0.05 * (high - low) if high > low else 0.05 * max(abs(high), 1.0)
    limits = (low - pad, high + pad)

    fig, ax = plt.subplots(figsize=(4.5, 4.5))
    ax.scatter(truth, pred, s=14, alpha=0.7, edgecolors="none", label="test samples")
    ax.plot(limits, limits, color="k", linewidth=1.0, label="y = x")
    ax.set_xlim(limits)
    ax.set_ylim(limits)
    ax.set_aspect("equal")
    ax.set_xlabel("DEM value")
    ax.set_ylabel("predicted value")
    ax.set_title(f"{label}: $R^2$ = {metrics['r2']:.3f}")
    ax.legend(loc="upper left", frameon=False)
    fig.tight_layout()
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=150)
    plt.close(fig)
    return out


def r2_vs_hidden_size(sweep_df: pd.DataFrame, path: str | Path) -> Path:
    """Test R^2 of every network of a sweep, marking both selected sizes.

    Parameters
    ----------
    sweep_df : pandas.DataFrame
        `SweepResult.table`: columns ``hidden_size``, ``test_r2`` and ``val_mse``.
    path : str or Path
        PNG file to write (parent folders are created).

    Returns
    -------
    Path
        The written file.
    """
    for column in ("hidden_size", "test_r2", "val_mse"):
        if column not in sweep_df.columns:
            raise KeyError(f"sweep table lacks column {column!r}")
    if sweep_df.empty:
        raise ValueError("sweep table is empty")
    table = sweep_df.sort_values("hidden_size")
    selected = select_by_validation(table)
    paper_rule = select_by_test_r2(table)
    r2_at = dict(zip(table["hidden_size"], table["test_r2"], strict=True))

    fig, ax = plt.subplots(figsize=(6.0, 4.0))
    ax.plot(table["hidden_size"], table["test_r2"], marker="o", markersize=3, color="C0")
    ax.scatter(
        [selected],
        [r2_at[selected]],
        s=120,
        facecolors="none",
        edgecolors="C1",
        linewidths=2,
        zorder=3,
        label=f"lowest generalisation error: {selected}",
    )
    ax.scatter(
        [paper_rule],
        [r2_at[paper_rule]],
        s=60,
        marker="*",
        color="C3",
        zorder=4,
        label=f"highest test $R^2$ (paper rule): {paper_rule}",
    )
    ax.set_xlabel("hidden neurons")
    ax.set_ylabel("test $R^2$")
    ax.legend(loc="lower right", frameon=False)
    fig.tight_layout()
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=150)
    plt.close(fig)
    return out
