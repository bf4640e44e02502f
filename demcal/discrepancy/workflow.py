"""The discrepancy workflow's steps on files: surrogates, configuration and runs in, tables out.

The scripts behind ``workflow/rules/discrepancy.smk`` call these functions; the method itself
lives in :mod:`demcal.discrepancy.find` (Find), :mod:`demcal.discrepancy.ranking` (Name),
:mod:`demcal.discrepancy.candidates` (the catalogue and the cases) and
:mod:`demcal.discrepancy.extension` (Add).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from demcal.core.experiments import Experiment
from demcal.design.cases import design_spec
from demcal.discrepancy.candidates import (
    REFERENCE_CASE,
    Candidate,
    applicability,
    base_point,
    parse_candidates,
)
from demcal.discrepancy.extension import rmse_of
from demcal.discrepancy.find import (
    LOAD_INPUTS,
    FindResult,
    ParameterBox,
    SurrogateModel,
    find,
    observation_table,
)
from demcal.discrepancy.plan import VERIFICATION_CASE
from demcal.discrepancy.ranking import (
    EffectResponse,
    fit_candidate,
    null_fit,
    rank_candidates,
    ranking_sigma,
    response_signature,
)
from demcal.discrepancy.report import gap_of, gap_table
from demcal.identification.calibration import calibrate
from demcal.surrogates.training import TEST_OF, load_surrogate

__all__ = [
    "RankingResult",
    "build_model",
    "find_from_files",
    "find_record",
    "load_surrogates",
    "rank",
    "recalibrate",
    "run_values",
    "screening_counts",
    "show",
]


def load_surrogates(
    paths: Mapping[str, str | Path],
) -> tuple[dict[str, tuple[Any, list[str]]], dict[str, float]]:
    """Saved surrogates (model, input names) and their held-out RMSE, per observable."""
    surrogates = {name: load_surrogate(path) for name, path in paths.items()}
    rmse = {name: rmse_of(path) for name, path in paths.items()}
    return surrogates, rmse


def _constants(config: Mapping[str, Any]) -> dict[str, dict[str, float]]:
    return {output: {"dCylDp": float(config[test]["dCylDp"])} for output, test in TEST_OF.items()}


def _bounds(name: str, config: Mapping[str, Any]) -> tuple[float, float]:
    """The screening axis of ``name`` within the span of the design (no extrapolation)."""
    spans = []
    axes = config["screening"]["axes"]
    if name in axes:
        spans.append((float(axes[name][0]), float(axes[name][1])))
    spec = design_spec(config["design"])
    if name in spec.get("ranges", {}):
        lo, hi = spec["ranges"][name]
        spans.append((float(lo), float(hi)))
    elif name in spec.get("levels", {}):
        spans.append((float(min(spec["levels"][name])), float(max(spec["levels"][name]))))
    if not spans:
        raise KeyError(
            f"parameter {name!r} is a surrogate input but has no range in screening.axes or "
            "design.ranges"
        )
    lo, hi = max(s[0] for s in spans), min(s[1] for s in spans)
    if lo > hi:
        raise ValueError(f"parameter {name!r}: screening axis and design range do not overlap")
    return lo, hi


def build_model(
    surrogates: Mapping[str, tuple[Any, Sequence[str]]],
    rmse: Mapping[str, float],
    experiment: Experiment,
    config: Mapping[str, Any],
    extra: Candidate | None = None,
) -> tuple[SurrogateModel, ParameterBox]:
    """The surrogate model of all measured observations and its parameter box.

    The parameters are the surrogate inputs other than the load and the test constants; their
    bounds are the screening axes within the design's ranges (the surrogates are not
    extrapolated), and an added candidate's parameter takes its range from the catalogue.
    """
    obs = observation_table(
        experiment, rmse, float(config["screening"]["tolerance"]), observables=list(surrogates)
    )
    constants = _constants(config)
    names: list[str] = []
    for output in obs["observable"].unique():
        for feature in surrogates[output][1]:
            if feature in LOAD_INPUTS or feature in constants.get(output, {}) or feature in names:
                continue
            names.append(feature)
    bounds: dict[str, tuple[float, float]] = {}
    integer: set[str] = set()
    for name in names:
        if extra is not None and name == extra.parameter:
            bounds[name] = extra.range
            if extra.integer:
                integer.add(name)
        else:
            bounds[name] = _bounds(name, config)
    model = SurrogateModel(surrogates, obs, names, constants)
    return model, ParameterBox(bounds, frozenset(integer))


def find_from_files(
    model_paths: Mapping[str, str | Path],
    experiment: Experiment,
    config: Mapping[str, Any],
    extra: Candidate | None = None,
) -> tuple[FindResult, SurrogateModel, ParameterBox]:
    """Find on saved surrogates with the ``discrepancy`` settings of ``config``."""
    settings = config["discrepancy"]
    surrogates, rmse = load_surrogates(model_paths)
    model, box = build_model(surrogates, rmse, experiment, config, extra)
    result = find(
        model,
        box,
        int(settings["grid_points"]),
        float(settings["gap_threshold"]),
        float(settings["fit_z"]),
    )
    return result, model, box


def run_values(runs: pd.DataFrame, run: str, observations: pd.DataFrame) -> np.ndarray:
    """DEM values of the observations in one run (all its tests), NaN where missing or failed.

    Parameters
    ----------
    runs : DataFrame
        Rows of :func:`demcal.discrepancy.extension.read_runs` (column ``run`` = case dir).
    run : str
        Run id without the stress suffix (e.g. ``ref`` for ``ref_s1``, ``ref_s2`` and the
        angle-of-repose case ``ref``).
    observations : DataFrame, shape (K, ...)

    Returns
    -------
    ndarray, shape (K,)
    """
    if len(runs) == 0:
        return np.full(len(observations), math.nan)
    base = runs["run"].astype(str).str.replace(r"_s\d+(_p\d+)?$", "", regex=True)
    mine = runs[(base == run) & (runs["status"] == "ok")]
    out = np.full(len(observations), math.nan)
    for k, (_, row) in enumerate(observations.iterrows()):
        name = row["observable"]
        if name == "aor":
            match = mine[mine["test"] == "angle_of_repose"]
        else:
            shear = mine[mine["test"] == "shear_cell"]
            match = shear[
                np.isclose(shear["normal_stress"].astype(float), row["normal_stress"], rtol=1e-9)
                & np.isclose(shear["P"].astype(float), row["P"], rtol=1e-9)
            ]
        if len(match) and name in match and np.isfinite(float(match[name].iloc[0])):
            out[k] = float(match[name].iloc[0])
    return out


@dataclass
class RankingResult:
    """Outcome of the Name step.

    Attributes
    ----------
    table : DataFrame
        One row per candidate of the catalogue (ranked ones first), with description,
        parameter, status and signature.
    winner : Candidate or None
    fits : dict
        Candidate name -> CandidateFit.
    find : FindResult
        The Find result on the observations used in the ranking.
    notes : list[str]
        Observations or probe levels left out, and why.
    """

    table: pd.DataFrame
    winner: Candidate | None
    fits: dict
    find: FindResult
    null_deviance: float
    notes: list[str] = field(default_factory=list)


def rank(
    model_paths: Mapping[str, str | Path],
    experiment: Experiment,
    config: Mapping[str, Any],
    runs: pd.DataFrame,
    probe_point: Mapping[str, float],
) -> RankingResult:
    """Score every applicable candidate with its probe runs and rank them (BIC).

    ``probe_point`` is the parameter set the probes ran at (``point`` of the Find record); it
    gives the "absent" magnitude of a candidate whose absence is another parameter's value.

    Observations whose reference probe run gave no value are left out of the ranking (and the
    null fit is redone without them); a probe level with a missing value is dropped for its
    candidate; a candidate without any usable level is reported as not scored.
    """
    settings = config["discrepancy"]
    candidates = parse_candidates(settings["candidates"])
    surrogates, rmse = load_surrogates(model_paths)
    model, box = build_model(surrogates, rmse, experiment, config)
    obs = model.observations
    notes: list[str] = []
    reference = run_values(runs, REFERENCE_CASE, obs)
    keep = np.isfinite(reference)
    if not keep.any():
        raise ValueError("the reference probe run gave no value for any observation")
    if not keep.all():
        dropped = obs[~keep]
        notes.append(
            "left out (no value in the reference run): "
            + ", ".join(f"{r.observable} at {r.normal_stress:g} Pa" for r in dropped.itertuples())
        )
        model = SurrogateModel(surrogates, obs[keep], model.parameters, _constants(config))
        obs = model.observations
        reference = reference[keep]
    null = find(
        model,
        box,
        int(settings["grid_points"]),
        float(settings["gap_threshold"]),
        float(settings["fit_z"]),
    )
    grid = box.grid(int(settings["grid_points"]))
    predictions = model.predict(grid)
    noise = obs["surrogate_rmse"].to_numpy(float)
    weights = ranking_sigma(obs["sigma"].to_numpy(float), noise)
    null_weighted = null_fit(model, box, grid, predictions, weights)
    point = {k: float(v) for k, v in probe_point.items()}
    fits = {}
    rows = []
    for cand in candidates:
        row: dict[str, Any] = {
            "candidate": cand.name,
            "description": cand.description,
            "parameter": cand.parameter,
        }
        ok, reason = applicability(cand, config)
        if not ok:
            rows.append({**row, "status": f"not applicable: {reason}"})
            continue
        mags, values = [], []
        for j, level in enumerate(cand.probe_levels):
            vals = run_values(runs, cand.case_id(j), obs)
            if np.all(np.isfinite(vals)):
                mags.append(level)
                values.append(vals)
            else:
                notes.append(f"{cand.name}: probe level {level:g} dropped (a run gave no value)")
        if not mags:
            rows.append({**row, "status": "not scored: no usable probe run"})
            continue
        response = EffectResponse.from_runs(
            cand.name,
            [cand.off_magnitude(point), *mags],
            np.vstack([reference, *values]),
            reference=0,
            integer=cand.integer,
        )
        if response.magnitudes.size < 2:
            rows.append({**row, "status": "not scored: probe levels equal the absent value"})
            continue
        fit = fit_candidate(
            model,
            box,
            grid,
            predictions,
            response,
            weights,
            int(settings["magnitude_points"]),
        )
        fits[cand.name] = fit
        signature = response_signature(obs, response, reference, noise)
        rows.append({**row, "status": "scored", "signature": signature})
    scored, winner_name = rank_candidates(
        null_weighted.deviance,
        fits,
        len(obs),
        float(settings["min_delta_bic"]),
        float(settings["min_explained"]),
    )
    unscored = [r["candidate"] for r in rows if r["status"].startswith("not scored")]
    if winner_name is not None and unscored:
        notes.append(
            f"{winner_name} leads, but is not named: {', '.join(unscored)} could not be scored"
        )
        winner_name = None
    info = pd.DataFrame(rows)
    table = scored.merge(info, on="candidate", how="right")
    table = table.sort_values(["rank"], na_position="last", kind="stable").reset_index(drop=True)
    table["named"] = table["candidate"] == winner_name
    table.loc[table["status"] == "scored", "status"] = np.where(
        table.loc[table["status"] == "scored", "named"], "named", "not significant"
    )
    winner = next((c for c in candidates if c.name == winner_name), None)
    return RankingResult(table, winner, fits, null, null_weighted.deviance, notes)


def find_record(result: FindResult, box: ParameterBox, config: Mapping[str, Any]) -> dict:
    """JSON record of a Find result: verdict, gap, theta* and the complete parameter set."""
    return {
        "missing": result.missing,
        "verdict": result.verdict,
        "gap": result.gap,
        "threshold": result.threshold,
        "chi2": result.best.deviance,
        "n_observations": len(result.observations),
        "theta": result.best.theta,
        "point": base_point(result.best.theta, config),
        "bounds": {k: list(v) for k, v in box.bounds.items()},
        "sentences": result.sentences,
        "pinned": result.pinned,
    }


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
    result = calibrate(surrogates, experiment, screening, _constants(config))
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


def show(
    before: pd.DataFrame,
    find_rec: Mapping[str, Any],
    ranking_rec: Mapping[str, Any],
    after: pd.DataFrame | None,
    recal_rec: Mapping[str, Any] | None,
    reference_runs: pd.DataFrame,
    verification_runs: pd.DataFrame,
) -> tuple[pd.DataFrame, dict[str, Any]]:
    """The before/after table and the summary of a discrepancy study.

    Parameters
    ----------
    before, after : DataFrame
        Find observations of the current and (if any) the extended model.
    find_rec, ranking_rec, recal_rec : mapping
        Records of Find, Name and the recalibration (None when nothing was added).
    reference_runs, verification_runs : DataFrame
        Probe reference runs at theta* and verification runs (may be empty).
    """
    dem_before = run_values(reference_runs, REFERENCE_CASE, before)
    dem_after = (
        run_values(verification_runs, VERIFICATION_CASE, before) if recal_rec is not None else None
    )
    table = gap_table(before, after, dem_before, dem_after)
    summary: dict[str, Any] = {
        "missing": bool(find_rec["missing"]),
        "verdict": find_rec["verdict"],
        "gap_before": float(find_rec["gap"]),
        "threshold": float(find_rec["threshold"]),
        "theta_before": find_rec["theta"],
        "winner": ranking_rec.get("winner"),
        "ranking": ranking_rec.get("ranking", []),
        "dem_gap_before": gap_of(table["z_dem_before"]),
        "extended": recal_rec is not None,
    }
    if recal_rec is None:
        summary["reason"] = (
            "nothing is missing (gap within noise)"
            if not find_rec["missing"]
            else "no candidate beats 'nothing missing' clearly"
        )
        return table, summary
    gap_before = gap_of(table["z_before_common"])
    gap_after = gap_of(table["z_after_common"])
    dem_after_gap = gap_of(table["z_dem_after"])
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
            "verdict_after": recal_rec["verdict"],
            "screening_after": recal_rec.get("screening"),
        }
    )
    return table, summary
