"""What the replicate DEM runs of the Show step say about an added effect.

The extended model, run at its identified point, is compared with the measurements and with
the current model at theta* (both as means of ``discrepancy.replicates`` runs from fresh
packings), by the gap G = sqrt(mean z^2) over the fitted loads and apart over the held-out
loads. Three verdicts:

* ``confirmed``: the extended model is closer to the fitted measurements than the current
  one, at the held-out loads within the noise or closer than before, and what remains on the
  fitted loads is within the noise: N G^2 at most the (1 - alpha) quantile of chi^2 with N
  degrees of freedom, N the fitted values (G = 1.37 at N = 9 and alpha = 0.05);
* ``gap remains``: closer, held-out loads as above, but the remaining gap is more than noise
  explains: the effect accounts for part of the discrepancy, or stands in for an effect the
  catalogue lacks, and something is still missing;
* ``not confirmed``: no closer in DEM, or the held-out loads pushed out of the noise: a proxy
  that fits only the surrogates or only the loads it was fitted on.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
from scipy.stats import chi2

__all__ = [
    "CONFIRMED",
    "GAP_REMAINS",
    "NOISE_GAP",
    "NOT_CONFIRMED",
    "dem_confirms",
    "dem_noise_bound",
    "effect_verdict",
    "fitted_dem_values",
]

#: A gap (root mean square of z) at or below this is within the noise.
NOISE_GAP = 1.0
#: Verdict: closer, held-out loads as good or better, and the gap left within the noise.
CONFIRMED = "confirmed"
#: Verdict: closer and held-out loads as good or better, but a gap above the noise is left.
GAP_REMAINS = "gap remains"
#: Verdict: no closer in DEM, or the held-out loads pushed out of the noise.
NOT_CONFIRMED = "not confirmed"


def dem_confirms(
    dem_gap_before: float,
    dem_gap_after: float,
    held_out_before: float = math.nan,
    held_out_after: float = math.nan,
) -> bool:
    """Whether the DEM runs bear out an added effect (closer, and not worse where unfitted).

    The extended model at its identified point must be closer to the fitted measurements than
    the current model at theta* (replicate means), and at held-out loads (when there are any)
    within the noise (gap <= :data:`NOISE_GAP`) or closer than before. A proxy that only fits
    the surrogates, or only the loads it was fitted on, fails. Whether the gap left is noise
    is :func:`effect_verdict`'s second question.

    Parameters
    ----------
    dem_gap_before, dem_gap_after : float
        DEM gaps on the fitted loads, -.
    held_out_before, held_out_after : float
        DEM gaps on the held-out loads, -; NaN when there are none.
    """
    if not (math.isfinite(dem_gap_before) and math.isfinite(dem_gap_after)):
        return False
    if dem_gap_after >= dem_gap_before:
        return False
    if math.isfinite(held_out_after):
        return held_out_after <= max(NOISE_GAP, held_out_before)
    return True


def fitted_dem_values(table: pd.DataFrame) -> int:
    """Measured values on the fitted loads that have a DEM mean after the effect was added.

    Parameters
    ----------
    table : pandas.DataFrame, shape (n_observations, ...)
        The Show step's before/after table (``gap_before_after.csv``), with the columns
        ``held_out`` (bool) and ``z_dem_after`` (-, NaN where no run finished).

    Returns
    -------
    int
        The N of the gap G over the fitted loads.
    """
    fitted = table.loc[~table["held_out"].astype(bool), "z_dem_after"]
    return int(np.isfinite(fitted.to_numpy(dtype=float)).sum())


def dem_noise_bound(n_values: int, alpha: float) -> float:
    """Largest gap G = sqrt(mean z^2) over ``n_values`` values that noise explains.

    Parameters
    ----------
    n_values : int
        Measured values the gap is taken over (>= 1).
    alpha : float
        Level of the test, in (0, 1).

    Returns
    -------
    float
        sqrt(chi2.ppf(1 - alpha, n_values) / n_values), -.
    """
    if n_values < 1 or not 0.0 < alpha < 1.0:
        raise ValueError(f"need n_values >= 1 and 0 < alpha < 1, got {n_values}, {alpha}")
    return math.sqrt(float(chi2.ppf(1.0 - alpha, n_values)) / n_values)


def effect_verdict(
    dem_gap_before: float,
    dem_gap_after: float,
    held_out_before: float,
    held_out_after: float,
    n_fitted: int,
    alpha: float,
) -> str:
    """The DEM runs' verdict on an added effect (see the module notes).

    Parameters
    ----------
    dem_gap_before, dem_gap_after : float
        DEM gaps on the fitted loads, -.
    held_out_before, held_out_after : float
        DEM gaps on the held-out loads, -; NaN when there are none.
    n_fitted : int
        Measured values on the fitted loads with a DEM mean after.
    alpha : float
        Level of the noise test, in (0, 1) (Find's ``alpha``).

    Returns
    -------
    str
        :data:`CONFIRMED`, :data:`GAP_REMAINS` or :data:`NOT_CONFIRMED`.
    """
    if not dem_confirms(dem_gap_before, dem_gap_after, held_out_before, held_out_after):
        return NOT_CONFIRMED
    if n_fitted < 1 or dem_gap_after > dem_noise_bound(n_fitted, alpha):
        return GAP_REMAINS
    return CONFIRMED
