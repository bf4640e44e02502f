"""Feed-forward neural-network surrogates of DEM bulk values.

One network per bulk value (mu_psh, mu_sh, rho_b, aor), as in Benvenuti, Kloss & Pirker: one
hidden layer of tanh units and one linear output unit, trained on 70 % of the DEM cases,
early-stopped on a 15 % generalisation set and scored on the remaining 15 % test set. The
network size is chosen by a sweep over 5..40 hidden neurons
(:mod:`demcal.surrogates.hidden_size_sweep`); the training loop is
:func:`demcal.surrogates.network_training.train_lbfgs`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import torch
from sklearn.base import BaseEstimator, RegressorMixin
from sklearn.utils import check_random_state
from sklearn.utils.validation import check_is_fitted, validate_data

from demcal.surrogates.log_inputs import take_logs
from demcal.surrogates.network_file import load_network, save_network
from demcal.surrogates.network_training import single_torch_thread, train_lbfgs


def _scale(values: np.ndarray) -> np.ndarray:
    """Standard deviation per column, with 1 where a column is constant."""
    scale = values.std(axis=0)
    return np.where(scale > 0.0, scale, 1.0)


class MLPSurrogate(RegressorMixin, BaseEstimator):
    """One-hidden-layer tanh network with a linear output, trained with early stopping.

    The prediction is ``y = y_mean + y_scale * (w2 . tanh(W1 xs + b1) + b2)`` with
    ``xs = (x' - x_mean) / x_scale``, where ``x'`` is ``x`` with the natural logarithm of the
    columns `log_inputs`; means and standard deviations come from the training data.

    Parameters
    ----------
    hidden_size : int, default 15
        Number of tanh units in the hidden layer.
    max_epochs : int, default 1000
        Maximum number of L-BFGS iterations.
    learning_rate : float, default 1.0
        Initial step length of the L-BFGS line search (1.0 is the natural quasi-Newton step).
    patience : int, default 30
        Training stops after this many epochs without a lower generalisation-set error; the
        weights of the best epoch are kept.
    alpha : float, default 0.0
        L2 penalty on the weights (not the biases), added to the standardised mean squared
        error as ``alpha * ||W||^2 / n_train``.
    validation_fraction : float, default 0.15
        Share of the training data held out for early stopping when `fit` gets no
        generalisation set.
    random_state : int, numpy RandomState or None, default 0
        Seed of the weight initialisation and of the internal hold-out split.
    log_inputs : sequence of int, default ()
        Input columns the network sees as their natural logarithm
        (:mod:`demcal.surrogates.log_inputs`); inputs are always given in SI units.

    Attributes
    ----------
    n_features_in_ : int
        Number of inputs.
    feature_names_in_ : numpy.ndarray of str, shape (n_features_in_,)
        Input names, present when `fit` got a DataFrame.
    n_epochs_ : int
        Epochs run.
    best_epoch_ : int
        Epoch whose weights were kept (0 means the initial weights).
    stopped_early_ : bool
        Whether training ended because of the patience criterion.
    train_mse_, val_mse_ : float
        Mean squared errors (units of y squared) of the kept weights on the training and
        generalisation sets.
    loss_curve_, validation_curve_ : list of float
        Training and generalisation-set mean squared error (units of y squared) after every
        epoch, starting with the initial weights.
    n_train_, n_val_ : int
        Sizes of the sets used for fitting and for early stopping.
    seed_ : int
        Torch seed derived from `random_state`.
    """

    def __init__(
        self,
        hidden_size: int = 15,
        max_epochs: int = 1000,
        learning_rate: float = 1.0,
        patience: int = 30,
        alpha: float = 0.0,
        validation_fraction: float = 0.15,
        random_state: int | np.random.RandomState | None = 0,
        log_inputs: tuple[int, ...] = (),
    ) -> None:
        self.hidden_size = hidden_size
        self.max_epochs = max_epochs
        self.learning_rate = learning_rate
        self.patience = patience
        self.alpha = alpha
        self.validation_fraction = validation_fraction
        self.random_state = random_state
        self.log_inputs = log_inputs

    # ------------------------------------------------------------------ fitting
    def _check_params(self) -> None:
        def positive_int(name: str, value: Any) -> None:
            if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < 1:
                raise ValueError(f"{name} must be a positive integer, got {value!r}")

        positive_int("hidden_size", self.hidden_size)
        positive_int("max_epochs", self.max_epochs)
        positive_int("patience", self.patience)
        if not np.isfinite(self.learning_rate) or self.learning_rate <= 0.0:
            raise ValueError(f"learning_rate must be positive, got {self.learning_rate!r}")
        if not np.isfinite(self.alpha) or self.alpha < 0.0:
            raise ValueError(f"alpha must be non-negative, got {self.alpha!r}")
        if not 0.0 < self.validation_fraction < 1.0:
            raise ValueError(
                f"validation_fraction must lie in (0, 1), got {self.validation_fraction!r}"
            )

    def _seed(self) -> int:
        if isinstance(self.random_state, int | np.integer) and not isinstance(
            self.random_state, bool
        ):
            return int(self.random_state)
        return int(check_random_state(self.random_state).randint(np.iinfo(np.int32).max))

    def fit(
        self,
        X: npt.ArrayLike,
        y: npt.ArrayLike,
        X_val: npt.ArrayLike | None = None,
        y_val: npt.ArrayLike | None = None,
    ) -> MLPSurrogate:
        """Train the network.

        Parameters
        ----------
        X : array_like or DataFrame, shape (n, n_features)
            Training inputs in SI units.
        y : array_like, shape (n,)
            Training targets (one bulk value).
        X_val : array_like or DataFrame, shape (m, n_features), optional
            Generalisation set for early stopping. Without it, a share
            `validation_fraction` of the training data is held out (when n >= 3; with fewer
            samples the training error is monitored instead).
        y_val : array_like, shape (m,), optional
            Targets of the generalisation set; required together with `X_val`.

        Returns
        -------
        MLPSurrogate
            The fitted estimator.
        """
        self._check_params()
        X_arr, y_arr = validate_data(self, X, y, dtype=np.float64, y_numeric=True)
        X_arr = take_logs(X_arr, self.log_inputs)
        n = X_arr.shape[0]
        if n < 2:
            raise ValueError(f"MLPSurrogate needs at least 2 training samples, got n_samples={n}")
        if (X_val is None) != (y_val is None):
            raise ValueError("X_val and y_val must be given together")
        seed = self._seed()
        if X_val is not None:
            Xv, yv = validate_data(
                self, X_val, y_val, reset=False, dtype=np.float64, y_numeric=True
            )
            Xv = take_logs(Xv, self.log_inputs)
            Xt, yt = X_arr, y_arr
        elif n >= 3:
            n_val = min(n - 2, max(1, round(self.validation_fraction * n)))
            order = np.random.default_rng(seed).permutation(n)
            Xt, yt = X_arr[order[n_val:]], y_arr[order[n_val:]]
            Xv, yv = X_arr[order[:n_val]], y_arr[order[:n_val]]
        else:
            Xt, yt, Xv, yv = X_arr, y_arr, X_arr, y_arr

        self.x_mean_ = Xt.mean(axis=0)
        self.x_scale_ = _scale(Xt)
        self.y_mean_ = float(yt.mean())
        self.y_scale_ = float(_scale(yt[:, None])[0])
        self.seed_ = seed
        self.n_train_ = int(Xt.shape[0])
        self.n_val_ = int(Xv.shape[0])
        with single_torch_thread():
            self._train(Xt, yt, Xv, yv, seed)
        return self

    def _train(
        self, Xt: np.ndarray, yt: np.ndarray, Xv: np.ndarray, yv: np.ndarray, seed: int
    ) -> None:
        def standardise(X: np.ndarray, y: np.ndarray) -> tuple[torch.Tensor, torch.Tensor]:
            xs = torch.from_numpy((X - self.x_mean_) / self.x_scale_)
            ys = torch.from_numpy((y - self.y_mean_) / self.y_scale_)
            return xs, ys

        xt, yt_s = standardise(Xt, yt)
        xv, yv_s = standardise(Xv, yv)
        trained = train_lbfgs(
            xt,
            yt_s,
            xv,
            yv_s,
            hidden_size=self.hidden_size,
            learning_rate=self.learning_rate,
            alpha=self.alpha,
            max_epochs=self.max_epochs,
            patience=self.patience,
            seed=seed,
        )
        var = self.y_scale_**2
        self.W1_ = trained.W1
        self.b1_ = trained.b1
        self.w2_ = trained.w2
        self.b2_ = trained.b2
        self.n_epochs_ = trained.n_epochs
        self.best_epoch_ = trained.best_epoch
        self.stopped_early_ = trained.stopped_early
        self.loss_curve_ = [float(v * var) for v in trained.loss_curve]
        self.validation_curve_ = [float(v * var) for v in trained.validation_curve]
        self.train_mse_ = self.loss_curve_[trained.best_epoch]
        self.val_mse_ = self.validation_curve_[trained.best_epoch]

    # --------------------------------------------------------------- prediction
    def _standardised_output(self, X: np.ndarray) -> np.ndarray:
        hidden = np.tanh(((X - self.x_mean_) / self.x_scale_) @ self.W1_.T + self.b1_)
        return hidden @ self.w2_ + self.b2_

    def predict(self, X: npt.ArrayLike) -> np.ndarray:
        """Predict the bulk value.

        Parameters
        ----------
        X : array_like or DataFrame, shape (n, n_features)
            Inputs in the units used for training.

        Returns
        -------
        numpy.ndarray of float64, shape (n,)
            Predictions in the units of the training target.
        """
        check_is_fitted(self, "W1_")
        X_arr = take_logs(validate_data(self, X, reset=False, dtype=np.float64), self.log_inputs)
        return self.y_mean_ + self.y_scale_ * self._standardised_output(X_arr)

    def predict_torch(self, X: torch.Tensor, chunk_size: int = 262_144) -> torch.Tensor:
        """Predict many rows at once in float32, for screening large candidate grids.

        The standardisation is folded into the weights once (in float64), so each chunk costs
        one matrix product, one tanh and one matrix-vector product.

        Parameters
        ----------
        X : torch.Tensor, shape (n, n_features_in_)
            Inputs in training units and column order (the columns `log_inputs` as they are,
            not their logarithm); converted to float32.
        chunk_size : int, default 262144
            Rows per chunk; bounds the hidden-layer buffer to chunk_size x hidden_size floats.

        Returns
        -------
        torch.Tensor of float32, shape (n,)
            Predictions in training units, without autograd history.
        """
        check_is_fitted(self, "W1_")
        if not isinstance(X, torch.Tensor):
            raise TypeError(f"predict_torch expects a torch.Tensor, got {type(X).__name__}")
        if X.ndim != 2 or X.shape[1] != self.n_features_in_:
            raise ValueError(f"X must have shape (n, {self.n_features_in_}), got {tuple(X.shape)}")
        if chunk_size < 1:
            raise ValueError(f"chunk_size must be positive, got {chunk_size}")
        W1 = self.W1_ / self.x_scale_
        b1 = self.b1_ - W1 @ self.x_mean_
        w2 = self.w2_ * self.y_scale_
        b2 = self.b2_ * self.y_scale_ + self.y_mean_
        W1_t = torch.from_numpy(W1.T.astype(np.float32)).to(X.device)
        b1_t = torch.from_numpy(b1.astype(np.float32)).to(X.device)
        w2_t = torch.from_numpy(w2.astype(np.float32)).to(X.device)
        logs = list(self.log_inputs)
        out = torch.empty(X.shape[0], dtype=torch.float32, device=X.device)
        with torch.no_grad():
            for start in range(0, X.shape[0], chunk_size):
                # With log columns a copy: the caller's grid must keep its SI values.
                chunk = X[start : start + chunk_size].to(torch.float32, copy=bool(logs))
                if logs:
                    chunk[:, logs] = chunk[:, logs].log()
                hidden = torch.addmm(b1_t, chunk, W1_t).tanh_()
                torch.mv(hidden, w2_t, out=out[start : start + chunk_size])
            out.add_(float(b2))
        return out

    # ------------------------------------------------------------ persistence
    def training_metrics(self) -> dict[str, float | int | bool]:
        """Training summary: set sizes, epochs and mean squared errors (units of y squared)."""
        check_is_fitted(self, "W1_")
        return {
            "n_train": self.n_train_,
            "n_val": self.n_val_,
            "n_epochs": self.n_epochs_,
            "best_epoch": self.best_epoch_,
            "stopped_early": self.stopped_early_,
            "train_mse": self.train_mse_,
            "val_mse": self.val_mse_,
        }

    def save(self, path: str | Path, metadata: dict[str, Any] | None = None) -> Path:
        """Write weights and scalers to `path` and a JSON description to ``<path>.json``.

        Parameters
        ----------
        path : str or Path
            Weight file; see :func:`demcal.surrogates.network_file.save_network`.
        metadata : dict, optional
            JSON-serialisable extras for the sidecar (target name, test metrics, config hash).

        Returns
        -------
        Path
            The weight file.
        """
        return save_network(self, path, metadata)

    @classmethod
    def load(cls, path: str | Path) -> MLPSurrogate:
        """Read a network written by `save`.

        Parameters
        ----------
        path : str or Path
            Weight file; see :func:`demcal.surrogates.network_file.load_network` for the
            errors raised.

        Returns
        -------
        MLPSurrogate
            A fitted estimator that predicts exactly as the saved one.
        """
        return load_network(cls, path)
