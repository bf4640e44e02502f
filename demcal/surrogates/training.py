"""Training the surrogate of one bulk value: the hidden-size sweep, the baselines, Table 4."""

import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd

from demcal.bulk.dataset import PARAMETERS, usable
from demcal.core.provenance import write_sidecar
from demcal.surrogates.baselines import bayesian_linear_regression, gaussian_process_regression
from demcal.surrogates.data_split import split_groups
from demcal.surrogates.figures import parity_plot, r2_vs_hidden_size
from demcal.surrogates.hidden_size_sweep import (
    SweepResult,
    select_by_test_r2,
    select_by_validation,
    sweep_hidden_sizes,
)
from demcal.surrogates.metrics import method_comparison_table, regression_metrics, to_markdown
from demcal.surrogates.network import MLPSurrogate

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
METHODS = ("Bayesian", "Gaussian", "ANN")


def varying_features(data: pd.DataFrame, candidates: Sequence[str]) -> list[str]:
    """Inputs present in ``data`` that take more than one value (constants carry no information)."""
    return [c for c in candidates if c in data and data[c].nunique(dropna=True) > 1]


@dataclass
class TrainedSurrogate:
    output: str
    features: list[str]
    sweep: SweepResult
    table4: pd.DataFrame
    n_samples: int


def train_output(
    data: pd.DataFrame, output: str, settings: Mapping[str, Any], out_dir: str | Path
) -> TrainedSurrogate:
    """Train and evaluate the network of ``output`` and its baselines; write all artifacts.

    Parameters
    ----------
    data : DataFrame
        The tidy bulk dataset.
    output : {"mu_psh", "mu_sh", "rho_b", "aor"}
    settings : mapping
        The ``surrogate`` config section.
    out_dir : path
        Receives model.pt (+ .json sidecar), sweep.csv, table4.csv/.md and the figures.

    Raises
    ------
    ValueError
        When fewer than 6 usable samples or 3 parameter sets exist (no meaningful split).
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    rows = usable(data[data["test"] == TEST_OF[output]], output)
    if len(rows) < 6:
        raise ValueError(
            f"{output}: only {len(rows)} usable DEM results; at least 6 are needed to train"
        )
    features = varying_features(rows, INPUTS[output])
    X = rows[features].to_numpy(dtype=float)
    y = rows[output].to_numpy(dtype=float)
    seed = int(settings["seed"])
    # Split by parameter set: the load conditions of one set are not independent samples.
    train, val, test = split_groups(rows["design_id"].to_numpy(), seed, tuple(settings["split"]))
    lo, hi = settings["hidden_sizes"]
    sweep = sweep_hidden_sizes(
        X,
        y,
        train,
        val,
        test,
        sizes=range(lo, hi + 1),
        seed=seed,
        max_epochs=int(settings["max_epochs"]),
        patience=int(settings["patience"]),
    )
    sweep.table.to_csv(out_dir / "sweep.csv", index=False)
    predictions = {"ANN": sweep.model.predict(X[test])}
    blr = bayesian_linear_regression().fit(X[train], y[train])
    predictions["Bayesian"] = blr.predict(X[test])
    gp = gaussian_process_regression(seed).fit(X[train], y[train])
    predictions["Gaussian"] = gp.predict(X[test])
    table4 = method_comparison_table({m: (y[test], predictions[m]) for m in METHODS})
    table4.to_csv(out_dir / "table4.csv")
    (out_dir / "table4.md").write_text(
        f"Table 4 ({output}): test-set comparison, {len(test)} of {len(rows)} samples\n\n"
        + to_markdown(table4, float_format=".3g")
        + "\n"
    )
    for method in METHODS:
        parity_plot(
            y[test],
            predictions[method],
            f"{method} ({output})",
            out_dir / f"parity_{method.lower()}.png",
        )
    r2_vs_hidden_size(sweep.table, out_dir / "r2_vs_hidden_size.png")
    ann = regression_metrics(y[test], predictions["ANN"])
    sweep.model.save(
        out_dir / "model.pt",
        metadata={
            "output": output,
            "features": features,
            "n_samples": len(rows),
            "split_sizes": [len(train), len(val), len(test)],
            "selected_size": int(sweep.selected_size),
            "paper_rule_size": int(sweep.paper_rule_size),
            "test_metrics": {k: float(v) for k, v in ann.items()},
        },
    )
    return TrainedSurrogate(output, features, sweep, table4, len(rows))


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


def write_table4_document(
    outputs: Sequence[str],
    tables: Sequence[str | Path],
    sweeps: Sequence[str | Path],
    markdown: str | Path,
) -> None:
    """Gather Table 4 of every bulk value and its hidden-size choices into one markdown file.

    Parameters
    ----------
    outputs : sequence of str
        The bulk values, in document order.
    tables, sweeps : sequence of path
        ``table4.csv`` and ``sweep.csv`` of each bulk value, in the order of ``outputs``.
    markdown : path
        The document.
    """
    parts = ["# Table 4: regression methods compared on the test set\n"]
    for name, table, sweep in zip(outputs, tables, sweeps, strict=True):
        t4 = pd.read_csv(table, index_col=0)
        sw = pd.read_csv(sweep)
        parts.append(
            f"## {name}\n\nNetwork size chosen by generalisation-set error: "
            f"{select_by_validation(sw)} hidden neurons; the paper's rule (best test R^2) "
            f"would pick {select_by_test_r2(sw)}.\n\n{to_markdown(t4, float_format='.3g')}\n"
        )
    with open(markdown, "w") as fh:
        fh.write("\n".join(parts))


def load_surrogate(path: str | Path) -> tuple[MLPSurrogate, list[str]]:
    """A saved network and its ordered input names."""
    model = MLPSurrogate.load(path)
    meta = json.loads(Path(f"{path}.json").read_text())
    features = meta.get("metadata", {}).get("features")
    if features is None:
        raise ValueError(f"{path}.json: no feature list in the sidecar")
    return model, list(features)
