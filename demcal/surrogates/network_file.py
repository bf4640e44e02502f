"""Saved networks: a ``torch.save`` file of plain tensors and numbers plus a JSON sidecar.

The weight file holds the estimator parameters, the weights, the input and output scalers and
the training summary; ``torch.load(weights_only=True)`` reads it without running code. The
sidecar ``<file>.json`` records the file's SHA-256, the hidden size, seed, feature names,
training summary, package versions and caller metadata.
"""

from __future__ import annotations

import hashlib
import json
import platform
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import sklearn
import torch
from sklearn.utils.validation import check_is_fitted

if TYPE_CHECKING:
    from demcal.surrogates.network import MLPSurrogate

MODEL_FORMAT = "demcal.MLPSurrogate/1"
"""Identifier stored in every saved network file."""

_WEIGHT_KEYS = ("W1", "b1", "w2", "b2", "x_mean", "x_scale", "y_mean", "y_scale")


def save_network(
    model: MLPSurrogate, path: str | Path, metadata: dict[str, Any] | None = None
) -> Path:
    """Write weights and scalers to `path` and a JSON description to ``<path>.json``.

    Parameters
    ----------
    model : MLPSurrogate
        A fitted network.
    path : str or Path
        Weight file (a ``torch.save`` of a plain dict of tensors and numbers).
    metadata : dict, optional
        JSON-serialisable extras for the sidecar (target name, test metrics, config hash).

    Returns
    -------
    Path
        The weight file.
    """
    check_is_fitted(model, "W1_")
    path = Path(path)
    # Plain Python numbers only: torch.load(weights_only=True) and JSON reject numpy scalars.
    params: dict[str, Any] = {}
    for key, value in model.get_params().items():
        if isinstance(value, bool | np.bool_):
            params[key] = bool(value)
        elif isinstance(value, int | np.integer):
            params[key] = int(value)
        elif isinstance(value, float | np.floating):
            params[key] = float(value)
        elif key == "log_inputs":
            params[key] = [int(c) for c in value]
        elif key == "random_state":
            # A RandomState (or None) cannot reproduce the fit; the seed it gave can.
            params[key] = int(model.seed_)
        else:
            params[key] = value
    features = (
        [str(name) for name in model.feature_names_in_]
        if hasattr(model, "feature_names_in_")
        else None
    )
    state: dict[str, Any] = {
        "format": MODEL_FORMAT,
        "params": params,
        "n_features_in": int(model.n_features_in_),
        "feature_names": features,
        "seed": int(model.seed_),
        "training": model.training_metrics(),
        "W1": torch.from_numpy(model.W1_.copy()),
        "b1": torch.from_numpy(model.b1_.copy()),
        "w2": torch.from_numpy(model.w2_.copy()),
        "b2": torch.tensor(model.b2_, dtype=torch.float64),
        "x_mean": torch.from_numpy(np.asarray(model.x_mean_, dtype=np.float64).copy()),
        "x_scale": torch.from_numpy(np.asarray(model.x_scale_, dtype=np.float64).copy()),
        "y_mean": torch.tensor(model.y_mean_, dtype=torch.float64),
        "y_scale": torch.tensor(model.y_scale_, dtype=torch.float64),
    }
    path.parent.mkdir(parents=True, exist_ok=True)
    torch.save(state, path)
    sidecar = {
        "model_file": path.name,
        "format": MODEL_FORMAT,
        "sha256": hashlib.sha256(path.read_bytes()).hexdigest(),
        "hidden_size": int(model.hidden_size),
        "random_state": params["random_state"],
        "seed": int(model.seed_),
        "params": params,
        "n_features_in": int(model.n_features_in_),
        "feature_names": features,
        "training": model.training_metrics(),
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


def load_network(cls: type[MLPSurrogate], path: str | Path) -> MLPSurrogate:
    """Read a network written by `save`.

    Parameters
    ----------
    cls : type
        The estimator class to build (:class:`~demcal.surrogates.network.MLPSurrogate`).
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
    params = dict(state["params"])
    if "log_inputs" in params:
        params["log_inputs"] = tuple(int(c) for c in params["log_inputs"])
    model = cls(**params)
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
