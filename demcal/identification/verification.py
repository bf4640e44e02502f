"""The loop the paper left open: DEM bulk values at the identified set against the measurements,
on one engine or several side by side."""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
import pandas as pd

from demcal.core.experiments import Experiment
from demcal.identification.acceptance import relative_deviation, within_tolerance

#: Column of the largest relative difference between engines (two engines or more).
ENGINE_DIFFERENCE = "engine_difference"


def engine_columns(engine: str) -> tuple[str, str, str]:
    """Columns of one engine in the verification table: value, deviation, within tolerance."""
    return f"dem_{engine}", f"deviation_{engine}", f"within_tolerance_{engine}"


def scatter_columns(engine: str) -> tuple[str, str]:
    """Columns of one engine's replicate scatter: standard deviation and number of runs."""
    return f"dem_sd_{engine}", f"runs_{engine}"


def measured_observations(experiment: Experiment) -> list[dict]:
    """The measured observables in table order: name, load, measured value and sd.

    The angle of repose has no load: its ``normal_stress`` and ``P`` are NaN.
    """
    rows = []
    for cond in experiment.shear_conditions:
        for name, measured in cond.values.items():
            sd = cond.uncertainties.get(name)
            rows.append(
                {
                    "observable": name,
                    "normal_stress": cond.normal_stress,
                    "P": cond.P,
                    "measured": measured,
                    "measured_sd": sd if sd is not None else math.nan,
                }
            )
    if experiment.angle_of_repose is not None:
        sd = experiment.angle_of_repose_sd
        rows.append(
            {
                "observable": "aor",
                "normal_stress": math.nan,
                "P": math.nan,
                "measured": experiment.angle_of_repose,
                "measured_sd": sd if sd is not None else math.nan,
            }
        )
    return rows


def _dem_values(runs: pd.DataFrame, row: Mapping) -> np.ndarray:
    """The DEM values of the observable of ``row`` in ``runs``, one per replicate run that
    finished (empty when none matches)."""
    name = row["observable"]
    if name == "aor":
        values = runs.loc[runs["test"] == "angle_of_repose", "aor"]
    else:
        shear = runs[runs["test"] == "shear_cell"]
        stress, p = row["normal_stress"], row["P"]
        match = shear[
            (shear["normal_stress"] - stress).abs().lt(1e-6 * stress)
            & (shear["P"] - p).abs().lt(1e-9)
        ]
        values = match[name] if name in match else pd.Series(dtype=float)
    values = values.to_numpy(dtype=float)
    return values[np.isfinite(values)]


def verification_table(
    runs: Mapping[str, pd.DataFrame], experiment: Experiment, tolerance: float
) -> pd.DataFrame:
    """One row per measured observable: measured, each engine's DEM value and deviation.

    Parameters
    ----------
    runs : mapping of str to DataFrame
        Per engine name (in the order of the columns), the bulk rows of its verification cases
        (tidy layout of ``demcal.bulk.dataset``).
    experiment : Experiment
        The measurements.
    tolerance : float
        Acceptance tolerance |1 - num/exp| (eqs. 3-4).

    Returns
    -------
    pandas.DataFrame
        Columns ``observable``, ``normal_stress``, ``P``, ``measured``, ``measured_sd``, then per
        engine ``dem_<engine>`` (the mean over its replicate runs), ``dem_sd_<engine>`` (their
        sample standard deviation, NaN for one run), ``runs_<engine>`` (how many finished),
        ``deviation_<engine>`` (|1 - dem/measured|) and ``within_tolerance_<engine>``; with two
        engines or more, ``engine_difference``: the
        largest |1 - dem_other/dem_first| over the other engines, NaN when a value is missing
        (or the first engine's value is 0).
        A missing DEM value (no run at that load) is NaN and never within the tolerance.
    """
    if not runs:
        raise ValueError("no engine: nothing to verify")
    rows = measured_observations(experiment)
    for row in rows:
        values = []
        for engine, frame in runs.items():
            value, deviation, within = engine_columns(engine)
            sd, count = scatter_columns(engine)
            replicates = _dem_values(frame, row)
            dem = float(np.mean(replicates)) if replicates.size else math.nan
            row[value] = dem
            row[sd] = float(np.std(replicates, ddof=1)) if replicates.size > 1 else math.nan
            row[count] = int(replicates.size)
            name = row["observable"]
            accepted = within_tolerance({name: np.array([dem])}, {name: row["measured"]}, tolerance)
            row[deviation] = float(relative_deviation(dem, row["measured"]))
            row[within] = bool(accepted[0])
            values.append(dem)
        if len(values) > 1:
            first = values[0]
            row[ENGINE_DIFFERENCE] = (
                float(np.max(relative_deviation(values[1:], first))) if first != 0.0 else math.nan
            )
    return pd.DataFrame(rows)
