"""Find where a calibrated model and the measurements disagree (discrepancy workflow, step 1).

With the observations y_k, their uncertainties sigma_k and the surrogate predictions f_k of
:mod:`demcal.discrepancy.observations`, the normalised misfit of observation k at a parameter
set theta is

    z_k(theta) = (f_k(theta) - y_k) / sigma_k.

Over the parameter box (a regular grid, then a bounded local refinement of the best grid point,
:mod:`demcal.discrepancy.best_fit`) this module finds

* per observation, the range of values the model reaches and the smallest achievable |z_k|;
* the joint best point theta* = argmin chi^2, chi^2 = sum_k z_k^2;
* the gap figure G = sqrt(chi^2(theta*) / N): about 1 or less when the model explains the data
  within its uncertainty, clearly above 1 when it cannot;
* the verdict, from a parametric bootstrap of "nothing missing": data sets drawn as
  y* = f(theta*) + sigma * N(0, 1) are fitted over the same grid, and p is the share of them
  whose best chi^2 reaches the observed one. Something is missing when p < alpha, so that on
  data the model does describe the verdict is wrong in a share alpha of the cases, whatever N
  and the number of parameters (a fixed threshold on G has a false-alarm rate that depends on
  both, and is far from its large-N value at the few values a shear test gives).

A verdict needs more measured values than the box has free parameters: with N <= d the best fit
can match N values exactly whatever the material lacks, so Find then says that the data are too
few (and how many are needed) instead of "nothing missing". Naming an effect adds one parameter,
so it needs N >= d + 2.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from demcal.discrepancy.best_fit import (
    BestFit,
    ParameterBox,
    best_deviances,
    exceedance_p,
    minimise_chi2,
    pinned_parameters,
)
from demcal.discrepancy.observations import OBSERVABLES, SurrogateModel, format_stress

__all__ = [
    "FindResult",
    "describe_disagreement",
    "describe_pinned",
    "find",
    "null_deviances",
]


@dataclass
class FindResult:
    """Outcome of the Find step.

    Attributes
    ----------
    observations : DataFrame, shape (K, ...)
        The observation table plus reach_min, reach_max (model range over the box),
        best_abs_z (smallest achievable |z|), at_best (value at theta*), z_at_best.
    best : BestFit
        theta* and chi^2(theta*).
    gap : float
        sqrt(chi^2(theta*) / K).
    alpha : float
        Significance level of the verdict (its false-alarm rate on data without a missing
        effect).
    sentences : list[str]
        Where the disagreement sits, one sentence per observable, and one more when theta* sits
        on the boundary of the box.
    pinned : dict[str, str]
        Parameters of theta* on a bound of the box: name -> "lower" or "upper".
    n_free : int
        Free parameters of the box (axes with a non-zero width), d.
    p_value : float
        Share of the bootstrap data sets of "nothing missing" whose best grid chi^2 reaches the
        observed one (counting the observed set itself).
    draws : int
        Bootstrap data sets.
    """

    observations: pd.DataFrame
    best: BestFit
    gap: float
    alpha: float
    sentences: list[str]
    pinned: dict[str, str] = field(default_factory=dict)
    n_free: int = 0
    p_value: float = 1.0
    draws: int = 0

    @property
    def too_few(self) -> bool:
        """True when N <= d: the best fit can match every value, so no verdict is possible."""
        return len(self.observations) <= self.n_free

    @property
    def missing(self) -> bool:
        """True when "nothing missing" is rejected at ``alpha`` on enough data."""
        return not self.too_few and self.p_value < self.alpha

    @property
    def verdict(self) -> str:
        n, d = len(self.observations), self.n_free
        if self.too_few:
            return (
                f"{n} measured value{'s' if n != 1 else ''} for {d} free parameter"
                f"{'s' if d != 1 else ''}: too few for a verdict (the best fit can match them "
                f"whatever is missing) -> measure at least {d + 1} values (another load "
                f"condition, P or the angle of repose), {d + 2} to name a missing effect"
            )
        test = f"gap {self.gap:.2f}, p = {self.p_value:.3g}"
        if self.missing:
            text = (
                f"{test} < {self.alpha:g}: the model cannot reproduce the measurements within "
                "their uncertainty -> a physical effect is missing"
            )
            if n < d + 2:
                text += f" (naming it needs at least {d + 2} measured values, {n} given)"
            return text
        text = f"{test} >= {self.alpha:g}: within noise -> nothing missing"
        if self.pinned:
            text += f", but theta* sits on the box boundary ({', '.join(self.pinned)})"
        return text


def describe_pinned(pinned: Mapping[str, str], box: ParameterBox) -> str:
    """One sentence on the parameters of theta* that sit on a bound of the box."""
    parts = [
        f"{name} at its {side} bound {box.bounds[name][0 if side == 'lower' else 1]:g}"
        for name, side in pinned.items()
    ]
    return (
        "theta* sits on the boundary of the parameter box (" + ", ".join(parts) + "): the best "
        "fit may lie outside it. Widen the box where such values are physical; where they are "
        "not, these parameters are standing in for an effect the model lacks."
    )


def null_deviances(
    predictions: np.ndarray, fitted: np.ndarray, sigma: np.ndarray, draws: int, seed: int
) -> np.ndarray:
    """Best grid chi^2 of data sets drawn under "nothing missing" (parametric bootstrap).

    Parameters
    ----------
    predictions : ndarray, shape (G, K)
        Model predictions at the G grid points.
    fitted : ndarray, shape (K,)
        Predictions at the best fit, the data's expectation under "nothing missing".
    sigma : ndarray, shape (K,)
        Uncertainties of the K values.
    draws : int
        Data sets drawn, y* = fitted + sigma * N(0, 1).
    seed : int
        Seed of the draws.

    Returns
    -------
    ndarray, shape (draws,)
        min over the grid of chi^2(y*) for each data set.
    """
    rng = np.random.default_rng(seed)
    data = fitted + sigma * rng.standard_normal((draws, fitted.size))
    return best_deviances(predictions, data, sigma)


def find(
    model: SurrogateModel,
    box: ParameterBox,
    grid_points: int,
    alpha: float = 0.05,
    fit_z: float = 2.0,
    refine: bool = True,
    draws: int = 1000,
    seed: int = 0,
) -> FindResult:
    """Best achievable misfit per observation, the joint best point and the gap figure.

    Parameters
    ----------
    model : SurrogateModel
        Predictions of the K observations (its ``observations`` hold measured and sigma).
    box : ParameterBox
        The parameter box, with the names of ``model.parameters`` in the same order.
    grid_points : int
        Points per continuous axis of the regular grid.
    alpha : float
        Significance level of the verdict.
    fit_z : float
        |z| at or below which an observation counts as fitted in the sentences.
    refine : bool
        Refine theta* with L-BFGS-B from the best grid point.
    draws : int
        Bootstrap data sets of the verdict (the p-value resolves 1 / (draws + 1)).
    seed : int
        Seed of the bootstrap.
    """
    if not 0.0 < alpha < 1.0:
        raise ValueError(f"alpha must lie in (0, 1), got {alpha}")
    if draws < 1:
        raise ValueError(f"draws must be at least 1, got {draws}")
    if box.names != model.parameters:
        raise ValueError(f"box parameters {box.names} differ from model's {model.parameters}")
    obs = model.observations.copy()
    y = obs["measured"].to_numpy(float)
    sigma = obs["sigma"].to_numpy(float)
    grid = box.grid(grid_points)
    F = model.predict(grid)
    Z = (F - y) / sigma
    chi2 = np.sum(Z**2, axis=1)

    def objective(theta: np.ndarray) -> np.ndarray:
        return np.sum(((model.predict(theta) - y) / sigma) ** 2, axis=1)

    theta, value = minimise_chi2(objective, box, grid, chi2, refine=refine)
    at_best = model.predict(theta[None, :])[0]
    obs["reach_min"] = F.min(axis=0)
    obs["reach_max"] = F.max(axis=0)
    obs["best_abs_z"] = np.minimum(np.abs(Z).min(axis=0), np.abs(at_best - y) / sigma)
    obs["at_best"] = at_best
    obs["z_at_best"] = (at_best - y) / sigma
    best = BestFit(dict(zip(box.names, map(float, theta), strict=True)), value, at_best)
    gap = math.sqrt(value / len(obs))
    pinned = pinned_parameters(best.theta, box)
    sentences = describe_disagreement(obs, fit_z)
    if pinned:
        sentences.append(describe_pinned(pinned, box))
    n_free = sum(1 for lo, hi in box.bounds.values() if hi > lo)
    # The observed statistic is the grid minimum, as for the bootstrap sets.
    g0 = int(np.argmin(chi2))
    null = null_deviances(F, F[g0], sigma, draws, seed)
    p_value = float(exceedance_p(null, chi2[g0]))
    return FindResult(obs, best, gap, alpha, sentences, pinned, n_free, p_value, draws)


_NAMES = {
    "mu_psh": "mu_psh",
    "mu_sh": "mu_sh",
    "rho_b": "rho_b",
    "aor": "the angle of repose",
}


def _where(rows: pd.DataFrame) -> str:
    if rows["normal_stress"].isna().all():
        return ""
    parts = []
    for stress, group in rows.groupby("normal_stress", sort=True):
        ps = ", ".join(f"{p:g}" for p in sorted(group["P"]))
        parts.append(f"{format_stress(stress)} (P = {ps})")
    return " at " + "; ".join(parts)


def describe_disagreement(obs: pd.DataFrame, fit_z: float = 2.0) -> list[str]:
    """One sentence per observable saying where the disagreement sits.

    An observation is *unreachable* when its measurement lies more than ``fit_z`` sigma outside
    the range the model reaches anywhere in the box (reported as the percentage beyond that
    range), *in conflict* when the model can reach it alone but not together with the others
    (|z| at theta* above ``fit_z``), and *fits* otherwise.

    Parameters
    ----------
    obs : DataFrame
        ``FindResult.observations`` (needs measured, sigma, reach_min, reach_max, z_at_best).
    fit_z : float
        |z| at or below which an observation fits.
    """
    sentences = []
    for name in [o for o in OBSERVABLES if o in set(obs["observable"])]:
        rows = obs[obs["observable"] == name]
        label = _NAMES[name]
        above = rows[rows["measured"] > rows["reach_max"] + fit_z * rows["sigma"]]
        below = rows[rows["measured"] < rows["reach_min"] - fit_z * rows["sigma"]]
        unreachable = set(above.index) | set(below.index)
        rest = rows[~rows.index.isin(unreachable)]
        conflict = rest[rest["z_at_best"].abs() > fit_z]
        fits = rest[rest["z_at_best"].abs() <= fit_z]
        parts = []
        if len(above):
            pct = 100.0 * (above["measured"] / above["reach_max"] - 1.0)
            parts.append(
                f"{label}{_where(above)} is {_span(pct)} % above anything the model reaches"
            )
        if len(below):
            pct = 100.0 * (1.0 - below["measured"] / below["reach_min"])
            parts.append(
                f"{label}{_where(below)} is {_span(pct)} % below anything the model reaches"
            )
        for sign, side in ((-1.0, "below"), (1.0, "above")):
            group = conflict[np.sign(conflict["z_at_best"]) == sign]
            if len(group):
                z = group["z_at_best"].abs()
                parts.append(
                    f"{label}{_where(group)} is reachable alone, but the best joint fit stays "
                    f"{_span(z, '.1f')} sigma {side} it"
                )
        if not parts:
            sentences.append(f"{label} fits{_where(rows)}.")
            continue
        text = "; ".join(parts)
        if len(fits):
            where = _where(fits)
            text += f", while{where} it fits" if where else ", while the rest fits"
        sentences.append(text + ".")
    return sentences


def _span(values: pd.Series, fmt: str = ".0f") -> str:
    lo, hi = format(float(values.min()), fmt), format(float(values.max()), fmt)
    return lo if lo == hi else f"{lo}-{hi}"
