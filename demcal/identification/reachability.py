"""Can the model reach the measurement? The measured values against the DEM results of the design.

The screening can only find sets that the surrogates place within the tolerance of a measured
value, and the surrogates only know the range the DEM runs of the design box covered. A measured
value outside that range (widened by the tolerance) cannot be matched by any set in the box: the
model lacks an effect, the box is too small, or the virtual test does not measure what the real
test does. A value that only a few runs reach lies at the edge of what the model reaches: a
single run scatters from seed to seed (one quick heap by about 2 deg), so the highest runs of a
design overstate the highest value a parameter set gives on average, and the sets found there
rest on the surrogates where they learnt least. Such verdicts belong at the top of the report,
before any table that would otherwise suggest a calibration.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from demcal.core.experiments import Experiment

__all__ = ["EDGE_SHARE", "Reach", "edge_runs", "reach_of_measurements", "reach_statement"]

#: A measured value lies inside the model's reach when at least this share of the DEM runs (and
#: at least one) lies beyond it on its far side, i.e. inside about the central 90 % of the runs.
EDGE_SHARE = 0.05


@dataclass(frozen=True)
class Reach:
    """One measured value against the DEM values of the design at its load condition.

    Attributes
    ----------
    observable : str
        ``mu_psh``, ``mu_sh``, ``rho_b`` or ``aor``.
    condition : str
        The load condition (``"1068 Pa, P = 1"``) or ``"angle of repose"``.
    measured : float
        The measured value (its unit).
    dem_min, dem_max : float
        Range of the finite DEM values at that condition (NaN when there are none).
    n_runs : int
        DEM runs with a finite value at that condition.
    above : bool
        Whether the measured value lies above the runs' median (its far side is above it).
    n_beyond : int
        DEM runs beyond the measured value on its far side.
    reachable : bool
        ``dem_min (1 - tol) <= measured <= dem_max (1 + tol)``.
    inside : bool
        ``n_beyond >= edge_runs(n_runs)``: enough DEM runs lie beyond the measured value that
        it is not reached by seed scatter alone.
    """

    observable: str
    condition: str
    measured: float
    dem_min: float
    dem_max: float
    n_runs: int
    above: bool
    n_beyond: int
    reachable: bool
    inside: bool


def edge_runs(n_runs: int) -> int:
    """Runs that must lie beyond a measured value for it to count as inside the model's reach.

    Parameters
    ----------
    n_runs : int
        DEM runs with a finite value at the measurement's condition.

    Returns
    -------
    int
        ``max(1, ceil(EDGE_SHARE * n_runs))``: one run for up to 20 runs, four for 64.
    """
    return max(1, math.ceil(EDGE_SHARE * n_runs - 1e-9))


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
    checks: list[tuple[str, str, float, pd.Series]] = []
    for cond in experiment.shear_conditions:
        rows = _shear_rows(data, cond.normal_stress, cond.P)
        for name, measured in cond.values.items():
            values = rows[name] if name in rows else pd.Series(dtype=float)
            checks.append((name, cond.label, measured, values))
    if experiment.angle_of_repose is not None:
        aor = data.loc[data["test"] == "angle_of_repose", "aor"] if "aor" in data else None
        checks.append(
            (
                "aor",
                "angle of repose",
                experiment.angle_of_repose,
                aor if aor is not None else pd.Series(dtype=float),
            )
        )
    for name, condition, measured, values in checks:
        finite = pd.to_numeric(values, errors="coerce").to_numpy(dtype=np.float64)
        finite = finite[np.isfinite(finite)]
        lo = float(finite.min()) if finite.size else np.nan
        hi = float(finite.max()) if finite.size else np.nan
        reachable = bool(finite.size) and lo * (1.0 - tol) <= measured <= hi * (1.0 + tol)
        above = bool(finite.size) and measured > float(np.median(finite))
        beyond = int((finite > measured).sum() if above else (finite < measured).sum())
        inside = bool(finite.size) and beyond >= edge_runs(finite.size)
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
    runs = (
        "every DEM run"
        if r.n_beyond == 0
        else f"{r.n_runs - r.n_beyond} of the {r.n_runs} DEM runs"
    )
    return (
        f"{r.observable} ({r.condition}) measured {r.measured:.4g}, {side} {runs} of the design "
        f"box ({r.dem_min:.4g} to {r.dem_max:.4g})"
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
                f"Every measured value of {material} lies within the range the DEM runs of the "
                "design box cover."
            )
        # Within the tolerance of the range but beyond all or all but a few runs: the screening
        # then relies on the surrogate where it has the fewest runs around it, and the few runs
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
        if r.n_runs == 0:
            parts.append(f"{r.observable} ({r.condition}): no DEM run of the design has a value")
        else:
            parts.append(
                f"{r.observable} ({r.condition}) measured {r.measured:.4g}, DEM runs of the "
                f"design box {r.dem_min:.4g} to {r.dem_max:.4g}"
            )
    return (
        f"**The model cannot reach the measurement of {material}**: "
        + "; ".join(parts)
        + ". No parameter set in the box reproduces it; widen the box, add the missing effect "
        "(docs/discrepancy.md) or check that the virtual test measures what the real one does."
    )
