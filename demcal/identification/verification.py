"""The loop the paper left open: DEM bulk values at the identified set against the measurements."""

import math

import pandas as pd

from demcal.core.experiments import Experiment


def verification_table(
    runs: pd.DataFrame, experiment: Experiment, tolerance: float
) -> pd.DataFrame:
    """One row per measured observable: measured, DEM at the identified set, deviation, within?

    Parameters
    ----------
    runs : DataFrame
        Bulk rows of the verification cases (tidy layout of ``demcal.bulk.dataset``).
    experiment : Experiment
        The measurements.
    tolerance : float
        Acceptance tolerance |1 - num/exp| (eqs. 3-4).
    """
    rows = []
    shear = runs[runs["test"] == "shear_cell"]
    for cond in experiment.shear_conditions:
        match = shear[
            (shear["normal_stress"] - cond.normal_stress).abs().lt(1e-6 * cond.normal_stress)
            & (shear["P"] - cond.P).abs().lt(1e-9)
        ]
        for name, measured in cond.values.items():
            dem = float(match[name].iloc[0]) if len(match) else math.nan
            rows.append(
                _row(
                    name,
                    cond.normal_stress,
                    cond.P,
                    measured,
                    cond.uncertainties.get(name),
                    dem,
                    tolerance,
                )
            )
    if experiment.angle_of_repose is not None:
        aor = runs[runs["test"] == "angle_of_repose"]
        dem = float(aor["aor"].iloc[0]) if len(aor) else math.nan
        rows.append(
            _row(
                "aor",
                math.nan,
                math.nan,
                experiment.angle_of_repose,
                experiment.angle_of_repose_sd,
                dem,
                tolerance,
            )
        )
    return pd.DataFrame(rows)


def _row(name, stress, p, measured, sd, dem, tolerance) -> dict:
    deviation = abs(1.0 - dem / measured) if math.isfinite(dem) else math.nan
    return {
        "observable": name,
        "normal_stress": stress,
        "P": p,
        "measured": measured,
        "measured_sd": sd if sd is not None else math.nan,
        "dem_identified": dem,
        "relative_deviation": deviation,
        "within_tolerance": bool(deviation < tolerance) if math.isfinite(deviation) else False,
    }
