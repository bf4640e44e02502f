"""Inputs a surrogate sees on a logarithmic scale.

The bulk values rise steeply with the sliding friction coefficient below about 0.3 and
saturate above it, where contacts roll rather than slide. On a linear axis a design of a few
dozen sets puts two or three sets in the steep part, and a smooth regressor with one length
scale per input cannot follow both parts; on ``log(mu_s)`` the response is close to linear
over the whole range [0.1, 1] (cross-validated on quick-scale runs in
``docs/identification.md``). Rolling friction stays linear: its effect on the bulk values is
close to linear in the box, and its logarithm made the angle's network worse.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import numpy.typing as npt
from sklearn.pipeline import Pipeline
from sklearn.preprocessing import FunctionTransformer

from demcal.core.parameters import LOG_SCALE_PARAMETERS

#: Model inputs taken as their natural logarithm (LIGGGHTS names).
LOG_INPUTS = LOG_SCALE_PARAMETERS


def log_columns(features: Sequence[str]) -> tuple[int, ...]:
    """Positions of the logarithmic inputs among ``features``.

    Parameters
    ----------
    features : sequence of str
        The model's ordered input names.

    Returns
    -------
    tuple of int
        Column indices of the names in :data:`LOG_INPUTS`, ascending.
    """
    return tuple(k for k, name in enumerate(features) if name in LOG_INPUTS)


def take_logs(X: npt.ArrayLike, columns: Sequence[int]) -> np.ndarray:
    """``X`` with the natural logarithm of its ``columns``.

    Parameters
    ----------
    X : array_like, shape (n, n_features)
        Inputs in SI units.
    columns : sequence of int
        Columns to take the logarithm of.

    Returns
    -------
    numpy.ndarray of float64, shape (n, n_features)
        A copy; ``X`` is left unchanged.

    Raises
    ------
    ValueError
        If a column holds a value that is not positive (a friction coefficient of 0 has no
        logarithm; the design ranges must start above 0).
    """
    out = np.array(X, dtype=np.float64, copy=True)
    cols = list(columns)
    if not cols:
        return out
    if out.ndim != 2 or max(cols) >= out.shape[1] or min(cols) < 0:
        raise ValueError(f"log columns {cols} do not fit inputs of shape {out.shape}")
    values = out[:, cols]
    if not np.all(values > 0.0):
        raise ValueError(
            f"inputs in log columns {cols} must be positive, smallest is {np.nanmin(values):g}"
        )
    out[:, cols] = np.log(values)
    return out


def log_transformer(columns: Sequence[int]) -> FunctionTransformer:
    """A scikit-learn step applying :func:`take_logs` to ``columns``.

    Parameters
    ----------
    columns : sequence of int
        Columns to take the logarithm of.

    Returns
    -------
    sklearn.preprocessing.FunctionTransformer
    """
    return FunctionTransformer(take_logs, kw_args={"columns": tuple(columns)})


def pipeline_log_columns(pipeline: Pipeline) -> tuple[int, ...]:
    """The columns the ``log`` step (:func:`log_transformer`) of a fitted pipeline takes.

    Parameters
    ----------
    pipeline : sklearn.pipeline.Pipeline
        With a step named ``log``.

    Returns
    -------
    tuple of int
    """
    step = pipeline.named_steps["log"]
    return tuple((step.kw_args or {}).get("columns", ()))
