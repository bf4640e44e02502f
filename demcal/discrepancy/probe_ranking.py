"""Name the missing effect on files: the candidates scored with their probe runs and ranked
(discrepancy workflow, step 2; the method is in :mod:`demcal.discrepancy.ranking`), and the
ranking's outputs with the extended design of the named effect."""

from __future__ import annotations

import json
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from demcal.core.experiments import Experiment, load_experiment
from demcal.core.provenance import write_sidecar
from demcal.discrepancy.best_fit import ParameterBox
from demcal.discrepancy.candidates import (
    REFERENCE_CASE,
    Candidate,
    applicability,
    extended_design,
    parse_candidates,
)
from demcal.discrepancy.dem_check import fitted_experiment, replicate_bases
from demcal.discrepancy.effect_response import EffectResponse, response_signature
from demcal.discrepancy.find import FindResult, find
from demcal.discrepancy.model_from_files import (
    build_model,
    load_surrogates,
    surrogate_constants,
)
from demcal.discrepancy.observations import SurrogateModel
from demcal.discrepancy.ranking import (
    UNNAMEABLE,
    NamingTest,
    fit_candidate,
    naming_power,
    naming_test,
    null_fit,
    power_with_fixed,
    rank_candidates,
    ranking_sigma,
)
from demcal.discrepancy.report import condition_label, ranking_markdown
from demcal.discrepancy.run_results import read_runs, replicate_statistics

__all__ = ["RankingResult", "lead_points", "rank", "ranking_record", "write_lead", "write_ranking"]


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
    null_deviance : float
        Deviance D_0 of "nothing missing" with the ranking weights.
    notes : list[str]
        Observations or probe levels left out, and why.
    test : NamingTest or None
        The bootstrap tests of the naming decision (None when no candidate was scored).
    ambiguous : tuple of str or None
        The top candidate and the runner-up when an effect was found but the two could not be
        told apart (nothing named for that reason), else None.
    power : DataFrame or None
        Per candidate and probe level, the shares of data sets with that effect in which it
        would be found and named (:func:`~demcal.discrepancy.ranking.naming_power`); None
        when no candidate was scored or ``discrepancy.power_draws`` is 0.
    """

    table: pd.DataFrame
    winner: Candidate | None
    fits: dict
    find: FindResult
    null_deviance: float
    notes: list[str] = field(default_factory=list)
    test: NamingTest | None = None
    ambiguous: tuple[str, str] | None = None
    power: pd.DataFrame | None = None


@dataclass
class _Scores:
    """The candidates' fits on the probe runs, before any test (see :func:`_score`)."""

    model: SurrogateModel
    box: ParameterBox
    grid: np.ndarray
    predictions: np.ndarray
    weights: np.ndarray
    null_deviance: float
    fits: dict
    responses: dict[str, EffectResponse]
    rows: list[dict[str, Any]]
    notes: list[str]

    def ranked(self, min_explained: float) -> tuple[pd.DataFrame, str | None]:
        """The scored candidates ordered by dBIC, and the leader if it explains enough."""
        return rank_candidates(
            self.null_deviance, self.fits, len(self.model.observations), min_explained
        )


def _score(
    model_paths: Mapping[str, str | Path],
    experiment: Experiment,
    config: Mapping[str, Any],
    runs: pd.DataFrame,
    probe_point: Mapping[str, float],
    reprobes: pd.DataFrame | None = None,
    points: Mapping[str, Mapping[str, float]] | None = None,
) -> _Scores:
    """Fit every applicable candidate with its probe response (see :func:`rank`)."""
    settings = config["discrepancy"]
    n_reference = int(settings["replicates"])
    n_probe = int(settings["probe_replicates"])
    candidates = parse_candidates(settings["candidates"])
    surrogates, rmse = load_surrogates(model_paths)
    model, box = build_model(surrogates, rmse, experiment, config)
    obs = model.observations
    notes: list[str] = []
    reference = _mean_of_runs(runs, REFERENCE_CASE, n_reference, obs)
    keep = np.isfinite(reference)
    if not keep.any():
        raise ValueError("the reference probe runs gave no value for any observation")
    if not keep.all():
        dropped = obs[~keep]
        notes.append(
            "left out (no value in any reference run): "
            + ", ".join(f"{r.observable} at {r.normal_stress:g} Pa" for r in dropped.itertuples())
        )
        model = SurrogateModel(surrogates, obs[keep], model.parameters, surrogate_constants(config))
        obs = model.observations
        reference = reference[keep]
    grid = box.grid(int(settings["grid_points"]))
    predictions = model.predict(grid)
    noise = obs["surrogate_rmse"].to_numpy(float)
    weights = ranking_sigma(obs["sigma"].to_numpy(float), noise, n_probe, n_reference)
    null_weighted = null_fit(model, box, grid, predictions, weights)
    point = {k: float(v) for k, v in probe_point.items()}
    fits = {}
    responses: dict[str, EffectResponse] = {}
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
        source, own_reference, own_point = runs, reference, point
        if points and cand.name in points and reprobes is not None and len(reprobes):
            again = _mean_of_runs(reprobes, cand.reference_case, n_reference, obs)
            if np.all(np.isfinite(again)):
                source, own_reference = reprobes, again
                own_point = {**point, **{k: float(v) for k, v in points[cand.name].items()}}
            else:
                notes.append(
                    f"{cand.name}: scored with its probes at theta* (its reference runs at its "
                    "own best fit gave no value for every observation)"
                )
        mags, values = [], []
        for j, level in enumerate(cand.probe_levels):
            vals = _mean_of_runs(source, cand.case_id(j), n_probe, obs)
            if np.all(np.isfinite(vals)):
                mags.append(level)
                values.append(vals)
            else:
                notes.append(
                    f"{cand.name}: probe level {level:g} dropped (no run gave a value for "
                    "every observation)"
                )
        if not mags:
            rows.append({**row, "status": "not scored: no usable probe run"})
            continue
        response = EffectResponse.from_runs(
            cand.name,
            [cand.off_magnitude(own_point), *mags],
            np.vstack([own_reference, *values]),
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
        responses[cand.name] = response
        signature = response_signature(obs, response, own_reference, noise)
        if source is not runs:
            at = ", ".join(f"{k} {own_point[k]:.4g}" for k in box.names if k in own_point)
            notes.append(f"{cand.name}: scored with its probe runs at its own best fit ({at})")
        rows.append({**row, "status": "scored", "signature": signature})
    return _Scores(
        model,
        box,
        grid,
        predictions,
        weights,
        null_weighted.deviance,
        fits,
        responses,
        rows,
        notes,
    )


def lead_points(
    model_paths: Mapping[str, str | Path],
    experiment: Experiment,
    config: Mapping[str, Any],
    runs: pd.DataFrame,
    probe_point: Mapping[str, float],
) -> dict[str, dict[str, float]]:
    """The best fit of each of the ``discrepancy.reprobe`` leading candidates, where they are
    probed again before the naming.

    A response measured at theta* is added to the surrogate everywhere; a missing effect can
    drag theta* far from where the model extended by it fits, so the leaders are probed again
    at their own best fit (one step of relinearisation) and scored with those responses.

    Returns
    -------
    dict
        Candidate -> complete parameter set (``probe_point`` with the candidate's best-fit
        values of the free parameters), in dBIC order; empty when no candidate was scored.
    """
    count = int(config["discrepancy"]["reprobe"])
    if count == 0:
        return {}
    scores = _score(model_paths, experiment, config, runs, probe_point)
    table, _ = scores.ranked(float(config["discrepancy"]["min_explained"]))
    names = [str(n) for n in table.sort_values("rank")["candidate"]][:count]
    base = {k: float(v) for k, v in probe_point.items()}
    return {n: {**base, **scores.fits[n].best.theta} for n in names}


def rank(
    model_paths: Mapping[str, str | Path],
    experiment: Experiment,
    config: Mapping[str, Any],
    runs: pd.DataFrame,
    probe_point: Mapping[str, float],
    reprobes: pd.DataFrame | None = None,
    points: Mapping[str, Mapping[str, float]] | None = None,
) -> RankingResult:
    """Score every applicable candidate with its probe runs and rank them (BIC).

    ``probe_point`` is the parameter set the probes ran at (``point`` of the Find record); it
    gives the "absent" magnitude of a candidate whose absence is another parameter's value.
    A candidate in ``points`` (:func:`lead_points`) is scored with its runs in ``reprobes``
    instead: its reference (run :attr:`~demcal.discrepancy.candidates.Candidate.reference_case`)
    and levels at its own best fit.

    The reference is the mean of the ``discrepancy.replicates`` runs at theta* and a probe
    level the mean of its ``discrepancy.probe_replicates`` runs, each over the runs that
    finished. Observations without a value in any reference run are left out of the ranking
    (and the null fit is redone without them); a probe level without a value in any of its runs
    is dropped for its candidate; a candidate without any usable level is reported as not
    scored.
    """
    settings = config["discrepancy"]
    scores = _score(model_paths, experiment, config, runs, probe_point, reprobes, points)
    # Find on the observations the ranking keeps (its bootstrap is the ranking's only use of it).
    null = find(
        scores.model,
        scores.box,
        int(settings["grid_points"]),
        float(settings["alpha"]),
        float(settings["fit_z"]),
        draws=int(settings["bootstrap_draws"]),
    )
    obs = scores.model.observations
    notes = scores.notes
    fits, responses = scores.fits, scores.responses
    predictions, weights = scores.predictions, scores.weights
    candidates = parse_candidates(settings["candidates"])
    # dBIC orders the candidates; the bootstrap tests below decide whether the top one is named.
    scored, winner_name = scores.ranked(float(settings["min_explained"]))
    rows = scores.rows
    unscored = [r["candidate"] for r in rows if r["status"].startswith("not scored")]
    if winner_name is not None and unscored:
        notes.append(
            f"{winner_name} leads, but is not named: {', '.join(unscored)} could not be scored"
        )
        winner_name = None
    y = obs["measured"].to_numpy(float)
    alpha, points_m = float(settings["alpha"]), int(settings["magnitude_points"])
    boot = int(settings["bootstrap_draws"])
    test = None
    if responses:
        test = naming_test(predictions, y, weights, responses, points_m, boot)
    power = None
    if test is not None and int(settings["power_draws"]) > 0:
        draws = int(settings["power_draws"])
        power = naming_power(
            predictions, y, weights, responses, alpha, points_m, draws, null_drops=test.null_drops
        )
        # Each candidate the data cannot name, again with one parameter held at a time.
        hold = partial(
            power_with_fixed,
            scores.grid,
            predictions,
            list(scores.box.names),
            y,
            weights,
            responses,
        )
        fixed = {c: hold(c, alpha, points_m, draws, boot) for c in _unnameable(power)}
        notes += _power_notes(power, fixed)
    ambiguous = None
    if winner_name is not None and test is not None:
        winner_name, ambiguous = _tested_winner(
            winner_name, test, float(settings["alpha"]), obs, notes
        )
    if winner_name is not None and len(obs) < null.n_free + 2:
        # A candidate adds one parameter: with N <= d + 1 it can fit every value exactly.
        notes.append(
            f"{winner_name} leads, but is not named: {len(obs)} measured values cannot tell "
            f"{null.n_free + 1} fitted parameters apart (at least {null.n_free + 2} needed)"
        )
        winner_name = None
    info = pd.DataFrame(rows)
    table = scored.merge(info, on="candidate", how="right")
    table = table.sort_values(["rank"], na_position="last", kind="stable").reset_index(drop=True)
    table["named"] = table["candidate"] == winner_name
    table.loc[table["status"] == "scored", "status"] = np.where(
        table.loc[table["status"] == "scored", "named"], "named", "not significant"
    )
    if power is not None:
        table["power"] = table["candidate"].map(_power_text(power))
    winner = next((c for c in candidates if c.name == winner_name), None)
    return RankingResult(
        table, winner, fits, null, scores.null_deviance, notes, test, ambiguous, power
    )


def _power_text(power: pd.DataFrame) -> dict[str, str]:
    """Candidate -> its naming power per probe level, e.g. ``"1.5e+04: 8 %, 6.5e+04: 97 %"``."""
    return {
        name: ", ".join(f"{r.magnitude:.3g}: {100 * r.named:.0f} %" for r in rows.itertuples())
        for name, rows in power.groupby("candidate", sort=False)
    }


def _unnameable(power: pd.DataFrame) -> list[str]:
    """Candidates whose naming power stays below :data:`UNNAMEABLE` at every probe level."""
    best = power.groupby("candidate", sort=False)["named"].max()
    return [str(name) for name, share in best.items() if share < UNNAMEABLE]


def _power_notes(
    power: pd.DataFrame, fixed: Mapping[str, Mapping[str, float]] | None = None
) -> list[str]:
    """A note for each candidate that these measurements could not name at any probe level,
    with the parameters whose separate measurement would change that (``fixed``: candidate ->
    parameter -> best power with that parameter held, :func:`power_with_fixed`)."""
    notes = []
    for name in _unnameable(power):
        rows = power[power["candidate"] == name]
        best = rows.loc[rows["named"].idxmax()]
        note = (
            f"{name} could not be named from these measurements even if it were present "
            f"at its probe level {best['magnitude']:.3g}: data sets drawn with it there "
            f"show an effect in {100 * best['found']:.0f} % and name it in at most "
            f"{100 * best['named']:.0f} % - what it changes, the fitted parameters absorb "
            "or the noise hides; a 'nothing missing' or another name does not rule it out"
        )
        held = (fixed or {}).get(name) or {}
        helps = {p: v for p, v in held.items() if v >= UNNAMEABLE}
        if helps:
            note += "; it could be named with " + " or ".join(
                f"{p} measured on its own (up to {100 * v:.0f} % with {p} held at its best-fit "
                "value)"
                for p, v in sorted(helps.items(), key=lambda item: -item[1])
            )
        elif held:
            top = max(held, key=held.__getitem__)
            note += (
                "; holding any one of "
                + ", ".join(sorted(held))
                + " at its best-fit value, as a measurement of it alone would, does not change "
                f"that (at most {100 * held[top]:.0f} %, with {top} held)"
            )
        notes.append(note)
    return notes


def _mean_of_runs(runs: pd.DataFrame, run: str, count: int, obs: pd.DataFrame) -> np.ndarray:
    """Mean DEM value of each observation over the ``count`` replicates of ``run`` that gave
    one (NaN where none did), shape (K,)."""
    mean, _, _ = replicate_statistics(runs, replicate_bases(run, count), obs)
    return mean


def _tested_winner(
    leader: str, test: NamingTest, alpha: float, obs: pd.DataFrame, notes: list[str]
) -> tuple[str | None, tuple[str, str] | None]:
    """The leader if both bootstrap tests reject at ``alpha``, else None (with a note why);
    and the top candidate with the runner-up when it is the runner-up test that fails."""
    if test.p_effect >= alpha:
        notes.append(
            f"{leader} leads, but is not named: noise alone gives as large an improvement "
            f"(p = {test.p_effect:.3g} >= {alpha:g}, {test.draws} data sets drawn under "
            "'nothing missing')"
        )
        return None, None
    if test.runner_up is not None and test.p_runner_up is not None:
        if test.p_runner_up >= alpha:
            where = ""
            if test.separating is not None:
                row = obs.iloc[test.separating]
                label = condition_label(row)
                where = row["observable"] + ("" if label == "-" else f" at {label}")
            notes.append(
                f"{test.top} and {test.runner_up} cannot be told apart (p = "
                f"{test.p_runner_up:.3g} >= {alpha:g} that {test.runner_up} fits this much worse "
                f"by chance): their fits differ most in {where}; repeating that measurement or "
                "measuring near it separates them best"
            )
            return None, (test.top, test.runner_up)
    return leader, None


def ranking_record(result: RankingResult) -> dict[str, Any]:
    """JSON record of a ranking: the winner, the scored candidates and the winner's fit."""
    scored = result.table[result.table["rank"].notna()]
    record: dict[str, Any] = {
        "winner": result.winner.name if result.winner else None,
        "ran": True,
        "n_observations": len(result.find.observations),
        "null_deviance": result.null_deviance,
        "notes": result.notes,
        "p_effect": result.test.p_effect if result.test else None,
        "ambiguous": list(result.ambiguous) if result.ambiguous else None,
        "runner_up": result.test.runner_up if result.test else None,
        "p_runner_up": result.test.p_runner_up if result.test else None,
        "power": []
        if result.power is None
        else [
            {k: (str(v) if k == "candidate" else float(v)) for k, v in row.items()}
            for row in result.power.to_dict("records")
        ],
        "ranking": [
            {
                "candidate": r.candidate,
                "delta_bic": float(r.delta_bic),
                "magnitude": float(r.magnitude),
                "explained": float(r.explained),
            }
            for r in scored.itertuples()
        ],
    }
    if result.winner is not None:
        fit = result.fits[result.winner.name]
        record.update(
            {
                "parameter": result.winner.parameter,
                "magnitude": fit.magnitude,
                "theta": fit.best.theta,
            }
        )
    return record


def _empty(path: str | Path, columns: list[str]) -> None:
    pd.DataFrame(columns=columns).to_csv(path, index=False)


def write_ranking(
    model_paths: Mapping[str, str | Path],
    experiment_path: str | Path,
    config: Mapping[str, Any],
    find_record_path: str | Path,
    probe_files: Iterable[str | Path],
    table_path: str | Path,
    markdown_path: str | Path,
    record_path: str | Path,
    probes_path: str | Path,
    design_path: str | Path,
    lead_record_path: str | Path | None = None,
    reprobe_files: Iterable[str | Path] = (),
    reprobes_path: str | Path | None = None,
) -> RankingResult | None:
    """Rank the candidates and write the ranking, its record and the extended design.

    When Find found nothing missing the ranking is not run: the table, probe table and design
    are written empty, and the report and record say why.

    Parameters
    ----------
    model_paths : mapping
        Observable -> saved surrogate of the current model.
    experiment_path : path
        The experiment file with the measurements.
    config : mapping
        The validated configuration.
    find_record_path : path
        Record of the Find step (``missing``, ``verdict``, ``point``).
    probe_files : iterable of path
        ``bulk.csv`` of every probe run (none when nothing is missing).
    table_path, markdown_path, record_path : path
        Ranking table (CSV), report (markdown) and record (JSON) to write.
    probes_path : path
        All probe-run rows (CSV) to write.
    design_path : path
        Extended design of the named effect (CSV; only the header when none is named).
    lead_record_path : path, optional
        Record of :func:`write_lead`: the candidates probed again at their own best fit.
    reprobe_files : iterable of path
        ``bulk.csv`` of those runs.
    reprobes_path : path, optional
        Their rows (CSV) to write.

    Returns
    -------
    RankingResult or None
        None when the ranking was not run.
    """
    settings = config["discrepancy"]
    find_rec = json.loads(Path(find_record_path).read_text())
    if not find_rec["missing"]:
        empty = pd.DataFrame(columns=["rank", "candidate", "status"])
        empty.to_csv(table_path, index=False)
        Path(markdown_path).write_text(
            ranking_markdown(empty, None, 0, 0.0, verdict=find_rec["verdict"])
        )
        record = {"winner": None, "ran": False, "reason": find_rec["verdict"], "ranking": []}
        Path(record_path).write_text(json.dumps(record, indent=2) + "\n")
        _empty(design_path, ["case_id"])
        _empty(probes_path, ["case_id"])
        if reprobes_path is not None:
            _empty(reprobes_path, ["case_id"])
        return None
    # Held-out loads are kept for the DEM check of the Show step.
    experiment = fitted_experiment(load_experiment(experiment_path), config)
    runs = read_runs(probe_files)
    runs.to_csv(probes_path, index=False, float_format="%.8g")
    points = {}
    if lead_record_path is not None:
        points = json.loads(Path(lead_record_path).read_text())["points"]
    reprobes = read_runs(reprobe_files)
    if reprobes_path is not None:
        if len(reprobes):
            reprobes.to_csv(reprobes_path, index=False, float_format="%.8g")
        else:
            _empty(reprobes_path, ["case_id"])
    result = rank(model_paths, experiment, config, runs, find_rec["point"], reprobes, points)
    result.table.to_csv(table_path, index=False, float_format="%.6g")
    Path(markdown_path).write_text(
        ranking_markdown(
            result.table,
            result.winner.name if result.winner else None,
            len(result.find.observations),
            float(settings["alpha"]),
            float(settings["min_explained"]),
            result.notes,
            probe_runs=int(settings["probe_replicates"]),
            reference_runs=int(settings["replicates"]),
        )
    )
    if result.winner is not None:
        ext = settings["extended"]
        design = extended_design(config, result.winner, int(ext["n"]), int(ext["seed"]))
        design.to_csv(design_path, index=False, float_format="%.12g")
    else:
        _empty(design_path, ["case_id"])
    record = {**ranking_record(result), "probed_again_at": points}
    Path(record_path).write_text(json.dumps(record, indent=2) + "\n")
    write_sidecar(record_path, config)
    return result


def write_lead(
    model_paths: Mapping[str, str | Path],
    experiment_path: str | Path,
    config: Mapping[str, Any],
    find_record_path: str | Path,
    probe_files: Iterable[str | Path],
    record_path: str | Path,
) -> dict[str, dict[str, float]]:
    """Write the points where the leading candidates are probed again (:func:`lead_points`).

    Parameters
    ----------
    model_paths : mapping
        Observable -> saved surrogate of the current model.
    experiment_path : path
        The experiment file with the measurements.
    config : mapping
        The validated configuration.
    find_record_path : path
        Record of the Find step.
    probe_files : iterable of path
        ``bulk.csv`` of every probe run at theta* (none when nothing is missing).
    record_path : path
        The record (JSON): ``points``, candidate -> complete parameter set (SI units); empty
        when nothing is missing, no candidate was scored or ``discrepancy.reprobe`` is 0.

    Returns
    -------
    dict
        The ``points`` written.
    """
    find_rec = json.loads(Path(find_record_path).read_text())
    points: dict[str, dict[str, float]] = {}
    if find_rec["missing"]:
        experiment = fitted_experiment(load_experiment(experiment_path), config)
        runs = read_runs(probe_files)
        points = lead_points(model_paths, experiment, config, runs, find_rec["point"])
    record = {"reprobe": int(config["discrepancy"]["reprobe"]), "points": points}
    Path(record_path).write_text(json.dumps(record, indent=2) + "\n")
    write_sidecar(record_path, config)
    return points
