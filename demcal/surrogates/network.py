"""Feed-forward neural-network surrogates of DEM bulk values.

One network per bulk value (mu_psh, mu_sh, rho_b, aor), as in Benvenuti, Kloss & Pirker: one
hidden layer of tanh units and one linear output unit, trained on 70 % of the DEM cases,
early-stopped on a 15 % generalisation set and scored on the remaining 15 % test set. The
network size is chosen by a sweep over 5..40 hidden neurons.

Training uses full-batch L-BFGS with a strong-Wolfe line search in float64 (one L-BFGS
iteration is one epoch). A quasi-Newton method suits these small networks and few hundred
samples: it converges in far fewer epochs than stochastic gradient descent, much as the
Levenberg-Marquardt training customary for such networks does.
"""

from __future__ import annotations

import hashlib
import json
import platform
from collections.abc import Iterable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import pandas as pd
import sklearn
import torch
from sklearn.base import BaseEstimator, RegressorMixin
from sklearn.utils import check_random_state
from sklearn.utils.validation import check_is_fitted, validate_data

from demcal.surrogates.metrics import regression_metrics

MODEL_FORMAT = "demcal.MLPSurrogate/1"
"""Identifier stored in every saved network file."""

_WEIGHT_KEYS = ("W1", "b1", "w2", "b2", "x_mean", "x_scale", "y_mean", "y_scale")


def split_indices(
    n: int, seed: int, fractions: Sequence[float] = (0.7, 0.15, 0.15)
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Random split of ``n`` samples into training, generalisation and test indices.

    Parameters
    ----------
    n : int
        Number of samples; at least 3.
    seed : int
        Seed of the permutation; the same seed gives the same split.
    fractions : sequence of 3 floats, default (0.7, 0.15, 0.15)
        Positive shares of training, generalisation (early stopping) and test sets; they are
        normalised to sum to one.

    Returns
    -------
    train, val, test : numpy.ndarray of int64, shapes (n_train,), (n_val,), (n_test,)
        Sorted, disjoint indices that together cover ``range(n)``; each part is non-empty.
        The generalisation and test sizes are ``round(n * fraction)`` (at least 1) and the
        training set takes the rest.

    Raises
    ------
    ValueError
        If ``n < 3``, the fractions are not three positive finite numbers, or they leave the
        training set empty.
    """
    if isinstance(n, bool) or int(n) != n:
        raise ValueError(f"n must be an integer, got {n!r}")
    n = int(n)
    if n < 3:
        raise ValueError(f"split_indices needs n >= 3 to fill three sets, got n={n}")
    shares = np.asarray(fractions, dtype=np.float64)
    if shares.shape != (3,) or not np.all(np.isfinite(shares)) or np.any(shares <= 0.0):
        raise ValueError(f"fractions must be three positive numbers, got {fractions!r}")
    shares = shares / shares.sum()
    n_val = max(1, round(n * shares[1]))
    n_test = max(1, round(n * shares[2]))
    n_train = n - n_val - n_test
    if n_train < 1:
        raise ValueError(f"fractions {tuple(fractions)} leave no training samples for n={n}")
    order = np.random.default_rng(seed).permutation(n)
    train = np.sort(order[:n_train])
    val = np.sort(order[n_train : n_train + n_val])
    test = np.sort(order[n_train + n_val :])
    return train.astype(np.int64), val.astype(np.int64), test.astype(np.int64)


@contextmanager
def _single_thread() -> Iterator[None]:
    """Run torch on one intra-op thread, so that training is reproducible bit for bit."""
    previous = torch.get_num_threads()
    torch.set_num_threads(1)
    try:
        yield
    finally:
        torch.set_num_threads(previous)


def _scale(values: np.ndarray) -> np.ndarray:
    """Standard deviation per column, with 1 where a column is constant."""
    scale = values.std(axis=0)
    return np.where(scale > 0.0, scale, 1.0)


def split_groups(
    groups: Sequence[object], seed: int, fractions: Sequence[float] = (0.7, 0.15, 0.15)
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Random split that keeps all samples of a group in the same set.

    Rows that share a DEM parameter set (e.g. the load conditions of one case, whose pre-shear
    values coincide) must not be split between training and test, or the test set would
    measure memory instead of prediction.

    Parameters
    ----------
    groups : sequence, shape (n,)
        Group label of every sample.
    seed, fractions
        As in :func:`split_indices`, applied to the distinct groups.

    Returns
    -------
    train, val, test : numpy.ndarray of int64
        Sorted sample indices.
    """
    labels = np.asarray(groups)
    unique, inverse = np.unique(labels, return_inverse=True)
    parts = split_indices(len(unique), seed, fractions)
    return tuple(np.flatnonzero(np.isin(inverse, part)).astype(np.int64) for part in parts)


class MLPSurrogate(RegressorMixin, BaseEstimator):
    """One-hidden-layer tanh network with a linear output, trained with early stopping.

    The prediction is ``y = y_mean + y_scale * (w2 . tanh(W1 xs + b1) + b2)`` with
    ``xs = (x - x_mean) / x_scale``; means and standard deviations come from the training data.

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
    ) -> None:
        self.hidden_size = hidden_size
        self.max_epochs = max_epochs
        self.learning_rate = learning_rate
        self.patience = patience
        self.alpha = alpha
        self.validation_fraction = validation_fraction
        self.random_state = random_state

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
        with _single_thread():
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
        n_in, n_hidden = xt.shape[1], int(self.hidden_size)

        # Glorot-uniform weights keep the tanh units out of saturation for standardised inputs.
        gen = torch.Generator().manual_seed(seed)

        def uniform(shape: tuple[int, ...], bound: float) -> torch.Tensor:
            values = (torch.rand(shape, generator=gen, dtype=torch.float64) * 2.0 - 1.0) * bound
            return values.requires_grad_(True)

        W1 = uniform((n_hidden, n_in), float(np.sqrt(6.0 / (n_in + n_hidden))))
        b1 = uniform((n_hidden,), 0.5)
        w2 = uniform((n_hidden,), float(np.sqrt(6.0 / (n_hidden + 1))))
        b2 = torch.zeros((), dtype=torch.float64, requires_grad=True)
        params = [W1, b1, w2, b2]

        def forward(x: torch.Tensor) -> torch.Tensor:
            return torch.tanh(torch.addmm(b1, x, W1.T)) @ w2 + b2

        penalty = float(self.alpha) / xt.shape[0]
        optimiser = torch.optim.LBFGS(
            params,
            lr=float(self.learning_rate),
            max_iter=1,
            # torch derives the line-search budget from max_eval; the default (5/4 of
            # max_iter) would leave no evaluations for it.
            max_eval=25,
            history_size=20,
            tolerance_grad=1e-10,
            tolerance_change=1e-14,
            line_search_fn="strong_wolfe",
        )

        def closure() -> torch.Tensor:
            optimiser.zero_grad()
            loss = torch.mean((forward(xt) - yt_s) ** 2)
            if penalty > 0.0:
                loss = loss + penalty * (torch.sum(W1**2) + torch.sum(w2**2))
            loss.backward()
            return loss

        def errors() -> tuple[float, float]:
            with torch.no_grad():
                train = float(torch.mean((forward(xt) - yt_s) ** 2))
                val = float(torch.mean((forward(xv) - yv_s) ** 2))
            return train, val

        def snapshot() -> list[torch.Tensor]:
            return [p.detach().clone() for p in params]

        train_err, val_err = errors()
        loss_curve, val_curve = [train_err], [val_err]
        best_val, best_epoch, best = val_err, 0, snapshot()
        stopped_early = False
        epoch = 0
        for epoch in range(1, int(self.max_epochs) + 1):
            optimiser.step(closure)
            train_err, val_err = errors()
            if not (np.isfinite(train_err) and np.isfinite(val_err)):
                break
            loss_curve.append(train_err)
            val_curve.append(val_err)
            if val_err < best_val:
                best_val, best_epoch, best = val_err, epoch, snapshot()
            elif epoch - best_epoch >= int(self.patience):
                stopped_early = True
                break
            # L-BFGS has converged when a step no longer changes the training error.
            if abs(loss_curve[-2] - train_err) <= 1e-14 * max(1.0, train_err):
                break

        var = self.y_scale_**2
        self.W1_ = best[0].numpy().copy()
        self.b1_ = best[1].numpy().copy()
        self.w2_ = best[2].numpy().copy()
        self.b2_ = float(best[3])
        self.n_epochs_ = int(epoch)
        self.best_epoch_ = int(best_epoch)
        self.stopped_early_ = bool(stopped_early)
        self.loss_curve_ = [float(v * var) for v in loss_curve]
        self.validation_curve_ = [float(v * var) for v in val_curve]
        self.train_mse_ = self.loss_curve_[best_epoch]
        self.val_mse_ = self.validation_curve_[best_epoch]

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
        X_arr = validate_data(self, X, reset=False, dtype=np.float64)
        return self.y_mean_ + self.y_scale_ * self._standardised_output(X_arr)

    def predict_torch(self, X: torch.Tensor, chunk_size: int = 262_144) -> torch.Tensor:
        """Predict many rows at once in float32, for screening large candidate grids.

        The standardisation is folded into the weights once (in float64), so each chunk costs
        one matrix product, one tanh and one matrix-vector product.

        Parameters
        ----------
        X : torch.Tensor, shape (n, n_features_in_)
            Inputs in training units and column order; converted to float32.
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
        out = torch.empty(X.shape[0], dtype=torch.float32, device=X.device)
        with torch.no_grad():
            for start in range(0, X.shape[0], chunk_size):
                chunk = X[start : start + chunk_size].to(torch.float32)
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
            Weight file (a ``torch.save`` of a plain dict of tensors and numbers).
        metadata : dict, optional
            JSON-serialisable extras for the sidecar (target name, test metrics, config hash).

        Returns
        -------
        Path
            The weight file.
        """
        check_is_fitted(self, "W1_")
        path = Path(path)
        # Plain Python numbers only: torch.load(weights_only=True) and JSON reject numpy scalars.
        params: dict[str, Any] = {}
        for key, value in self.get_params().items():
            if isinstance(value, bool | np.bool_):
                params[key] = bool(value)
            elif isinstance(value, int | np.integer):
                params[key] = int(value)
            elif isinstance(value, float | np.floating):
                params[key] = float(value)
            elif key == "random_state":
                # A RandomState (or None) cannot reproduce the fit; the seed it gave can.
                params[key] = int(self.seed_)
            else:
                params[key] = value
        features = (
            [str(name) for name in self.feature_names_in_]
            if hasattr(self, "feature_names_in_")
            else None
        )
        state: dict[str, Any] = {
            "format": MODEL_FORMAT,
            "params": params,
            "n_features_in": int(self.n_features_in_),
            "feature_names": features,
            "seed": int(self.seed_),
            "training": self.training_metrics(),
            "W1": torch.from_numpy(self.W1_.copy()),
            "b1": torch.from_numpy(self.b1_.copy()),
            "w2": torch.from_numpy(self.w2_.copy()),
            "b2": torch.tensor(self.b2_, dtype=torch.float64),
            "x_mean": torch.from_numpy(np.asarray(self.x_mean_, dtype=np.float64).copy()),
            "x_scale": torch.from_numpy(np.asarray(self.x_scale_, dtype=np.float64).copy()),
            "y_mean": torch.tensor(self.y_mean_, dtype=torch.float64),
            "y_scale": torch.tensor(self.y_scale_, dtype=torch.float64),
        }
        path.parent.mkdir(parents=True, exist_ok=True)
        torch.save(state, path)
        sidecar = {
            "model_file": path.name,
            "format": MODEL_FORMAT,
            "sha256": hashlib.sha256(path.read_bytes()).hexdigest(),
            "hidden_size": int(self.hidden_size),
            "random_state": params["random_state"],
            "seed": int(self.seed_),
            "params": params,
            "n_features_in": int(self.n_features_in_),
            "feature_names": features,
            "training": self.training_metrics(),
            "versions": {
                "python": platform.python_version(),
                "torch": torch.__version__,
                "numpy": np.__version__,
                "sklearn": sklearn.__version__,
            },
        }
        if metadata:
            sidecar["metadata"] = metadata
        Path(f"{path}.json").write_text(json.dumps(sidecar, indent=2) + "\n")
        return path

    @classmethod
    def load(cls, path: str | Path) -> MLPSurrogate:
        """Read a network written by `save`.

        Parameters
        ----------
        path : str or Path
            Weight file; the JSON sidecar is not needed.

        Returns
        -------
        MLPSurrogate
            A fitted estimator that predicts exactly as the saved one.

        Raises
        ------
        FileNotFoundError
            If `path` does not exist.
        KeyError
            If the file lacks an entry.
        ValueError
            If the file is not a saved network or its arrays are inconsistent.
        """
        path = Path(path)
        if not path.is_file():
            raise FileNotFoundError(f"no saved network at {path}")
        try:
            state = torch.load(path, weights_only=True)
        except Exception as error:
            raise ValueError(f"{path}: not a readable torch file ({error})") from error
        if not isinstance(state, dict) or state.get("format") != MODEL_FORMAT:
            raise ValueError(f"{path}: not a {MODEL_FORMAT} file")
        for key in (*_WEIGHT_KEYS, "params", "n_features_in", "seed", "training"):
            if key not in state:
                raise KeyError(f"{path}: missing entry {key!r}")
        model = cls(**state["params"])
        model.n_features_in_ = int(state["n_features_in"])
        if state.get("feature_names") is not None:
            model.feature_names_in_ = np.asarray(state["feature_names"], dtype=object)
        model.seed_ = int(state["seed"])
        model.W1_ = state["W1"].numpy().astype(np.float64)
        model.b1_ = state["b1"].numpy().astype(np.float64)
        model.w2_ = state["w2"].numpy().astype(np.float64)
        model.b2_ = float(state["b2"])
        model.x_mean_ = state["x_mean"].numpy().astype(np.float64)
        model.x_scale_ = state["x_scale"].numpy().astype(np.float64)
        model.y_mean_ = float(state["y_mean"])
        model.y_scale_ = float(state["y_scale"])
        d, h = model.n_features_in_, int(model.hidden_size)
        shapes = {
            "W1": (model.W1_.shape, (h, d)),
            "b1": (model.b1_.shape, (h,)),
            "w2": (model.w2_.shape, (h,)),
            "x_mean": (model.x_mean_.shape, (d,)),
            "x_scale": (model.x_scale_.shape, (d,)),
        }
        for key, (found, expected) in shapes.items():
            if found != expected:
                raise ValueError(f"{path}: entry {key!r} has shape {found}, expected {expected}")
        training = state["training"]
        model.n_train_ = int(training["n_train"])
        model.n_val_ = int(training["n_val"])
        model.n_epochs_ = int(training["n_epochs"])
        model.best_epoch_ = int(training["best_epoch"])
        model.stopped_early_ = bool(training["stopped_early"])
        model.train_mse_ = float(training["train_mse"])
        model.val_mse_ = float(training["val_mse"])
        return model


# ---------------------------------------------------------------------- sweep
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
