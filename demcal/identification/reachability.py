"""Can the model reach the measurement? The measured values against the DEM results of the design.

The screening can only find sets that the surrogates place within the tolerance of a measured
value, and the surrogates only know the range the DEM runs of the design box covered. A measured
value outside that range (widened by the tolerance) cannot be matched by any set in the box: the
model lacks an effect, the box is too small, or the virtual test does not measure what the real
test does. The range is taken over parameter sets, each the mean of its replicate runs (the
value its surrogate learns), not over single runs, whose seed-to-seed scatter (one quick heap
about 1.7 deg) would widen it. A value that only a few sets reach lies at the edge of what the
model reaches: the highest sets of a design still carry the scatter of their few runs, so they
overstate the highest value a parameter set gives on average, and the sets found there rest on
the surrogates where they learnt least. Such verdicts belong at the top of the report,
before any table that would otherwise suggest a calibration.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from demcal.core.experiments import Experiment

__all__ = [
    "EDGE_SHARE",
    "Reach",
    "edge_sets",
    "reach_of_measurements",
    "reach_statement",
    "set_means",
]

#: A measured value lies inside the model's reach when at least this share of the parameter sets
#: (and at least one) lies beyond it on its far side, i.e. inside about the central 90 % of them.
EDGE_SHARE = 0.05


@dataclass(frozen=True)
class Reach:
    """One measured value against the DEM values of the design's parameter sets at its load
    condition (each set the mean of its replicate runs).

    Attributes
    ----------
    observable : str
        ``mu_psh``, ``mu_sh``, ``rho_b`` or ``aor``.
    condition : str
        The load condition (``"1068 Pa, P = 1"``) or ``"angle of repose"``.
    measured : float
        The measured value (its unit).
    dem_min, dem_max : float
        Range of the sets' finite DEM values at that condition (NaN when there are none).
    n_sets : int
        Parameter sets with a finite value at that condition.
    above : bool
        Whether the measured value lies above the sets' median (its far side is above it).
    n_beyond : int
        Parameter sets beyond the measured value on its far side.
    reachable : bool
        ``dem_min (1 - tol) <= measured <= dem_max (1 + tol)``.
    inside : bool
        ``n_beyond >= edge_sets(n_sets)``: enough sets lie beyond the measured value that it
        is not reached by the scatter of a few runs alone.
    """

    observable: str
    condition: str
    measured: float
    dem_min: float
    dem_max: float
    n_sets: int
    above: bool
    n_beyond: int
    reachable: bool
    inside: bool


def edge_sets(n_sets: int) -> int:
    """Parameter sets that must lie beyond a measured value for it to count as inside the
    model's reach.

    Parameters
    ----------
    n_sets : int
        Parameter sets with a finite value at the measurement's condition.

    Returns
    -------
    int
        ``max(1, ceil(EDGE_SHARE * n_sets))``: one set for up to 20 sets, four for 64.
    """
    return max(1, math.ceil(EDGE_SHARE * n_sets - 1e-9))


def set_means(rows: pd.DataFrame, name: str) -> np.ndarray:
    """The finite values of ``name`` per parameter set, each the mean of its replicate runs.

    Parameters
    ----------
    rows : pandas.DataFrame
        Runs at one load condition, with the column ``name`` and ``design_id`` (a row without
        an id counts as a set of its own).
    name : str
        The bulk value.

    Returns
    -------
    numpy.ndarray, shape (n_sets,)
        Means over each set's runs with a finite value.
    """
    if name not in rows:
        return np.empty(0)
    values = pd.to_numeric(rows[name], errors="coerce")
    keep = np.isfinite(values.to_numpy(dtype=np.float64))
    if "design_id" not in rows:
        return values[keep].to_numpy(dtype=np.float64)
    ids = rows["design_id"].astype(object).where(rows["design_id"].notna(), rows.index.to_series())
    return values[keep].groupby(ids[keep].astype(str)).mean().to_numpy(dtype=np.float64)


def _shear_rows(data: pd.DataFrame, stress: float | None, p: float | None) -> pd.DataFrame:
    shear = data[data["test"] == "shear_cell"]
    if stress is None or p is None:  # a condition without load: every shear run
        return shear
    return shear[
        (shear["normal_stress"] - stress).abs().le(1e-6 * stress) & (shear["P"] - p).abs().le(1e-9)
    ]


def reach_of_measurements(data: pd.DataFrame, experiment: Experiment, tol: float) -> list[Reach]:
    """Compare every measured value with the range of the DEM values at its condition.

    Parameters
    ----------
    data : pandas.DataFrame
        The bulk-value dataset (``results/bulk/dataset.csv``): one row per DEM case with
        columns ``test``, ``normal_stress`` (Pa), ``P`` and the bulk values.
    experiment : Experiment
        The measurements.
    tol : float
        Relative acceptance tolerance of the screening (e.g. 0.05).

    Returns
    -------
    list of Reach
        One entry per measured value, in the experiment's order.
    """
    out: list[Reach] = []
    checks: list[tuple[str, str, float, np.ndarray]] = []
    for cond in experiment.shear_conditions:
        rows = _shear_rows(data, cond.normal_stress, cond.P)
        for name, measured in cond.values.items():
            checks.append((name, cond.label, measured, set_means(rows, name)))
    if experiment.angle_of_repose is not None:
        heaps = data[data["test"] == "angle_of_repose"]
        checks.append(
            ("aor", "angle of repose", experiment.angle_of_repose, set_means(heaps, "aor"))
        )
    for name, condition, measured, finite in checks:
        lo = float(finite.min()) if finite.size else np.nan
        hi = float(finite.max()) if finite.size else np.nan
        reachable = bool(finite.size) and lo * (1.0 - tol) <= measured <= hi * (1.0 + tol)
        above = bool(finite.size) and measured > float(np.median(finite))
        beyond = int((finite > measured).sum() if above else (finite < measured).sum())
        inside = bool(finite.size) and beyond >= edge_sets(finite.size)
        out.append(
            Reach(
                name,
                condition,
                float(measured),
                lo,
                hi,
                int(finite.size),
                above,
                beyond,
                reachable,
                inside,
            )
        )
    return out


def _edge_part(r: Reach) -> str:
    side = "above" if r.above else "below"
    sets = (
        "every parameter set"
        if r.n_beyond == 0
        else f"{r.n_sets - r.n_beyond} of the {r.n_sets} parameter sets"
    )
    return (
        f"{r.observable} ({r.condition}) measured {r.measured:.4g}, {side} {sets} of the design "
        f"box ({r.dem_min:.4g} to {r.dem_max:.4g}, means of each set's DEM runs)"
    )


def reach_statement(reach: list[Reach], material: str) -> str:
    """One sentence for the first line of a report: every measurement reachable, or which not.

    Parameters
    ----------
    reach : list of Reach
        From :func:`reach_of_measurements`.
    material : str
        Name of the measured material.

    Returns
    -------
    str
        A single line (no trailing newline).
    """
    missing = [r for r in reach if not r.reachable]
    if not missing:
        edge = [r for r in reach if not r.inside]
        if not edge:
            return (
                f"Every measured value of {material} lies within the range the parameter sets "
                "of the design box cover."
            )
        # Within the tolerance of the range but beyond all or all but a few sets: the screening
        # then relies on the surrogate where it has the fewest runs around it, and the few sets
        # that reach the value may owe it to seed scatter.
        return (
            f"**The measurement of {material} lies at the edge of what the model reaches**: "
            + "; ".join(_edge_part(r) for r in edge)
            + ". Within the tolerance, but the sets found there rest on the surrogates at the "
            "edge of what the runs cover and may miss in the verification; widen the box or add "
            "the missing effect (docs/discrepancy.md)."
        )
    parts = []
    for r in missing:
        if r.n_sets == 0:
            parts.append(f"{r.observable} ({r.condition}): no DEM run of the design has a value")
        else:
            parts.append(
                f"{r.observable} ({r.condition}) measured {r.measured:.4g}, parameter sets of "
                f"the design box {r.dem_min:.4g} to {r.dem_max:.4g}"
            )
    return (
        f"**The model cannot reach the measurement of {material}**: "
        + "; ".join(parts)
        + ". No parameter set in the box reproduces it; widen the box, add the missing effect "
        "(docs/discrepancy.md) or check that the virtual test measures what the real one does."
    )
