"""Identification: screening the candidate grid against the measurements (paper eqs. 3-4).

Three screenings as in the paper's Table 5: the shear-cell conditions alone (SSC), the angle of
repose alone (AoR), and both (shear-cell conditions, then AoR on the marked sets).
"""

import gzip
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import torch

from demcal.core.experiments import Experiment, MeasuredCondition
from demcal.identification.acceptance import (
    acceptance_band,
    relative_deviation,
    within_tolerance,
)
from demcal.identification.candidate_grid import draw_axes
from demcal.identification.screening import screen
from demcal.identification.screening_stages import stage_from_condition
from demcal.identification.statistics import (
    combine_statistics,
    identified_parameters,
    valid_set_statistics,
)
from demcal.identification.verification import measured_observations

GROUPS = ("SSC", "AoR", "SSC & AoR")


class ConstantInputs:
    """A predictor with some inputs held at constants, exposing only the remaining ones.

    Parameters
    ----------
    model : object
        Has ``predict_torch(X: Tensor (n, d)) -> Tensor (n,)`` over ``features``.
    features : sequence of str
        The model's ordered input names.
    constants : mapping
        Values of inputs that are not screened (e.g. dCylDp of the test).
    """

    def __init__(self, model: Any, features: Sequence[str], constants: Mapping[str, float]):
        self.model = model
        self.features = list(features)
        self.constants = {k: float(v) for k, v in constants.items() if k in features}
        self.free = [f for f in self.features if f not in self.constants]

    def predict_torch(self, X: torch.Tensor) -> torch.Tensor:
        full = torch.empty((X.shape[0], len(self.features)), dtype=X.dtype)
        for k, name in enumerate(self.features):
            if name in self.constants:
                full[:, k] = self.constants[name]
            else:
                full[:, k] = X[:, self.free.index(name)]
        return self.model.predict_torch(full)

    def predict(self, X: np.ndarray) -> np.ndarray:
        return self.predict_torch(torch.as_tensor(X, dtype=torch.float32)).double().numpy()


@dataclass
class CalibrationResult:
    axes: dict[str, np.ndarray]
    valid: dict[str, pd.DataFrame]  # per group, the valid parameter sets
    n_total: int
    elapsed_s: float
    table5: pd.DataFrame
    identified: dict[str, dict[str, float]]
    identified_group: str
    # The surrogates' predictions at the identified mean set (:func:`predictions_at`).
    at_identified: list[dict[str, Any]] = field(default_factory=list)


def predictions_at(
    point: Mapping[str, float],
    predictors: Mapping[str, tuple[ConstantInputs, Sequence[str]]],
    experiment: Experiment,
    tol: float,
    coverage: float = 0.0,
) -> list[dict[str, Any]]:
    """The surrogates' prediction of every measured value at one parameter set.

    The mean of the valid sets need not be valid itself: when the valid region is curved or
    thin, its mean lies outside it, and a verification there misses although the screening
    worked. These predictions tell the two apart before any DEM run.

    Parameters
    ----------
    point : mapping
        Parameter name -> value (SI units), e.g. the identified means.
    predictors : mapping
        Output name -> (predictor, its free input names), as screened.
    experiment : Experiment
        The measurements.
    tol : float
        Relative acceptance tolerance.
    coverage : float
        Standard deviations of a measured value that widen its band, as in the screening
        (:func:`demcal.identification.acceptance.acceptance_band`).

    Returns
    -------
    list of dict
        Per measured value with a predictor, in the experiment's order: ``observable``,
        ``normal_stress`` (Pa) and ``P`` (None for the angle of repose), ``measured``,
        ``predicted``, ``deviation`` (|1 - predicted / measured|), ``band`` (the relative
        half-width it was accepted within) and ``within_tolerance``.
    """
    out: list[dict[str, Any]] = []
    for obs in measured_observations(experiment):
        name, measured = obs["observable"], float(obs["measured"])
        if name not in predictors:
            continue
        load = {
            k: float(obs[k])
            for k in ("normal_stress", "P")
            if obs[k] is not None and math.isfinite(obs[k])
        }
        inputs = {**point, **load}
        model, free = predictors[name]
        predicted = float(model.predict(np.array([[float(inputs[f]) for f in free]]))[0])
        sd = float(obs["measured_sd"])
        sds = {name: sd} if math.isfinite(sd) else {}
        accepted = within_tolerance(
            {name: np.array([predicted])}, {name: measured}, tol, sds, coverage
        )
        out.append(
            {
                "observable": name,
                "normal_stress": load.get("normal_stress"),
                "P": load.get("P"),
                "measured": measured,
                "predicted": predicted,
                "deviation": float(relative_deviation(predicted, measured)),
                "band": acceptance_band(measured, tol, sds.get(name), coverage),
                "within_tolerance": bool(accepted[0]),
            }
        )
    return out


def angle_condition(experiment: Experiment) -> MeasuredCondition:
    """The measured angle of repose as a condition without load, named ``aor`` (eq. 4)."""
    sd = experiment.angle_of_repose_sd
    return MeasuredCondition(
        {"aor": float(experiment.angle_of_repose)},
        {} if sd is None else {"aor": float(sd)},
        name="aor",
    )


def calibrate(
    surrogates: Mapping[str, tuple[Any, Sequence[str]]],
    experiment: Experiment,
    screening: Mapping[str, Any],
    constants: Mapping[str, Mapping[str, float]],
) -> CalibrationResult:
    """Screen the candidate grid and return the valid sets per group with Table 5.

    Parameters
    ----------
    surrogates : mapping
        Output name -> (model, feature names).
    experiment : Experiment
        The measurements; only what was measured is matched.
    screening : mapping
        The ``screening`` config section (axes, seed, chunk_size, threads, tolerance,
        measurement_coverage).
    constants : mapping
        Output name -> inputs held constant for that network (e.g. the test's dCylDp).

    Raises
    ------
    ValueError
        When a network input is neither a screening axis, a load variable nor a constant.
    """
    spec = {k: (float(v[0]), float(v[1]), int(v[2])) for k, v in screening["axes"].items()}
    axes = draw_axes(spec, int(screening["seed"]))
    tol = float(screening["tolerance"])
    coverage = float(screening["measurement_coverage"])
    predictors = {}
    for output, (model, features) in surrogates.items():
        wrapped = ConstantInputs(model, features, constants.get(output, {}))
        missing = [f for f in wrapped.free if f not in axes and f not in ("normal_stress", "P")]
        if missing:
            raise ValueError(
                f"network {output}: input(s) {missing} vary in the design but are neither "
                "screening axes (screening.axes) nor held constant"
            )
        predictors[output] = (wrapped, wrapped.free)
    shear_stages = [
        stage_from_condition(c, tol, coverage)
        for c in experiment.shear_conditions
        if all(o in predictors for o in c.values)
    ]
    aor_stages = (
        [stage_from_condition(angle_condition(experiment), tol, coverage)]
        if experiment.angle_of_repose is not None and "aor" in predictors
        else []
    )
    plans = {"SSC": shear_stages, "AoR": aor_stages, "SSC & AoR": shear_stages + aor_stages}
    valid: dict[str, pd.DataFrame] = {}
    n_total, elapsed = 0, 0.0
    for group, stages in plans.items():
        if not stages or (group == "SSC & AoR" and not (shear_stages and aor_stages)):
            continue
        result = screen(
            predictors,
            axes,
            fixed={},
            stages=stages,
            tol=tol,
            chunk_size=int(screening["chunk_size"]),
            num_threads=int(screening["threads"]),
        )
        valid[group] = result.to_frame(axes)
        n_total = result.n_total
        elapsed += result.elapsed_s
    ranges = {k: (v[0], v[1]) for k, v in spec.items()}
    tables = [
        valid_set_statistics(valid[g], ranges, n_total, label=g) for g in GROUPS if g in valid
    ]
    table5 = combine_statistics(tables) if tables else pd.DataFrame()
    chosen = next((g for g in reversed(GROUPS) if g in valid and len(valid[g]) > 0), None)
    identified = identified_parameters(valid[chosen], list(axes)) if chosen else {}
    at_identified = (
        predictions_at(
            {k: v["mean"] for k, v in identified.items()}, predictors, experiment, tol, coverage
        )
        if identified
        else []
    )
    return CalibrationResult(
        axes, valid, n_total, elapsed, table5, identified, chosen or "", at_identified
    )


def valid_sets_file(out_dir: str | Path, group: str) -> Path:
    """Where the valid sets of ``group`` go (``valid_ssc_aor.csv.gz`` for "SSC & AoR")."""
    name = group.lower().replace(" & ", "_").replace(" ", "_")
    return Path(out_dir) / f"valid_{name}.csv.gz"


def csv_text(frame: pd.DataFrame) -> str:
    """The text ``frame.to_csv(index=False, float_format="%.6g")`` writes, made faster.

    Each distinct value of a column is formatted once: the valid sets of a grid hold a few
    dozen values per parameter over up to millions of rows, and formatting every cell took
    most of the identification's time.

    Parameters
    ----------
    frame : pandas.DataFrame
        Float columns (parameter values in their SI units), shape (n_sets, n_parameters).

    Returns
    -------
    str
        Header line and one line per row; missing values are empty fields.
    """
    columns = []
    for name in frame.columns:
        codes, distinct = pd.factorize(frame[name], use_na_sentinel=False)
        text = np.array(["" if pd.isna(v) else f"{v:.6g}" for v in distinct], dtype=object)
        columns.append(pd.Series(text[codes], dtype=object))
    header = ",".join(map(str, frame.columns))
    if not columns or len(frame) == 0:
        return header + "\n"
    rows = columns[0].str.cat(columns[1:], sep=",") if len(columns) > 1 else columns[0]
    return "\n".join([header, *rows.tolist()]) + "\n"


def write_valid_sets(result: CalibrationResult, out_dir: str | Path) -> dict[str, Path]:
    """Valid sets per group as gzip-compressed CSV (:func:`valid_sets_file`)."""
    paths = {}
    for group, frame in result.valid.items():
        path = valid_sets_file(out_dir, group)
        # Level 6 (gzip's default): 5 % larger files than level 9 in a quarter of the time.
        with gzip.open(path, "wt", compresslevel=6, newline="") as out:
            out.write(csv_text(frame))
        paths[group] = path
    return paths
