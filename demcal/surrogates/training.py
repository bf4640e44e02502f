"""Training the surrogate of one bulk value: the hidden-size sweep, the baselines, the
cross-validation by parameter set, Table 4 and the Gaussian process and linear regression that
may screen instead of the network (``surrogate.screen_with``)."""

import json
import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from demcal.bulk.dataset import PARAMETERS, training_rows
from demcal.core.experiments import Experiment
from demcal.core.provenance import write_sidecar
from demcal.surrogates.baselines import (
    baseline_predictions,
    bayesian_linear_regression,
    gaussian_process_regression,
)
from demcal.surrogates.cross_validation import (
    METHODS,
    CrossValidation,
    cross_validate,
    effective_folds,
    set_counts,
)
from demcal.surrogates.data_split import split_groups
from demcal.surrogates.figures import parity_plot, r2_vs_hidden_size
from demcal.surrogates.hidden_size_sweep import SweepResult, sweep_hidden_sizes
from demcal.surrogates.linear_surrogate import LinearSurrogate
from demcal.surrogates.log_inputs import log_columns
from demcal.surrogates.metrics import regression_metrics
from demcal.surrogates.network import MLPSurrogate
from demcal.surrogates.process_surrogate import ProcessSurrogate
from demcal.surrogates.table4 import (
    SPLIT_PARTS,
    acceptance_reference,
    method_rows,
    section_markdown,
)
from demcal.surrogates.table4 import write_table4_document as write_table4_document

_log = logging.getLogger(__name__)

#: The Gaussian process of a bulk value, written beside its network (``model.pt``).
PROCESS_FILE = "process.json"
#: The linear regression of a bulk value, beside its network.
LINEAR_FILE = "linear.json"
#: Table 4 method of each ``surrogate.screen_with`` choice; ``best`` picks among them in this
#: order of preference on a tie.
SCREENING_METHODS = {"network": "ANN", "process": "Gaussian", "linear": "Bayesian"}
#: Methods that ``best`` takes only where their CV RMSE is below the acceptance tolerance: a
#: plane imposes straight lines on the whole box, and where it misses by more than the band it
#: screens with, its slopes (spurious ones included) decide which sets pass.
RESTRICTED_METHODS = ("Bayesian",)

#: Candidate inputs per bulk value (paper section "Artificial Neural Networks").
SHEAR_INPUTS = (*PARAMETERS, "normal_stress", "P")
REPOSE_INPUTS = SHEAR_INPUTS[:-2]
INPUTS = {
    "mu_psh": SHEAR_INPUTS,
    "mu_sh": SHEAR_INPUTS,
    "rho_b": SHEAR_INPUTS,
    "aor": REPOSE_INPUTS,
}
TEST_OF = {
    "mu_psh": "shear_cell",
    "mu_sh": "shear_cell",
    "rho_b": "shear_cell",
    "aor": "angle_of_repose",
}


def varying_features(data: pd.DataFrame, candidates: Sequence[str]) -> list[str]:
    """Inputs present in ``data`` that take more than one value (constants carry no information)."""
    return [c for c in candidates if c in data and data[c].nunique(dropna=True) > 1]


@dataclass
class TrainedSurrogate:
    """Outcome of :func:`train_output`.

    Attributes
    ----------
    output : str
        The bulk value.
    features : list of str
        The network's ordered inputs.
    sweep : SweepResult
        The hidden-size sweep on the single split; ``sweep.model`` is the saved network.
    table4 : pandas.DataFrame
        The Table 4 rows (:func:`demcal.surrogates.table4.method_rows`), one per method.
    n_samples : int
        Usable rows.
    cv : CrossValidation or None
        The cross-validation by parameter set, None when off or skipped.
    cv_note : str
        Why the fold count differs from ``surrogate.cv_folds`` (empty if it does not).
    """

    output: str
    features: list[str]
    sweep: SweepResult
    table4: pd.DataFrame
    n_samples: int
    cv: CrossValidation | None = None
    cv_note: str = ""


def train_output(
    data: pd.DataFrame, output: str, settings: Mapping[str, Any], out_dir: str | Path
) -> TrainedSurrogate:
    """Train and evaluate the network of ``output`` and its baselines; write all artifacts.

    The saved network comes from the hidden-size sweep on one split by parameter set
    (``surrogate.split``): trained on the training sets, early-stopped on the generalisation
    sets, scored on the test sets. The same network size and settings, and the baselines, are
    then cross-validated with ``surrogate.cv_folds`` folds by parameter set
    (:func:`demcal.surrogates.cross_validation.cross_validate`); a fold count larger than the
    usable sets allow is clamped with a logged warning
    (:func:`demcal.surrogates.cross_validation.effective_folds`).

    Parameters
    ----------
    data : DataFrame
        The tidy bulk dataset (one row per case and load condition, ``design_id`` naming the
        parameter set).
    output : {"mu_psh", "mu_sh", "rho_b", "aor"}
    settings : mapping
        The ``surrogate`` config section (``hidden_sizes``, ``split``, ``seed``,
        ``max_epochs``, ``patience``, ``cv_folds``).
    out_dir : path
        Receives model.pt (+ .json sidecar), process.json (the Gaussian process on all usable
        rows, :class:`demcal.surrogates.process_surrogate.ProcessSurrogate`), sweep.csv,
        table4.csv/.md, cv_folds.csv (one row per fold and method; only a header without
        cross-validation) and the figures.

    Raises
    ------
    ValueError
        When fewer than 6 usable samples or 3 parameter sets exist (no meaningful split), or
        ``cv_folds`` is 1 or negative.
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    rows = training_rows(data, TEST_OF[output], output)
    if len(rows) < 6:
        raise ValueError(
            f"{output}: only {len(rows)} usable DEM results; at least 6 are needed to train"
        )
    features = varying_features(rows, INPUTS[output])
    X = rows[features].to_numpy(dtype=float)
    y = rows[output].to_numpy(dtype=float)
    groups = rows["design_id"].astype(str).to_numpy()
    seed = int(settings["seed"])
    n_folds, cv_note = effective_folds(settings["cv_folds"], int(np.unique(groups).size))
    if cv_note:
        _log.warning("%s: %s", output, cv_note)
    # Split by parameter set: the load conditions of one set are not independent samples.
    train, val, test = split_groups(groups, seed, tuple(settings["split"]))
    lo, hi = settings["hidden_sizes"]
    logs = log_columns(features)
    mlp_params = {"max_epochs": int(settings["max_epochs"]), "patience": int(settings["patience"])}
    sweep = sweep_hidden_sizes(
        X, y, train, val, test, sizes=range(lo, hi + 1), seed=seed, log_inputs=logs, **mlp_params
    )
    sweep.table.to_csv(out_dir / "sweep.csv", index=False)
    predictions = baseline_predictions(X[train], y[train], X[test], seed, log_inputs=logs)
    predictions["ANN"] = sweep.model.predict(X[test])
    test_metrics = {m: regression_metrics(y[test], predictions[m]) for m in METHODS}
    cv = None
    if n_folds:
        cv = cross_validate(
            X,
            y,
            groups,
            n_folds,
            hidden_size=sweep.selected_size,
            seed=seed,
            split=tuple(settings["split"]),
            log_inputs=logs,
            **mlp_params,
        )
        cv_table = cv.folds
    else:
        cv_table = pd.DataFrame(columns=["fold", "method"])
    cv_table.to_csv(out_dir / "cv_folds.csv", index=False, float_format="%.6g")
    # The process that may screen (surrogate.screen_with) learns from every usable row; its
    # white-noise term is the scatter that caps every method's R^2 (Table 4).
    process = gaussian_process_regression(seed, log_inputs=logs).fit(X, y)
    noise_sd = float(np.sqrt(process.named_steps["regressor"].noise_variance_))
    parts = (train, val, test)
    counts = {name: set_counts(groups, part) for name, part in zip(SPLIT_PARTS, parts, strict=True)}
    table4 = method_rows(
        output,
        counts,
        test_metrics,
        cv,
        cv_note,
        float(np.mean(y)),
        sweep.selected_size,
        noise_sd=noise_sd,
        y_var=float(np.var(y)),
    )
    table4.to_csv(out_dir / "table4.csv", float_format="%.6g")
    (out_dir / "table4.md").write_text(section_markdown(output, table4, sweep.table))
    for method in METHODS:
        parity_plot(
            y[test],
            predictions[method],
            f"{method} ({output})",
            out_dir / f"parity_{method.lower()}.png",
        )
    r2_vs_hidden_size(sweep.table, out_dir / "r2_vs_hidden_size.png")
    ProcessSurrogate.from_pipeline(process, features).save(
        out_dir / PROCESS_FILE, metadata={"output": output, "n_samples": len(rows)}
    )
    plane = bayesian_linear_regression(logs).fit(X, y)
    LinearSurrogate.from_pipeline(plane, features).save(
        out_dir / LINEAR_FILE, metadata={"output": output, "n_samples": len(rows)}
    )
    cv_metrics = {}
    if cv is not None:
        ann = table4.loc["ANN"]
        cv_metrics = {
            "folds": int(ann["cv_folds"]),
            "sets": int(ann["cv_sets"]),
            "rows": int(ann["cv_rows"]),
            **{k: float(ann[f"cv_{k}"]) for k in ("r2", "rmse", "mae", "mse")},
        }
    sweep.model.save(
        out_dir / "model.pt",
        metadata={
            "output": output,
            "features": features,
            "log_features": [features[k] for k in logs],
            "n_samples": len(rows),
            "split_sizes": [len(train), len(val), len(test)],
            "split_sets": [counts[p][0] for p in SPLIT_PARTS],
            "selected_size": int(sweep.selected_size),
            "paper_rule_size": int(sweep.paper_rule_size),
            "test_metrics": {k: float(v) for k, v in test_metrics["ANN"].items()},
            "cv_metrics": cv_metrics,
        },
    )
    return TrainedSurrogate(output, features, sweep, table4, len(rows), cv, cv_note)


def train_from_dataset(
    dataset: str | Path,
    output: str,
    settings: Mapping[str, Any],
    model: str | Path,
    config: Mapping[str, Any],
) -> TrainedSurrogate:
    """Train the surrogate of ``output`` on the dataset file (:func:`train_output`).

    Parameters
    ----------
    dataset : path
        The tidy bulk dataset (CSV).
    output : {"mu_psh", "mu_sh", "rho_b", "aor"}
        The bulk value.
    settings : mapping
        The ``surrogate`` config section.
    model : path
        The network file (``model.pt``); every other artifact goes beside it, Table 4 with a
        provenance sidecar ``table4.csv.json``.
    config : mapping
        The validated configuration (for the sidecar).
    """
    trained = train_output(pd.read_csv(dataset), output, settings, Path(model).parent)
    write_sidecar(Path(model).parent / "table4.csv", config, seed=int(settings["seed"]))
    return trained


def load_surrogate(path: str | Path) -> tuple[MLPSurrogate, list[str]]:
    """A saved network and its ordered input names."""
    model = MLPSurrogate.load(path)
    meta = json.loads(Path(f"{path}.json").read_text())
    features = meta.get("metadata", {}).get("features")
    if features is None:
        raise ValueError(f"{path}.json: no feature list in the sidecar")
    return model, list(features)


def screening_method(table4: pd.DataFrame, choice: str, tolerance: float | None = None) -> str:
    """The Table 4 method (``"ANN"``, ``"Gaussian"`` or ``"Bayesian"``) that screens a bulk
    value.

    Parameters
    ----------
    table4 : DataFrame
        The bulk value's Table 4 rows (index: method; columns ``cv_r2``, ``cv_rmse``).
    choice : {"network", "process", "linear", "best"}
        ``surrogate.screen_with``; ``best`` takes the highest cross-validated R^2 of the
        network, the process and, where its CV RMSE is below ``tolerance``, the linear
        regression (:data:`RESTRICTED_METHODS`); the earlier of :data:`SCREENING_METHODS` on a
        tie and the network without cross-validation.
    tolerance : float, optional
        The acceptance band of the screening in units of the bulk value
        (``screening.tolerance`` times the measured value); without it ``best`` leaves the
        linear regression out.

    Returns
    -------
    str
    """
    if choice in SCREENING_METHODS:
        return SCREENING_METHODS[choice]
    if choice != "best":
        names = ", ".join([*SCREENING_METHODS, "best"])
        raise ValueError(f"surrogate.screen_with: {choice!r} is none of {names}")
    best, best_r2 = "ANN", -np.inf
    for method in SCREENING_METHODS.values():
        if method not in table4.index:
            continue
        r2, rmse = (float(table4.loc[method, k]) for k in ("cv_r2", "cv_rmse"))
        if method in RESTRICTED_METHODS and not (tolerance is not None and rmse < tolerance):
            continue
        if np.isfinite(r2) and r2 > best_r2:
            best, best_r2 = method, r2
    return best


def load_screening_surrogate(
    model_path: str | Path,
    choice: str,
    experiment: Experiment | None = None,
    tolerance: float | None = None,
) -> tuple[MLPSurrogate | ProcessSurrogate | LinearSurrogate, list[str], str]:
    """The surrogate that screens one bulk value, from the files of its training.

    Parameters
    ----------
    model_path : path
        The network (``model.pt``); Table 4 (``table4.csv``), the process
        (:data:`PROCESS_FILE`) and the linear regression (:data:`LINEAR_FILE`) lie beside it.
    choice : {"network", "process", "linear", "best"}
        ``surrogate.screen_with`` (:func:`screening_method`).
    experiment : Experiment, optional
        The measurements the grid is screened against, and
    tolerance : float, optional
        ``screening.tolerance`` (relative): with both, ``best`` may take the linear regression
        where its CV RMSE is below the acceptance band (the tolerance times the measured
        value, or times the data mean for a value that is not measured; Table 4's
        ``tolerance_abs``).

    Returns
    -------
    model : MLPSurrogate, ProcessSurrogate or LinearSurrogate
        Has ``predict_torch``.
    features : list of str
        Its ordered input names.
    method : str
        ``"ANN"``, ``"Gaussian"`` or ``"Bayesian"``.
    """
    model, features = load_surrogate(model_path)
    folder = Path(model_path).parent
    method = "ANN"
    if choice != "network":
        table4 = pd.read_csv(folder / "table4.csv", index_col=0)
        band = None
        if tolerance is not None:
            y_mean = float(table4["y_mean"].iloc[0])
            band = (
                tolerance
                * acceptance_reference(str(table4["output"].iloc[0]), experiment, y_mean)[0]
            )
        method = screening_method(table4, choice, band)
    if method == "ANN":
        return model, features, method
    if method == "Gaussian":
        path, other = folder / PROCESS_FILE, ProcessSurrogate.load(folder / PROCESS_FILE)
    else:
        path, other = folder / LINEAR_FILE, LinearSurrogate.load(folder / LINEAR_FILE)
    if other.features != features:
        raise ValueError(f"{path}: inputs {other.features} differ from the network's {features}")
    return other, features, method
