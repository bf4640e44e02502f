"""Show the gap before and after the named effect was added (discrepancy workflow, step 4):
the per-observation table, the figure, the verification report and the summary."""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Mapping
from pathlib import Path
from typing import Any

import pandas as pd

from demcal.core.experiments import Experiment, load_experiment
from demcal.core.provenance import write_sidecar
from demcal.discrepancy.candidates import REFERENCE_CASE
from demcal.discrepancy.dem_check import held_out_experiment, replicate_bases
from demcal.discrepancy.effect_verdict import (
    dem_noise_bound,
    effect_verdict,
    fitted_dem_values,
)
from demcal.discrepancy.observations import observation_table
from demcal.discrepancy.plan import VERIFICATION_CASE
from demcal.discrepancy.report import (
    condition_label,
    gap_figure,
    gap_of,
    gap_table,
    verification_markdown,
)
from demcal.discrepancy.run_results import read_runs, replicate_statistics

__all__ = ["gap_title", "held_out_rows", "show", "write_before_after"]


def held_out_rows(
    before: pd.DataFrame, experiment: Experiment, config: Mapping[str, Any]
) -> pd.DataFrame:
    """Observations of the held-out loads, on the same sigma as the fitted ones.

    sigma = sqrt(measurement sd^2 + surrogate held-out RMSE^2) with the RMSE of the same
    observable in ``before`` (the Find table), so that a held-out misfit reads like a fitted
    one. No surrogate value is given (``at_best`` NaN): these loads are checked by DEM only.

    Returns
    -------
    DataFrame, shape (H, ...)
        Columns of :func:`demcal.discrepancy.observations.observation_table` plus at_best,
        z_at_best (NaN) and held_out (True); empty without held-out loads.
    """
    held = held_out_experiment(experiment, config)
    if not held.shear_conditions:
        return pd.DataFrame(columns=[*before.columns, "held_out"])
    rmse = before.groupby("observable")["surrogate_rmse"].first().to_dict()
    measured = [o for o in held.outputs if o in rmse]
    rows = observation_table(
        held, rmse, float(config["screening"]["tolerance"]), observables=measured
    )
    return rows.assign(at_best=math.nan, z_at_best=math.nan, held_out=True)


def show(
    before: pd.DataFrame,
    find_rec: Mapping[str, Any],
    ranking_rec: Mapping[str, Any],
    after: pd.DataFrame | None,
    recal_rec: Mapping[str, Any] | None,
    reference_runs: pd.DataFrame,
    verification_runs: pd.DataFrame,
    held_out: pd.DataFrame | None = None,
    replicates: int = 1,
) -> tuple[pd.DataFrame, dict[str, Any]]:
    """The before/after table and the summary of a discrepancy study.

    Parameters
    ----------
    before, after : DataFrame
        Find observations of the current and (if any) the extended model.
    find_rec, ranking_rec, recal_rec : mapping
        Records of Find, Name and the recalibration (None when nothing was added).
    reference_runs, verification_runs : DataFrame
        Replicates of the reference run at theta* and of the verification run (may be empty).
    held_out : DataFrame or None
        Observations of the held-out loads (:func:`held_out_rows`).
    replicates : int
        Replicate runs per point (``discrepancy.replicates``).
    """
    observed = before.assign(held_out=False)
    if held_out is not None and len(held_out):
        observed = pd.concat([observed, held_out], ignore_index=True, sort=False)
    dem_before = replicate_statistics(
        reference_runs, replicate_bases(REFERENCE_CASE, replicates), observed
    )
    dem_after = (
        replicate_statistics(
            verification_runs, replicate_bases(VERIFICATION_CASE, replicates), observed
        )
        if recal_rec is not None
        else None
    )
    table = gap_table(observed, after, dem_before, dem_after)
    fitted, held = table[~table["held_out"]], table[table["held_out"]]
    summary: dict[str, Any] = {
        "missing": bool(find_rec["missing"]),
        "verdict": find_rec["verdict"],
        "gap_before": float(find_rec["gap"]),
        "alpha": float(find_rec["alpha"]),
        "p_value": float(find_rec["p_value"]),
        "theta_before": find_rec["theta"],
        "winner": ranking_rec.get("winner"),
        "ranking": ranking_rec.get("ranking", []),
        "replicates": int(replicates),
        "held_out": sorted({condition_label(r) for r in held.itertuples()}),
        "dem_gap_before": gap_of(fitted["z_dem_before"]),
        "held_out_dem_gap_before": gap_of(held["z_dem_before"]),
        "extended": recal_rec is not None,
    }
    if recal_rec is None:
        summary["reason"] = (
            "nothing is missing (gap within noise)"
            if not find_rec["missing"]
            else "no candidate named: "
            + ("; ".join(ranking_rec.get("notes") or []) or "none beats 'nothing missing' clearly")
        )
        return table, summary
    gap_before = gap_of(fitted["z_before_common"])
    gap_after = gap_of(fitted["z_after_common"])
    dem_after_gap = gap_of(fitted["z_dem_after"])
    held_after_gap = gap_of(held["z_dem_after"])
    n_dem = fitted_dem_values(table)
    verdict = effect_verdict(
        summary["dem_gap_before"],
        dem_after_gap,
        summary["held_out_dem_gap_before"],
        held_after_gap,
        n_dem,
        summary["alpha"],
    )
    summary.update(
        {
            "parameter": recal_rec["parameter"],
            "magnitude": recal_rec["magnitude"],
            "identified": recal_rec["point"],
            "gap_after_own_sigma": float(recal_rec["gap"]),
            "gap_before_common": gap_before,
            "gap_after": gap_after,
            "gap_ratio": gap_before / gap_after if gap_after > 0 else math.inf,
            "dem_gap_after": dem_after_gap,
            "dem_gap_ratio": summary["dem_gap_before"] / dem_after_gap
            if dem_after_gap > 0
            else math.inf,
            "held_out_dem_gap_after": held_after_gap,
            "dem_values": n_dem,
            "dem_gap_bound": dem_noise_bound(n_dem, summary["alpha"]) if n_dem else math.nan,
            "dem_verdict": verdict,
            "verdict_after": recal_rec["verdict"],
            "screening_after": recal_rec.get("screening"),
        }
    )
    return table, summary


def gap_title(summary: Mapping[str, Any]) -> str:
    """Title of the gap figure: the gap before and after, or why nothing was added."""
    if summary["extended"]:
        return (
            f"gap {summary['gap_before_common']:.2f} -> {summary['gap_after']:.2f} after adding "
            f"{summary['winner']} (common sigma)"
        )
    return f"gap {summary['gap_before']:.2f}: {summary['reason']}"


def write_before_after(
    config: Mapping[str, Any],
    find_record_path: str | Path,
    find_table_path: str | Path,
    ranking_record_path: str | Path,
    reference_files: Iterable[str | Path],
    table_path: str | Path,
    figure_path: str | Path,
    verification_path: str | Path,
    summary_path: str | Path,
    recalibration_path: str | Path | None = None,
    after_table_path: str | Path | None = None,
    verification_files: Iterable[str | Path] | None = None,
    experiment_path: str | Path | None = None,
) -> dict[str, Any]:
    """Write the before/after table, its figure, the verification report and the summary.

    Parameters
    ----------
    config : mapping
        The validated configuration (for the summary's sidecar).
    find_record_path, find_table_path : path
        Record and per-observation table of Find on the current model.
    ranking_record_path : path
        Record of the ranking.
    reference_files : iterable of path
        ``bulk.csv`` of the reference probe run at theta* (none when nothing is missing).
    table_path, figure_path, verification_path, summary_path : path
        Outputs: CSV, PNG, markdown and JSON (with sidecar).
    recalibration_path, after_table_path : path or None
        Record and per-observation table of the extended model; None when no effect was added.
    verification_files : iterable of path or None
        ``bulk.csv`` of the verification runs of the extended model.
    experiment_path : path or None
        The experiment file (for the held-out loads); default ``config["experiment"]``.

    Returns
    -------
    dict
        The summary written.
    """
    extended = recalibration_path is not None
    before = pd.read_csv(find_table_path)
    experiment = load_experiment(experiment_path or config["experiment"])
    table, summary = show(
        before,
        json.loads(Path(find_record_path).read_text()),
        json.loads(Path(ranking_record_path).read_text()),
        pd.read_csv(after_table_path) if extended else None,
        json.loads(Path(recalibration_path).read_text()) if extended else None,
        read_runs(reference_files),
        read_runs(verification_files or []) if extended else pd.DataFrame(),
        held_out_rows(before, experiment, config),
        int(config["discrepancy"]["replicates"]),
    )
    table.to_csv(table_path, index=False, float_format="%.6g")
    gap_figure(table, gap_title(summary), figure_path)
    Path(verification_path).write_text(verification_markdown(table, summary))
    Path(summary_path).write_text(json.dumps(summary, indent=2, default=float) + "\n")
    write_sidecar(summary_path, config)
    return summary
