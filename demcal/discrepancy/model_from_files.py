"""The surrogate model of the measured observations, built from saved surrogates and the
configuration, and the Find step on it with its output files."""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from demcal.core.experiments import Experiment, load_experiment
from demcal.core.provenance import write_sidecar
from demcal.design.cases import design_spec
from demcal.discrepancy.best_fit import ParameterBox
from demcal.discrepancy.candidates import Candidate, base_point
from demcal.discrepancy.dem_check import fitted_experiment
from demcal.discrepancy.extension import rmse_of
from demcal.discrepancy.find import FindResult, find
from demcal.discrepancy.observations import LOAD_INPUTS, SurrogateModel, observation_table
from demcal.discrepancy.report import find_markdown
from demcal.surrogates.training import TEST_OF, load_surrogate

__all__ = [
    "build_model",
    "find_from_files",
    "find_record",
    "load_surrogates",
    "surrogate_constants",
    "write_find",
]


def load_surrogates(
    paths: Mapping[str, str | Path],
) -> tuple[dict[str, tuple[Any, list[str]]], dict[str, float]]:
    """Saved surrogates (model, input names) and their held-out RMSE, per observable."""
    surrogates = {name: load_surrogate(path) for name, path in paths.items()}
    rmse = {name: rmse_of(path) for name, path in paths.items()}
    return surrogates, rmse


def surrogate_constants(config: Mapping[str, Any]) -> dict[str, dict[str, float]]:
    """Surrogate inputs held constant per observable: the test geometry ``dCylDp``."""
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
    constants = surrogate_constants(config)
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
        float(settings["alpha"]),
        float(settings["fit_z"]),
        draws=int(settings["bootstrap_draws"]),
    )
    return result, model, box


def find_record(result: FindResult, box: ParameterBox, config: Mapping[str, Any]) -> dict:
    """JSON record of a Find result: verdict, gap, theta* and the complete parameter set."""
    return {
        "missing": result.missing,
        "verdict": result.verdict,
        "gap": result.gap,
        "alpha": result.alpha,
        "p_value": result.p_value,
        "draws": result.draws,
        "chi2": result.best.deviance,
        "n_observations": len(result.observations),
        "n_free": result.n_free,
        "too_few": result.too_few,
        "theta": result.best.theta,
        "point": base_point(result.best.theta, config),
        "bounds": {k: list(v) for k, v in box.bounds.items()},
        "sentences": result.sentences,
        "pinned": result.pinned,
    }


def write_find(
    model_paths: Mapping[str, str | Path],
    experiment_path: str | Path,
    config: Mapping[str, Any],
    table_path: str | Path,
    record_path: str | Path,
    markdown_path: str | Path,
) -> FindResult:
    """Run Find on saved surrogates and write its table, record (with sidecar) and report.

    Parameters
    ----------
    model_paths : mapping
        Observable -> saved surrogate of the current model.
    experiment_path : path
        The experiment file with the measurements.
    config : mapping
        The validated configuration.
    table_path, record_path, markdown_path : path
        Per-observation CSV, JSON record (:func:`find_record`) and markdown report to write.
    """
    # Held-out loads are kept for the DEM check of the Show step.
    experiment = fitted_experiment(load_experiment(experiment_path), config)
    result, _, box = find_from_files(model_paths, experiment, config)
    record = find_record(result, box, config)
    result.observations.to_csv(table_path, index=False, float_format="%.8g")
    Path(record_path).write_text(json.dumps(record, indent=2) + "\n")
    Path(markdown_path).write_text(find_markdown(result, experiment.material, box.bounds))
    write_sidecar(record_path, config)
    return result
