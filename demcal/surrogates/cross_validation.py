"""K-fold cross-validation of the surrogates, grouped by DEM parameter set.

With a few dozen parameter sets, a 15 % test split holds two or three of them and its R^2 says
little. Cross-validation predicts every row once, by a model trained without the row's
parameter set, and scores the pooled out-of-fold predictions:

1. the distinct parameter sets (``design_id``) are shuffled and dealt into K folds
   (:func:`demcal.surrogates.data_split.grouped_folds`); the rows of one set are never split;
2. for each fold, the other folds form the training part, from which whole sets are held out as
   the generalisation (early stopping) set in the proportion of ``surrogate.split``
   (:func:`demcal.surrogates.data_split.holdout_groups`);
3. the network of the hidden size selected for the saved model is trained on that part with the
   same function and settings as the saved model
   (:func:`demcal.surrogates.hidden_size_sweep.sweep_hidden_sizes` with one size), the baselines
   are fitted on every row outside the fold
   (:func:`demcal.surrogates.baselines.baseline_predictions`), and all three predict the fold.
   The baselines stop on no generalisation set, and the Gaussian process that may screen is
   fitted on every usable row, so holding sets back from them would score a model fitted on a
   sixth fewer sets than the one that screens;
4. R^2, RMSE, MAE and MSE are computed once over the pooled predictions of all rows; the
   per-fold values give their spread (the R^2 of a fold against the variance of all rows, see
   ``CrossValidation.folds``).

The hidden size is chosen once, on the single split of the saved model, and not again inside
every fold (no nested cross-validation), so the cross-validated network error leans slightly
optimistic.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt
import pandas as pd

from demcal.surrogates.baselines import BASELINES, baseline_predictions
from demcal.surrogates.data_split import grouped_folds, holdout_groups
from demcal.surrogates.hidden_size_sweep import sweep_hidden_sizes
from demcal.surrogates.metrics import regression_metrics

__all__ = [
    "METHODS",
    "CrossValidation",
    "cross_validate",
    "effective_folds",
    "set_counts",
]

#: The regression methods of Table 4, in table order.
METHODS = (*BASELINES, "ANN")

#: Configuration key of the number of folds (named in messages).
FOLDS_KEY = "surrogate.cv_folds"

_log = logging.getLogger(__name__)


def set_counts(groups: npt.ArrayLike, index: npt.ArrayLike) -> tuple[int, int]:
    """Number of distinct parameter sets and of rows among the rows ``index``.

    Parameters
    ----------
    groups : array_like, shape (n,)
        Parameter-set label of every row.
    index : array_like of int, shape (m,)
        Rows of one part (training, generalisation, test or a fold).

    Returns
    -------
    n_sets, n_rows : int
    """
    rows = np.asarray(index, dtype=np.int64)
    return int(np.unique(np.asarray(groups)[rows]).size), int(rows.size)


def effective_folds(requested: int, n_sets: int) -> tuple[int, str]:
    """Number of folds to use on ``n_sets`` parameter sets, and why it differs from the request.

    The data decide how many sets are usable (failed DEM runs drop sets), so a request larger
    than the data allow is clamped with a note instead of stopping the workflow after the DEM
    runs: to ``n_sets`` (leave one set out), and to leave-one-set-out as well when the largest
    fold would leave fewer than two sets for training and generalisation.

    Parameters
    ----------
    requested : int
        ``surrogate.cv_folds``: 0 switches cross-validation off, otherwise at least 2.
    n_sets : int
        Distinct parameter sets with usable rows.

    Returns
    -------
    n_folds : int
        0 (off) or the number of folds, ``2 <= n_folds <= n_sets``.
    note : str
        Empty when ``n_folds == requested``, else the reason (for the log and Table 4).

    Raises
    ------
    ValueError
        If ``requested`` is negative, 1 or not an integer (names the key).
    """
    if isinstance(requested, bool) or int(requested) != requested or requested < 0:
        raise ValueError(f"{FOLDS_KEY} must be 0 (off) or an integer >= 2, got {requested!r}")
    requested = int(requested)
    if requested == 0:
        return 0, ""
    if requested == 1:
        raise ValueError(f"{FOLDS_KEY} must be 0 (off) or an integer >= 2, got 1")
    if n_sets < 3:
        return 0, (
            f"{FOLDS_KEY}={requested} but only {n_sets} parameter set(s) are usable; "
            "cross-validation needs 3 (training, generalisation, test) and is skipped"
        )
    n_folds, note = requested, ""
    if n_folds > n_sets:
        n_folds = n_sets
        note = (
            f"{FOLDS_KEY}={requested} exceeds the {n_sets} usable parameter sets; "
            f"using {n_sets} folds (leave one set out)"
        )
    if n_sets - math.ceil(n_sets / n_folds) < 2:
        n_folds = n_sets
        note = (
            f"{FOLDS_KEY}={requested} on {n_sets} usable parameter sets would leave fewer than "
            f"2 sets for training and generalisation; using {n_sets} folds (leave one set out)"
        )
    return n_folds, note


@dataclass(frozen=True)
class CrossValidation:
    """Out-of-fold predictions of every method and their scores.

    Attributes
    ----------
    y : numpy.ndarray, shape (n,)
        The bulk value of every row (units of the bulk value).
    fold : numpy.ndarray of int64, shape (n,)
        Fold (0 .. n_folds - 1) that predicted each row.
    predictions : dict of str to numpy.ndarray, shape (n,)
        Method -> out-of-fold prediction of every row, units of y.
    folds : pandas.DataFrame
        One row per fold and method: ``fold``, ``method``, ``train_sets``, ``train_rows``,
        ``generalisation_sets``, ``generalisation_rows``, ``test_sets``, ``test_rows`` and the
        fold's ``r2`` (-), ``rmse``, ``mae`` (units of y), ``mse`` (units of y squared) and
        ``r2_global`` = 1 - fold MSE / variance of ``y`` over all rows (-). A fold of a few
        parameter sets has little variance of its own, so its own ``r2`` is erratic;
        ``r2_global`` measures the fold's error against the spread of the whole data set, and
        its mean weighted by ``test_rows`` is the pooled R^2.
    n_sets : int
        Distinct parameter sets over all folds.
    """

    y: np.ndarray
    fold: np.ndarray
    predictions: dict[str, np.ndarray]
    folds: pd.DataFrame
    n_sets: int

    @property
    def n_folds(self) -> int:
        """Number of folds."""
        return int(self.fold.max()) + 1

    def pooled(self, method: str) -> dict[str, float]:
        """``r2``, ``rmse``, ``mae``, ``mse`` of the pooled out-of-fold predictions of a method."""
        return regression_metrics(self.y, self.predictions[method])

    def summary(self) -> pd.DataFrame:
        """Pooled scores and their spread over the folds, one row per method.

        Returns
        -------
        pandas.DataFrame
            Index ``method`` (the order of `predictions`); columns ``cv_folds``, ``cv_sets``,
            ``cv_rows``, pooled ``cv_r2``, ``cv_rmse``, ``cv_mae``, ``cv_mse`` and over the folds
            ``cv_r2_sd``, ``cv_r2_min``, ``cv_r2_max`` (of the folds' ``r2_global``),
            ``cv_rmse_sd``, ``cv_rmse_min``, ``cv_rmse_max`` (sample standard deviation over the
            folds; NaN where undefined).
        """
        rows = []
        for method in self.predictions:
            pooled = self.pooled(method)
            per_fold = self.folds[self.folds["method"] == method]
            row: dict[str, Any] = {
                "method": method,
                "cv_folds": self.n_folds,
                "cv_sets": self.n_sets,
                "cv_rows": int(self.y.size),
                **{f"cv_{k}": v for k, v in pooled.items()},
            }
            for metric, column in (("r2", "r2_global"), ("rmse", "rmse")):
                values = per_fold[column].to_numpy(dtype=np.float64)
                finite = values[np.isfinite(values)]
                spread = float(np.std(finite, ddof=1)) if finite.size > 1 else np.nan
                row[f"cv_{metric}_sd"] = spread
                row[f"cv_{metric}_min"] = float(finite.min()) if finite.size else np.nan
                row[f"cv_{metric}_max"] = float(finite.max()) if finite.size else np.nan
            rows.append(row)
        return pd.DataFrame(rows).set_index("method")


def cross_validate(
    X: npt.ArrayLike,
    y: npt.ArrayLike,
    groups: npt.ArrayLike,
    n_folds: int,
    hidden_size: int,
    seed: int = 0,
    split: Sequence[float] = (0.7, 0.15, 0.15),
    methods: Sequence[str] = METHODS,
    log_inputs: Sequence[int] = (),
    **mlp_params: Any,
) -> CrossValidation:
    """Grouped K-fold cross-validation of the network and the baselines.

    Parameters
    ----------
    X : array_like, shape (n, n_features)
        Inputs of all rows (SI units).
    y : array_like, shape (n,)
        Bulk value of all rows.
    groups : array_like, shape (n,)
        Parameter set (``design_id``) of every row; a set never straddles two folds.
    n_folds : int
        Number of folds, ``2 <= n_folds <= number of sets`` (see :func:`effective_folds`).
    hidden_size : int
        Hidden neurons of every fold's network (the size selected for the saved model).
    seed : int, default 0
        Seed of the fold assignment, of the generalisation hold-out within each fold (combined
        with the fold number), of the network initialisation and of the Gaussian-process
        restarts.
    split : sequence of 3 floats, default (0.7, 0.15, 0.15)
        ``surrogate.split``; the training part of a fold gives up the share
        ``split[1] / (split[0] + split[1])`` of its sets (at least one) to the network's
        generalisation set. The baselines are fitted on training and generalisation sets.
    methods : sequence of str, default METHODS
        Methods to run, a subset of ``("Bayesian", "Gaussian", "ANN")``, in output order.
    log_inputs : sequence of int, default ()
        Input columns every method takes as their natural logarithm
        (:mod:`demcal.surrogates.log_inputs`).
    **mlp_params
        Further `MLPSurrogate` parameters, as for the saved model (``max_epochs``,
        ``patience``, ...).

    Returns
    -------
    CrossValidation
        Out-of-fold predictions, per-fold scores and (via ``summary``) pooled scores.

    Raises
    ------
    ValueError
        If the arrays differ in length, ``n_folds`` is out of range, a method is unknown or a
        fold's training part holds fewer than two sets.
    """
    X_arr = np.asarray(X, dtype=np.float64)
    y_arr = np.asarray(y, dtype=np.float64)
    labels = np.asarray(groups)
    n = y_arr.shape[0]
    if X_arr.ndim != 2 or X_arr.shape[0] != n or labels.shape != (n,):
        raise ValueError(
            f"X {X_arr.shape}, y {y_arr.shape} and groups {labels.shape} must have n rows"
        )
    unknown = [m for m in methods if m not in METHODS]
    if unknown or not methods:
        raise ValueError(f"methods must be a non-empty subset of {METHODS}, got {list(methods)}")
    shares = [float(s) for s in split]
    if len(shares) != 3 or min(shares) <= 0.0:
        raise ValueError(f"split must be three positive shares, got {split!r}")
    held_share = shares[1] / (shares[0] + shares[1])

    fold_of = np.full(n, -1, dtype=np.int64)
    predictions = {m: np.full(n, np.nan) for m in methods}
    records: list[dict[str, Any]] = []
    for k, test in enumerate(grouped_folds(labels, n_folds, seed)):
        rest = np.setdiff1d(np.arange(n, dtype=np.int64), test)
        if np.unique(labels[rest]).size < 2:
            raise ValueError(
                f"fold {k}: the training part holds fewer than 2 parameter sets; use fewer folds"
            )
        kept, held = holdout_groups(labels[rest], seed=(seed, k), fraction=held_share)
        train, val = rest[kept], rest[held]
        fold_of[test] = k
        fold_pred: dict[str, np.ndarray] = {}
        baselines = [m for m in methods if m in BASELINES]
        if baselines:
            # No early stopping: the baselines learn from every set outside the fold.
            fitted = baseline_predictions(
                X_arr[rest], y_arr[rest], X_arr[test], seed, log_inputs=log_inputs
            )
            fold_pred.update({m: fitted[m] for m in baselines})
        if "ANN" in methods:
            sweep = sweep_hidden_sizes(
                X_arr,
                y_arr,
                train,
                val,
                test,
                sizes=[hidden_size],
                seed=seed,
                log_inputs=tuple(log_inputs),
                **mlp_params,
            )
            fold_pred["ANN"] = sweep.model.predict(X_arr[test])
        counts = {}
        for part, index in (("train", train), ("generalisation", val), ("test", test)):
            counts[f"{part}_sets"], counts[f"{part}_rows"] = set_counts(labels, index)
        for method in methods:
            predictions[method][test] = fold_pred[method]
            records.append(
                {
                    "fold": k,
                    "method": method,
                    **counts,
                    **regression_metrics(y_arr[test], fold_pred[method]),
                }
            )
        _log.debug("fold %d: %s", k, counts)
    folds = pd.DataFrame(records)
    # A fold of two or three sets has little variance of its own, so its own R^2 swings wildly;
    # against the variance of all rows, the row-weighted mean of the fold values is the pooled R^2.
    variance = float(np.var(y_arr))
    folds["r2_global"] = 1.0 - folds["mse"] / variance if variance > 0.0 else np.nan
    return CrossValidation(
        y=y_arr,
        fold=fold_of,
        predictions=predictions,
        folds=folds,
        n_sets=int(np.unique(labels).size),
    )
