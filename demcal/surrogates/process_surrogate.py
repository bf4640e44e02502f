"""The Gaussian process of a bulk value as a screening surrogate.

With a few dozen parameter sets the process often cross-validates far better than the networks
(``docs/identification.md``). For screening millions of candidate sets it needs what a network
offers: a file, a float32 ``predict_torch`` over chunks and no scikit-learn at screening time.
:class:`ProcessSurrogate` keeps the posterior mean of a fitted
:func:`demcal.surrogates.baselines.gaussian_process_regression` pipeline,

    y(x) = y_mean + y_std * sum_i alpha_i * c * k(|(x' - x_i) / l|),

    k(r) = (1 + sqrt(5) r + 5 r^2 / 3) exp(-sqrt(5) r)     (Matern 5/2, ``kernel: matern52``)
    k(r) = exp(-r^2 / 2)                                    (``kernel: rbf``, files before it)

where ``x'`` is ``x`` with the logarithm of the log columns, standardised as in training,
``x_i`` the standardised training inputs, ``alpha`` the process's weights (the white-noise
term adds nothing between distinct points), ``c`` the signal variance and ``l`` the length
scales. It is written as JSON: plain numbers, readable anywhere.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import torch
from sklearn.gaussian_process.kernels import RBF, Matern
from sklearn.pipeline import Pipeline

from demcal.surrogates.grid_evaluation import evaluate_in_chunks
from demcal.surrogates.log_inputs import pipeline_log_columns, take_logs
from demcal.surrogates.surrogate_json import read_surrogate_json, write_surrogate_json

#: Format tag of the file.
PROCESS_FORMAT = "demcal-gaussian-process-1"

#: Kernels a process file may name; files without the field hold an RBF process.
KERNELS = ("matern52", "rbf")

_SQRT5 = 5.0**0.5


def _correlation(sq: Any, kernel: str) -> Any:
    """Kernel value of squared scaled distances ``sq`` (numpy array or torch tensor, >= 0)."""
    xp = torch if isinstance(sq, torch.Tensor) else np
    if kernel == "rbf":
        return xp.exp(-0.5 * sq)
    r = xp.sqrt(sq)
    return (1.0 + _SQRT5 * r + (5.0 / 3.0) * sq) * xp.exp(-_SQRT5 * r)


class ProcessSurrogate:
    """Posterior mean of a fitted Gaussian process over named SI inputs.

    Parameters
    ----------
    features : sequence of str
        Ordered input names.
    log_inputs : sequence of int
        Columns taken as their natural logarithm before standardising.
    x_mean, x_scale : array_like, shape (d,)
        Standardisation of the (log-taken) inputs.
    x_train : array_like, shape (n, d)
        Standardised training inputs.
    alpha : array_like, shape (n,)
        Weights of the training points (normalised target units).
    length_scales : array_like, shape (d,)
        Kernel length scales in standardised input units.
    signal_variance : float
        Constant factor ``c`` of the kernel.
    y_mean, y_std : float
        Target normalisation, units of the bulk value.
    kernel : {"matern52", "rbf"}, default "matern52"
        Correlation function (module docstring).
    """

    def __init__(
        self,
        features: Sequence[str],
        log_inputs: Sequence[int],
        x_mean: npt.ArrayLike,
        x_scale: npt.ArrayLike,
        x_train: npt.ArrayLike,
        alpha: npt.ArrayLike,
        length_scales: npt.ArrayLike,
        signal_variance: float,
        y_mean: float,
        y_std: float,
        kernel: str = "matern52",
    ) -> None:
        if kernel not in KERNELS:
            raise ValueError(f"unknown process kernel {kernel!r}; expected one of {KERNELS}")
        self.kernel = kernel
        self.features = [str(f) for f in features]
        self.log_inputs = tuple(int(c) for c in log_inputs)
        self.x_mean = np.asarray(x_mean, dtype=np.float64)
        self.x_scale = np.asarray(x_scale, dtype=np.float64)
        self.x_train = np.asarray(x_train, dtype=np.float64)
        self.alpha = np.asarray(alpha, dtype=np.float64).reshape(-1)
        self.length_scales = np.broadcast_to(
            np.asarray(length_scales, dtype=np.float64), self.x_mean.shape
        ).copy()
        self.signal_variance = float(signal_variance)
        self.y_mean = float(y_mean)
        self.y_std = float(y_std)
        d = len(self.features)
        n = self.alpha.shape[0]
        if self.x_train.shape != (n, d) or self.x_mean.shape != (d,) or self.x_scale.shape != (d,):
            raise ValueError(
                f"inconsistent process: {d} features, x_train {self.x_train.shape}, "
                f"alpha ({n},), x_mean {self.x_mean.shape}, x_scale {self.x_scale.shape}"
            )

    @classmethod
    def from_pipeline(cls, pipeline: Pipeline, features: Sequence[str]) -> ProcessSurrogate:
        """Extract the posterior mean of a fitted `gaussian_process_regression` pipeline.

        Parameters
        ----------
        pipeline : sklearn.pipeline.Pipeline
            Fitted, steps ``log``, ``scale`` and ``regressor``.
        features : sequence of str
            Its ordered input names.
        """
        scaler = pipeline.named_steps["scale"]
        gp = pipeline.named_steps["regressor"].gp_
        kernel = gp.kernel_
        correlation = kernel.k1.k2
        if isinstance(correlation, Matern) and correlation.nu == 2.5:
            name = "matern52"
        elif type(correlation) is RBF:  # Matern derives from RBF
            name = "rbf"
        else:
            raise ValueError(f"no process file for the kernel {correlation!r}")
        return cls(
            features=features,
            log_inputs=pipeline_log_columns(pipeline),
            x_mean=scaler.mean_,
            x_scale=scaler.scale_,
            x_train=gp.X_train_,
            alpha=gp.alpha_,
            length_scales=kernel.k1.k2.length_scale,
            signal_variance=kernel.k1.k1.constant_value,
            y_mean=float(np.atleast_1d(gp._y_train_mean)[0]),
            y_std=float(np.atleast_1d(gp._y_train_std)[0]),
            kernel=name,
        )

    def _standardised(self, X: np.ndarray) -> np.ndarray:
        return (take_logs(X, self.log_inputs) - self.x_mean) / self.x_scale

    def predict(self, X: npt.ArrayLike) -> np.ndarray:
        """Posterior mean, float64.

        Parameters
        ----------
        X : array_like, shape (n, d)
            Inputs in SI units, in the order of `features`.

        Returns
        -------
        numpy.ndarray, shape (n,)
            Units of the bulk value.
        """
        xs = self._standardised(np.asarray(X, dtype=np.float64)) / self.length_scales
        xt = self.x_train / self.length_scales
        sq = (xs**2).sum(1)[:, None] + (xt**2).sum(1)[None, :] - 2.0 * xs @ xt.T
        k = self.signal_variance * _correlation(np.maximum(sq, 0.0), self.kernel)
        return self.y_mean + self.y_std * (k @ self.alpha)

    def predict_torch(self, X: torch.Tensor, chunk_size: int = 32_768) -> torch.Tensor:
        """Posterior mean of many rows in float32, for screening candidate grids.

        Parameters
        ----------
        X : torch.Tensor, shape (n, d)
            Inputs in SI units (log columns as they are); not modified.
        chunk_size : int, default 32768
            Rows per chunk; bounds the kernel buffer to chunk_size x n_train floats.

        Returns
        -------
        torch.Tensor of float32, shape (n,)
        """
        # float64 inside: the weights of a nearly noise-free process are large and of both
        # signs, so float32 kernels lose digits in the sum.
        scale = self.x_scale * self.length_scales
        shift = torch.from_numpy(self.x_mean / scale)
        inv = torch.from_numpy(1.0 / scale)
        xt = torch.from_numpy(self.x_train / self.length_scales)
        xt_sq = (xt**2).sum(1)
        weights = torch.from_numpy(self.signal_variance * self.y_std * self.alpha)

        def posterior_mean(chunk: torch.Tensor) -> torch.Tensor:
            xs = chunk * inv - shift
            sq = (xs**2).sum(1, keepdim=True) + xt_sq - 2.0 * xs @ xt.T
            return _correlation(sq.clamp_min_(0.0), self.kernel) @ weights + self.y_mean

        return evaluate_in_chunks(
            X, len(self.features), self.log_inputs, chunk_size, posterior_mean
        )

    def to_dict(self) -> dict[str, Any]:
        """JSON-serialisable description (every number as a Python float)."""
        return {
            "format": PROCESS_FORMAT,
            "features": self.features,
            "log_inputs": list(self.log_inputs),
            "x_mean": self.x_mean.tolist(),
            "x_scale": self.x_scale.tolist(),
            "x_train": self.x_train.tolist(),
            "alpha": self.alpha.tolist(),
            "length_scales": self.length_scales.tolist(),
            "signal_variance": self.signal_variance,
            "y_mean": self.y_mean,
            "y_std": self.y_std,
            "kernel": self.kernel,
        }

    def save(self, path: str | Path, metadata: dict[str, Any] | None = None) -> Path:
        """Write the process as JSON (``metadata`` under its own key)."""
        return write_surrogate_json(path, self.to_dict(), metadata)

    @classmethod
    def load(cls, path: str | Path) -> ProcessSurrogate:
        """Read a process written by `save`.

        Raises
        ------
        ValueError
            If the file is not a process of this format, names an unknown kernel or its arrays
            disagree in shape.
        """
        keys = (
            "features",
            "log_inputs",
            "x_mean",
            "x_scale",
            "x_train",
            "alpha",
            "length_scales",
            "signal_variance",
            "y_mean",
            "y_std",
        )
        return cls(
            **read_surrogate_json(
                path, PROCESS_FORMAT, "Gaussian-process", keys, optional={"kernel": "rbf"}
            )
        )
