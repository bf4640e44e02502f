"""Recalibrate the extended model (discrepancy workflow, step 3): Find with the named effect's
magnitude as one more axis, and the tolerance screening of the identification on it."""

from __future__ import annotations

import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from demcal.core.experiments import Experiment, load_experiment
from demcal.core.provenance import write_sidecar
from demcal.discrepancy.best_fit import ParameterBox
from demcal.discrepancy.candidates import Candidate
from demcal.discrepancy.dem_check import fitted_experiment
from demcal.discrepancy.find import FindResult
from demcal.discrepancy.model_from_files import (
    find_from_files,
    find_record,
    load_surrogates,
    surrogate_constants,
)
from demcal.discrepancy.report import find_markdown
from demcal.discrepancy.runs import named_candidate
from demcal.identification.calibration import calibrate

__all__ = ["recalibrate", "screening_counts", "write_recalibration"]


def screening_counts(
    model_paths: Mapping[str, str | Path],
    experiment: Experiment,
    config: Mapping[str, Any],
    box: ParameterBox,
    extra: Candidate | None = None,
) -> dict[str, Any]:
    """Tolerance screening (paper eqs. 3-4) over the model's parameters, plus the extra axis.

    Axes that no surrogate uses are left out (they only multiply the grid); an added
    candidate's parameter gets ``discrepancy.extended.axis_count`` draws over its range.

    Returns
    -------
    dict
        n_total, n_valid per group, the group used and its mean parameters.
    """
    surrogates, _ = load_surrogates(model_paths)
    screening = dict(config["screening"])
    count = int(config["discrepancy"]["extended"]["axis_count"])
    axes: dict[str, list[float]] = {}
    for name in box.names:
        given = config["screening"]["axes"].get(name)
        lo, hi = box.bounds[name]
        axes[name] = list(given) if given is not None else [lo, hi, count]
    if extra is not None:
        axes[extra.parameter] = [extra.range[0], extra.range[1], count]
    screening["axes"] = axes
    result = calibrate(surrogates, experiment, screening, surrogate_constants(config))
    return {
        "n_total": result.n_total,
        "n_valid": {g: len(v) for g, v in result.valid.items()},
        "group": result.identified_group,
        "means": {k: v["mean"] for k, v in result.identified.items()},
        "tolerance": float(config["screening"]["tolerance"]),
    }


def recalibrate(
    model_paths: Mapping[str, str | Path],
    experiment: Experiment,
    config: Mapping[str, Any],
    candidate: Candidate,
) -> tuple[FindResult, ParameterBox, dict[str, Any]]:
    """Find on the extended model (the effect's magnitude as one more axis) and its screening.

    Returns
    -------
    result : FindResult
        Gap and per-observation table of the extended model.
    box : ParameterBox
    record : dict
        Find record plus the candidate, its fitted magnitude and the screening counts.
    """
    result, _, box = find_from_files(model_paths, experiment, config, extra=candidate)
    record = find_record(result, box, config)
    if candidate.parameter in result.best.theta:
        magnitude = float(result.best.theta[candidate.parameter])
    else:
        raise ValueError(
            f"extended surrogates do not use {candidate.parameter!r}: it did not vary in the "
            "extended training data"
        )
    record.update(
        {
            "winner": candidate.name,
            "parameter": candidate.parameter,
            "magnitude": magnitude,
            "screening": screening_counts(model_paths, experiment, config, box, candidate),
        }
    )
    return result, box, record


def write_recalibration(
    model_paths: Mapping[str, str | Path],
    experiment_path: str | Path,
    config: Mapping[str, Any],
    ranking_record_path: str | Path,
    table_path: str | Path,
    record_path: str | Path,
    markdown_path: str | Path,
) -> tuple[FindResult, dict[str, Any]]:
    """Recalibrate the model extended by the named effect and write table, record and report.

    Parameters
    ----------
    model_paths : mapping
        Observable -> saved surrogate of the extended model.
    experiment_path : path
        The experiment file with the measurements.
    config : mapping
        The validated configuration.
    ranking_record_path : path
        Record of the ranking (its ``winner`` is the added effect).
    table_path, record_path, markdown_path : path
        Per-observation CSV, JSON record (with sidecar) and markdown report to write.

    Returns
    -------
    result : FindResult
    record : dict
        The record written (see :func:`recalibrate`).
    """
    candidate = named_candidate(config, ranking_record_path)
    # Held-out loads are kept for the DEM check of the Show step.
    experiment = fitted_experiment(load_experiment(experiment_path), config)
    result, box, record = recalibrate(model_paths, experiment, config, candidate)
    result.observations.to_csv(table_path, index=False, float_format="%.8g")
    Path(record_path).write_text(json.dumps(record, indent=2) + "\n")
    Path(markdown_path).write_text(
        find_markdown(result, f"{experiment.material}, model + {candidate.name}", box.bounds)
    )
    write_sidecar(record_path, config)
    return result, record
