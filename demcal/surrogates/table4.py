"""Table 4: the network and the baselines scored on the test set and in cross-validation.

Per bulk value, :func:`method_rows` gives one row per regression method with the sizes of the
single split (parameter sets and rows in training, generalisation and test), the test-set
metrics of the paper, the cross-validated R^2 and RMSE by parameter set with their spread over
the folds, the data mean, and the ceiling of R^2 set by the scatter of single runs (the white
noise of the Gaussian process on all rows). :func:`write_table4_document` gathers the rows of
every bulk value into ``table4.md`` and ``table4.csv`` and adds the acceptance tolerance of the
screening (``screening.tolerance`` times the measured value, or times the data mean for a value
that was not measured) and whether the RMSE lies below it.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from demcal.core.experiments import Experiment, load_experiment
from demcal.surrogates.cross_validation import METHODS, CrossValidation
from demcal.surrogates.hidden_size_sweep import select_by_test_r2, select_by_validation
from demcal.surrogates.metrics import METRIC_LABELS, to_markdown

__all__ = [
    "CV_COLUMNS",
    "SPLIT_PARTS",
    "acceptance_reference",
    "method_rows",
    "paper_layout",
    "section_markdown",
    "tolerance_columns",
    "write_table4_document",
]

#: The parts of the single split, as named in the column names.
SPLIT_PARTS = ("train", "generalisation", "test")

#: Cross-validation columns of :func:`method_rows` (see ``CrossValidation.summary``).
CV_COLUMNS = (
    "cv_folds",
    "cv_sets",
    "cv_rows",
    "cv_r2",
    "cv_rmse",
    "cv_mae",
    "cv_mse",
    "cv_r2_sd",
    "cv_r2_min",
    "cv_r2_max",
    "cv_rmse_sd",
    "cv_rmse_min",
    "cv_rmse_max",
)


def method_rows(
    output: str,
    split_counts: Mapping[str, tuple[int, int]],
    test_metrics: Mapping[str, Mapping[str, float]],
    cv: CrossValidation | None,
    cv_note: str,
    y_mean: float,
    hidden_size: int,
    noise_sd: float = float("nan"),
    y_var: float = float("nan"),
) -> pd.DataFrame:
    """The Table 4 rows of one bulk value, one per method (the per-value ``table4.csv``).

    Parameters
    ----------
    output : str
        The bulk value (``mu_psh``, ``mu_sh``, ``rho_b``, ``aor``).
    split_counts : mapping
        ``"train"``, ``"generalisation"``, ``"test"`` -> (parameter sets, rows).
    test_metrics : mapping
        Method -> ``regression_metrics`` on the test set (``r2``, ``rmse``, ``mae``, ``mse``).
    cv : CrossValidation or None
        The cross-validation, None when it is off or skipped.
    cv_note : str
        Why the fold count differs from ``surrogate.cv_folds`` (empty if it does not).
    y_mean : float
        Mean of the bulk value over all usable rows, units of y.
    hidden_size : int
        Hidden neurons of the network (given on the ANN row only).
    noise_sd : float, optional
        Scatter of one row about the mean response, units of y: the white-noise term of the
        Gaussian process fitted on all rows. NaN when unknown.
    y_var : float, optional
        Variance of the bulk value over all usable rows (the denominator of R^2), units of y
        squared.

    Returns
    -------
    pandas.DataFrame
        Index ``method`` in the order of ``test_metrics``; columns ``output``, ``n_sets``,
        ``n_rows``, ``<part>_sets`` and ``<part>_rows`` for each of `SPLIT_PARTS`, ``test_r2``,
        ``test_rmse``, ``test_mae``, ``test_mse``, the `CV_COLUMNS` (``cv_folds`` 0 and NaN
        scores without cross-validation), ``cv_note``, ``y_mean``, ``hidden_size``,
        ``noise_sd`` and ``r2_ceiling`` = 1 - noise_sd^2 / y_var, the R^2 that even the exact
        mean response would score on these rows (the same on every method's row).
    """
    summary = cv.summary() if cv is not None else None
    rows = []
    for method, metrics in test_metrics.items():
        row: dict[str, object] = {"method": method, "output": output}
        row["n_sets"] = sum(split_counts[p][0] for p in SPLIT_PARTS)
        row["n_rows"] = sum(split_counts[p][1] for p in SPLIT_PARTS)
        for part in SPLIT_PARTS:
            row[f"{part}_sets"], row[f"{part}_rows"] = split_counts[part]
        row.update({f"test_{k}": float(metrics[k]) for k in METRIC_LABELS})
        for column in CV_COLUMNS:
            if summary is not None and method in summary.index:
                row[column] = summary.loc[method, column]
            else:
                row[column] = 0 if column in ("cv_folds", "cv_sets", "cv_rows") else np.nan
        row["cv_note"] = cv_note
        row["y_mean"] = float(y_mean)
        row["hidden_size"] = int(hidden_size) if method == "ANN" else pd.NA
        row["noise_sd"] = float(noise_sd)
        row["r2_ceiling"] = 1.0 - float(noise_sd) ** 2 / float(y_var)
        rows.append(row)
    table = pd.DataFrame(rows).set_index("method")
    return table.astype({"cv_folds": int, "cv_sets": int, "cv_rows": int})


def paper_layout(table: pd.DataFrame) -> pd.DataFrame:
    """The test-set metrics in the paper's layout: metrics as rows, methods as columns.

    Parameters
    ----------
    table : pandas.DataFrame
        Rows of :func:`method_rows` (index ``method``).

    Returns
    -------
    pandas.DataFrame
        Index ``["R^2", "RMSE", "MAE", "MSE"]`` (named ``metric``), one column per method in
        the order of `METHODS`.
    """
    methods = [m for m in METHODS if m in table.index]
    data = {m: [float(table.loc[m, f"test_{k}"]) for k in METRIC_LABELS] for m in methods}
    return pd.DataFrame(data, index=pd.Index(list(METRIC_LABELS.values()), name="metric"))


def acceptance_reference(
    output: str, experiment: Experiment | None, y_mean: float
) -> tuple[float, str]:
    """The value the relative acceptance tolerance of ``output`` applies to.

    Parameters
    ----------
    output : str
        The bulk value.
    experiment : Experiment or None
        The measurements (``config["experiment"]``).
    y_mean : float
        Mean of the DEM data, units of y (the fallback).

    Returns
    -------
    reference : float
        The smallest measured magnitude of ``output`` over the measured conditions (the
        strictest absolute tolerance), or ``|y_mean|`` when ``output`` was not measured.
    basis : str
        ``"measured"`` or ``"data mean"``.
    """
    measured: list[float] = []
    if experiment is not None:
        if output == "aor" and experiment.angle_of_repose is not None:
            measured.append(float(experiment.angle_of_repose))
        for condition in experiment.shear_conditions:
            if output in condition.values:
                measured.append(float(condition.values[output]))
    if measured:
        return float(min(abs(v) for v in measured)), "measured"
    return abs(float(y_mean)), "data mean"


def tolerance_columns(
    table: pd.DataFrame, experiment: Experiment | None, tolerance: float
) -> pd.DataFrame:
    """Rows of :func:`method_rows` with the acceptance tolerance and the RMSE verdicts added.

    Parameters
    ----------
    table : pandas.DataFrame
        Rows of one or more bulk values (columns ``output``, ``test_rmse``, ``cv_rmse``,
        ``y_mean``).
    experiment : Experiment or None
        The measurements.
    tolerance : float
        ``screening.tolerance``: relative acceptance tolerance |1 - num/exp|.

    Returns
    -------
    pandas.DataFrame
        A copy with ``tolerance`` (relative), ``tolerance_reference`` (units of y),
        ``tolerance_basis`` (``measured`` or ``data mean``), ``tolerance_abs`` (units of y),
        ``test_rmse_rel`` and ``cv_rmse_rel`` (RMSE / reference), ``test_rmse_below_tolerance``
        and ``cv_rmse_below_tolerance`` (boolean; ``<NA>`` without cross-validation).
    """
    out = table.copy()
    refs = [
        acceptance_reference(str(name), experiment, float(mean))
        for name, mean in zip(out["output"], out["y_mean"], strict=True)
    ]
    out["tolerance"] = float(tolerance)
    out["tolerance_reference"] = [r for r, _ in refs]
    out["tolerance_basis"] = [b for _, b in refs]
    out["tolerance_abs"] = out["tolerance"] * out["tolerance_reference"]
    for kind in ("test", "cv"):
        rmse = out[f"{kind}_rmse"].astype(float)
        out[f"{kind}_rmse_rel"] = rmse / out["tolerance_reference"]
        below = pd.array(rmse < out["tolerance_abs"], dtype="boolean")
        below[~np.isfinite(rmse.to_numpy())] = pd.NA
        out[f"{kind}_rmse_below_tolerance"] = below
    return out


def _g(value: object) -> str:
    number = float(value)  # type: ignore[arg-type]
    return format(number, ".3g") if np.isfinite(number) else "n/a"


def _verdict(value: object) -> str:
    return "n/a" if pd.isna(value) else ("yes" if bool(value) else "NO")


def _summary_markdown(table: pd.DataFrame) -> str:
    rows = []
    for method, r in table.iterrows():
        cv_on = int(r["cv_folds"]) > 0
        row = {
            "method": method,
            "sets train/gen/test": "/".join(str(int(r[f"{p}_sets"])) for p in SPLIT_PARTS),
            "rows train/gen/test": "/".join(str(int(r[f"{p}_rows"])) for p in SPLIT_PARTS),
            "test R^2": _g(r["test_r2"]),
            "test RMSE": _g(r["test_rmse"]),
            "CV folds (sets/rows)": (
                f"{int(r['cv_folds'])} ({int(r['cv_sets'])}/{int(r['cv_rows'])})"
                if cv_on
                else "off"
            ),
            "CV R^2": _g(r["cv_r2"]),
            "CV R^2 of folds": f"{_g(r['cv_r2_min'])}..{_g(r['cv_r2_max'])}" if cv_on else "n/a",
            "CV RMSE": _g(r["cv_rmse"]),
            "CV RMSE of folds": (
                f"{_g(r['cv_rmse_min'])}..{_g(r['cv_rmse_max'])}" if cv_on else "n/a"
            ),
        }
        if "tolerance_abs" in table:
            row["tolerance"] = _g(r["tolerance_abs"])
            row["test RMSE < tol"] = _verdict(r["test_rmse_below_tolerance"])
            row["CV RMSE < tol"] = _verdict(r["cv_rmse_below_tolerance"])
        rows.append(row)
    return to_markdown(pd.DataFrame(rows).set_index("method"))


def section_markdown(name: str, table: pd.DataFrame, sweep: pd.DataFrame | None = None) -> str:
    """The Table 4 section of one bulk value (Markdown, headed ``## name``).

    Parameters
    ----------
    name : str
        The bulk value.
    table : pandas.DataFrame
        Its rows of :func:`method_rows`, optionally with :func:`tolerance_columns`.
    sweep : pandas.DataFrame, optional
        Its ``sweep.csv`` (hidden-size choice by generalisation error and by the paper's rule).

    Returns
    -------
    str
        The heading, a paragraph with the split sizes, the cross-validation and the tolerance,
        the table of all columns (one row per method) and, last, the test-set metrics in the
        paper's layout.
    """
    first = table.iloc[0]
    counts = ", ".join(
        f"{label} {int(first[f'{p}_sets'])} sets / {int(first[f'{p}_rows'])} rows"
        for p, label in zip(SPLIT_PARTS, ("training", "generalisation", "test"), strict=True)
    )
    text = [
        f"{int(first['n_rows'])} usable rows from {int(first['n_sets'])} parameter sets. "
        f"Single split by parameter set: {counts}; the baselines are fitted on the training "
        "rows only."
    ]
    if int(first["cv_folds"]) > 0:
        text.append(
            f"Cross-validation: {int(first['cv_folds'])} folds by parameter set over "
            f"{int(first['cv_sets'])} sets / {int(first['cv_rows'])} rows; every row is "
            "predicted once by models trained without its parameter set (the baselines on "
            "every row of the other folds, the network on them less its generalisation sets), "
            "R^2 and RMSE are those of the pooled predictions, with their range over the folds "
            "beside them."
        )
    else:
        text.append("Cross-validation: off.")
    note = first.get("cv_note")
    if isinstance(note, str) and note:
        text.append(f"Note: {note}.")
    if sweep is not None:
        text.append(
            f"Network size chosen by generalisation-set error: {select_by_validation(sweep)} "
            "hidden neurons (also in every fold); the paper's rule (best test R^2) would pick "
            f"{select_by_test_r2(sweep)}."
        )
    ceiling = float(first.get("r2_ceiling", np.nan))
    if np.isfinite(ceiling):
        text.append(
            f"Scatter of one row about the mean response (white-noise term of the Gaussian "
            f"process on all rows): {_g(first['noise_sd'])}, so even the exact mean response "
            f"would score an R^2 of at most {_g(ceiling)} on these rows; more parameter sets "
            "bring the CV R^2 towards that ceiling, only replicate runs (design.replicates) "
            "raise it."
        )
    if "tolerance_abs" in table:
        basis = (
            "the measured value (the smallest, if measured at several conditions)"
            if first["tolerance_basis"] == "measured"
            else "the mean of the DEM data (not measured)"
        )
        text.append(
            f"Acceptance tolerance: {float(first['tolerance']):g} x {basis} "
            f"{_g(first['tolerance_reference'])} = {_g(first['tolerance_abs'])}."
        )
    return (
        f"## {name}\n\n"
        + " ".join(text)
        + "\n\n"
        + _summary_markdown(table)
        + "\nTest-set metrics in the paper's layout:\n\n"
        + to_markdown(paper_layout(table), float_format=".3g")
    )


_PREAMBLE = """\
# Table 4: regression methods on the test set and in cross-validation by parameter set

Per bulk value: the sizes of the single split (parameter sets / rows in training, generalisation
and test), the test-set R^2 and RMSE of the saved network and of the baselines, and the
cross-validated ("CV") R^2 and RMSE: the parameter sets are dealt into K folds, every row is
predicted by models trained without its set, and R^2 and RMSE are computed once over all these
predictions (the range over the folds beside them). "tolerance" is the absolute acceptance
tolerance of the screening, screening.tolerance times the measured value; "RMSE < tol" says
whether the surrogate's typical error is smaller than it, i.e. whether the surrogate can
resolve the acceptance band it screens with. Each section also gives the scatter of one row
about the mean response and the R^2 ceiling it sets, 1 - scatter^2 / variance of the rows: the
score of a perfect surrogate on these rows. Units are those of the bulk value.
"""


def write_table4_document(
    outputs: Sequence[str],
    tables: Sequence[str | Path],
    sweeps: Sequence[str | Path],
    markdown: str | Path,
    *,
    csv: str | Path | None = None,
    experiment: str | Path | None = None,
    tolerance: float | None = None,
) -> pd.DataFrame:
    """Gather Table 4 of every bulk value into one Markdown document (and one CSV).

    Parameters
    ----------
    outputs : sequence of str
        The bulk values, in document order.
    tables, sweeps : sequence of path
        ``table4.csv`` (:func:`method_rows`) and ``sweep.csv`` of each bulk value, in the order
        of ``outputs``.
    markdown : path
        The document: a ``## value`` section per bulk value (:func:`section_markdown`).
    csv : path, optional
        All rows of the document, one per bulk value and method.
    experiment : path, optional
        The experiment file; with ``tolerance``, adds the tolerance columns
        (:func:`tolerance_columns`).
    tolerance : float, optional
        ``screening.tolerance``; without it the tolerance columns are left out.

    Returns
    -------
    pandas.DataFrame
        The rows written to ``csv``, index ``method``.
    """
    measured = load_experiment(experiment) if experiment is not None else None
    parts = [_PREAMBLE]
    frames = []
    for name, table_path, sweep_path in zip(outputs, tables, sweeps, strict=True):
        table = pd.read_csv(table_path, index_col=0, dtype={"cv_note": str})
        table["cv_note"] = table["cv_note"].fillna("")
        if tolerance is not None:
            table = tolerance_columns(table, measured, float(tolerance))
        parts.append(section_markdown(name, table, pd.read_csv(sweep_path)))
        frames.append(table)
    Path(markdown).write_text("\n".join(parts))
    combined = pd.concat(frames)
    if csv is not None:
        combined.to_csv(csv, float_format="%.6g")
    return combined
