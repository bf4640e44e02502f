"""Add the named effect: the extended training data and its surrogates (discrepancy step 3).

The extended model has the candidate's magnitude as one more input. Its training data are the
runs of the extended design, plus two kinds of runs that already exist and are exact samples of
the extended model: the current design's runs (the effect absent, i.e. the magnitude at its
"absent" value) and the probe runs at theta* (the reference and the winner's levels).
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import pandas as pd

from demcal.bulk.dataset import usable
from demcal.core.provenance import write_sidecar
from demcal.discrepancy.candidates import Candidate
from demcal.discrepancy.run_results import read_runs
from demcal.discrepancy.runs import named_candidate
from demcal.surrogates.data_split import split_indices
from demcal.surrogates.hidden_size_sweep import sweep_hidden_sizes
from demcal.surrogates.log_inputs import log_columns
from demcal.surrogates.metrics import regression_metrics
from demcal.surrogates.training import INPUTS, TEST_OF, varying_features

__all__ = [
    "extended_training_data",
    "train_extended_surrogate",
    "write_extended_dataset",
]


def extended_training_data(
    base: pd.DataFrame,
    probes: pd.DataFrame,
    extended: pd.DataFrame,
    candidate: Candidate,
    tests: Sequence[str],
) -> pd.DataFrame:
    """The training rows of the extended model, with the magnitude column filled everywhere.

    Parameters
    ----------
    base : DataFrame
        The current design's tidy dataset (effect absent).
    probes : DataFrame
        Probe runs (:func:`demcal.discrepancy.run_results.read_runs`); the reference and the
        candidate's levels are kept.
    extended : DataFrame
        Runs of the extended design (:func:`demcal.discrepancy.run_results.read_runs`).
    candidate : Candidate
        The added effect.
    tests : sequence of str
        Tests to keep.

    Returns
    -------
    DataFrame
        Rows of all three sources with a ``source`` column (base, probe, extended).
    """
    param = candidate.parameter

    def absent(frame: pd.DataFrame) -> pd.Series:
        if isinstance(candidate.off_value, str):
            return frame[candidate.off_value].astype(float)
        return pd.Series(float(candidate.off_value), index=frame.index)

    parts = []
    if len(base):
        b = base[base["test"].isin(tests)].copy()
        b[param] = absent(b)
        parts.append(b.assign(source="base"))
    if len(probes):
        kept = probes[probes["discrepancy_candidate"].isin(["none", candidate.name])].copy()
        kept = kept[kept["test"].isin(tests)]
        off = kept["discrepancy_candidate"] == "none"
        kept.loc[off, param] = absent(kept[off])
        parts.append(kept.assign(source="probe"))
    if len(extended):
        parts.append(extended[extended["test"].isin(tests)].assign(source="extended"))
    if not parts:
        raise ValueError("extended model: no training rows")
    data = pd.concat(parts, ignore_index=True, sort=False)
    if data[param].isna().any():
        raise ValueError(f"extended model: rows without a value of {param!r}")
    return data


def write_extended_dataset(
    config: Mapping[str, Any],
    ranking_record_path: str | Path,
    dataset_path: str | Path,
    probe_files: Iterable[str | Path],
    extended_files: Iterable[str | Path],
    tests: Sequence[str],
    out_path: str | Path,
) -> pd.DataFrame:
    """Write the training data of the model extended by the named effect (with sidecar).

    Parameters
    ----------
    config : mapping
        The validated configuration.
    ranking_record_path : path
        Record of the ranking (its ``winner`` is the added effect).
    dataset_path : path
        The current design's tidy dataset.
    probe_files, extended_files : iterable of path
        ``bulk.csv`` of the probe runs and of the extended design's runs.
    tests : sequence of str
        Tests to keep.
    out_path : path
        The CSV to write.

    Returns
    -------
    DataFrame
        The rows written (:func:`extended_training_data`).
    """
    candidate = named_candidate(config, ranking_record_path)
    data = extended_training_data(
        pd.read_csv(dataset_path),
        read_runs(probe_files),
        read_runs(extended_files),
        candidate,
        list(tests),
    )
    data.to_csv(out_path, index=False, float_format="%.10g")
    write_sidecar(out_path, config, extra={"rows": len(data)})
    return data


def train_extended_surrogate(
    data: pd.DataFrame,
    output: str,
    settings: Mapping[str, Any],
    extra_inputs: Sequence[str],
    model_path: str | Path,
) -> dict[str, Any]:
    """Train the network of one bulk value of the extended model and save it.

    The inputs are those of :data:`demcal.surrogates.training.INPUTS` plus ``extra_inputs`` that
    vary in
    the data; the hidden-size sweep, split and selection are those of the main surrogates
    (the ``surrogate`` config section).

    Returns
    -------
    dict
        The metadata written into the model's sidecar (features, sizes, test metrics).

    Raises
    ------
    ValueError
        When fewer than 6 usable rows exist.
    """
    rows = usable(data[data["test"] == TEST_OF[output]], output)
    if len(rows) < 6:
        raise ValueError(f"{output}: only {len(rows)} usable runs for the extended model")
    candidates = list(INPUTS[output]) + [e for e in extra_inputs if e not in INPUTS[output]]
    features = varying_features(rows, candidates)
    X = rows[features].to_numpy(dtype=float)
    y = rows[output].to_numpy(dtype=float)
    seed = int(settings["seed"])
    train, val, test = split_indices(len(rows), seed, tuple(settings["split"]))
    lo, hi = settings["hidden_sizes"]
    sweep = sweep_hidden_sizes(
        X,
        y,
        train,
        val,
        test,
        sizes=range(int(lo), int(hi) + 1),
        seed=seed,
        max_epochs=int(settings["max_epochs"]),
        patience=int(settings["patience"]),
        log_inputs=log_columns(features),
    )
    metrics = regression_metrics(y[test], sweep.model.predict(X[test]))
    metadata = {
        "output": output,
        "features": features,
        "n_samples": len(rows),
        "split_sizes": [len(train), len(val), len(test)],
        "selected_size": int(sweep.selected_size),
        "test_metrics": {k: float(v) for k, v in metrics.items()},
        "sources": {str(k): int(v) for k, v in rows["source"].value_counts().items()}
        if "source" in rows
        else {},
    }
    sweep.model.save(model_path, metadata=metadata)
    return metadata


def rmse_of(model_path: str | Path) -> float:
    """Held-out RMSE of a saved surrogate: its generalisation and test sets pooled.

    Both sets are left out of the fit; pooling them halves the scatter of the estimate when
    each holds only a handful of runs (the generalisation set steers early stopping, so the
    pooled value leans slightly optimistic). Falls back to the test RMSE alone.

    Raises
    ------
    KeyError
        When the sidecar has no test metrics (names the file).
    ValueError
        When the RMSE is not finite.
    """
    sidecar = Path(f"{model_path}.json")
    record = json.loads(sidecar.read_text())
    meta = record.get("metadata", {})
    try:
        test_mse = float(meta["test_metrics"]["mse"])
        n_test = int(meta["split_sizes"][2]) if "split_sizes" in meta else 1
    except KeyError as exc:
        raise KeyError(f"{sidecar}: no metadata.test_metrics") from exc
    training = record.get("training", {})
    n_val = int(training.get("n_val", 0))
    val_mse = float(training.get("val_mse", math.nan))
    if n_val > 0 and math.isfinite(val_mse):
        value = math.sqrt((n_val * val_mse + n_test * test_mse) / (n_val + n_test))
    else:
        value = math.sqrt(test_mse)
    if not math.isfinite(value):
        raise ValueError(f"{sidecar}: held-out RMSE is not finite")
    return value
