"""The Bayesian linear regression of a bulk value as a screening surrogate.

Where a bulk value depends nearly linearly on the contact parameters (the bulk density of the
quick shear cell: Table 4), the linear baseline cross-validates better than the network and the
Gaussian process, whose extra freedom only fits the scatter of single runs.
:class:`LinearSurrogate` keeps the fitted plane,

    y(x) = intercept + sum_j coef_j * x'_j,

where ``x'`` is ``x`` with the natural logarithm of the log columns, and offers what screening
needs: a JSON file and a float32 ``predict_torch``.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import torch
from sklearn.pipeline import Pipeline

from demcal.surrogates.baselines import linear_coefficients
from demcal.surrogates.grid_evaluation import evaluate_in_chunks
from demcal.surrogates.log_inputs import pipeline_log_columns, take_logs
from demcal.surrogates.surrogate_json import read_surrogate_json, write_surrogate_json

#: Format tag of the file.
LINEAR_FORMAT = "demcal-linear-regression-1"


class LinearSurrogate:
    """A plane over named SI inputs (some taken as their logarithm).

    Parameters
    ----------
    features : sequence of str
        Ordered input names.
    log_inputs : sequence of int
        Columns taken as their natural logarithm.
    coef : array_like, shape (d,)
        Slopes, units of the bulk value per unit of the input (per unit of its logarithm for a
        log column).
    intercept : float
        Value where every (log-taken) input is 0, units of the bulk value.
    """

    def __init__(
        self,
        features: Sequence[str],
        log_inputs: Sequence[int],
        coef: npt.ArrayLike,
        intercept: float,
    ) -> None:
        self.features = [str(f) for f in features]
        self.log_inputs = tuple(int(c) for c in log_inputs)
        self.coef = np.asarray(coef, dtype=np.float64).reshape(-1)
        self.intercept = float(intercept)
        if self.coef.shape != (len(self.features),):
            raise ValueError(
                f"inconsistent linear surrogate: {len(self.features)} features, "
                f"{self.coef.shape[0]} slopes"
            )

    @classmethod
    def from_pipeline(cls, pipeline: Pipeline, features: Sequence[str]) -> LinearSurrogate:
        """The plane of a fitted `demcal.surrogates.baselines.bayesian_linear_regression`.

        Parameters
        ----------
        pipeline : sklearn.pipeline.Pipeline
            Fitted, steps ``log``, ``scale`` and ``regressor``.
        features : sequence of str
            Its ordered input names.
        """
        coef, intercept = linear_coefficients(pipeline)
        return cls(features, pipeline_log_columns(pipeline), coef, intercept)

    def predict(self, X: npt.ArrayLike) -> np.ndarray:
        """The plane's value, float64.

        Parameters
        ----------
        X : array_like, shape (n, d)
            Inputs in SI units, in the order of `features`.

        Returns
        -------
        numpy.ndarray, shape (n,)
            Units of the bulk value.
        """
        return self.intercept + take_logs(X, self.log_inputs) @ self.coef

    def predict_torch(self, X: torch.Tensor, chunk_size: int = 262_144) -> torch.Tensor:
        """The plane's value over many rows in float32, for screening candidate grids.

        Parameters
        ----------
        X : torch.Tensor, shape (n, d)
            Inputs in SI units (log columns as they are); not modified.
        chunk_size : int, default 262144
            Rows per chunk (bounds the float64 copy).

        Returns
        -------
        torch.Tensor of float32, shape (n,)
        """
        # float64 inside: the intercept of a bulk density (~1e3) would eat float32 digits of
        # the small per-parameter terms.
        coef = torch.from_numpy(self.coef)
        return evaluate_in_chunks(
            X,
            len(self.features),
            self.log_inputs,
            chunk_size,
            lambda chunk: chunk @ coef + self.intercept,
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON-serialisable description (every number as a Python float)."""
        return {
            "format": LINEAR_FORMAT,
            "features": self.features,
            "log_inputs": list(self.log_inputs),
            "coef": self.coef.tolist(),
            "intercept": self.intercept,
        }

    def save(self, path: str | Path, metadata: dict[str, Any] | None = None) -> Path:
        """Write the plane as JSON (``metadata`` under its own key)."""
        return write_surrogate_json(path, self.to_dict(), metadata)

    @classmethod
    def load(cls, path: str | Path) -> LinearSurrogate:
        """Read a plane written by `save`.

        Raises
        ------
        ValueError
            If the file is not of this format or its slopes do not match its features.
        """
        keys = ("features", "log_inputs", "coef", "intercept")
        return cls(**read_surrogate_json(path, LINEAR_FORMAT, "linear-regression", keys))
