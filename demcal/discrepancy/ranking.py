"""Name the missing effect: score candidate effects by how much of the disagreement they explain
(discrepancy workflow, step 2).

For a candidate effect with magnitude a (one extra parameter, e.g. cohesionEnergyDensity), DEM
probe runs at theta* (the best point of the current model) measure how every observation k
responds: ``R_k(a_j) = DEM_k(theta*, a_j) - DEM_k(theta*, off)`` at the probe levels a_j. The
extended model is the surrogate plus this response, linearly interpolated between the levels:

    m_k(theta, a) = f_k(theta) + R_k(a),

which assumes that the effect acts additively near theta* (its response does not depend on
theta within the region the refit explores). A response is the difference of two DEM runs, each
with about the surrogate RMSE as noise, so the ranking weighs every observation with

    s_k^2 = sigma_k^2 + 2 rmse_k^2

for every candidate and for "nothing missing" alike: noisy observables count less, and no
candidate can gain from the noise of its probe runs through a larger variance. The deviance
D = sum_k ((y_k - m_k) / s_k)^2 is minimised over the parameter box and the probed magnitudes;
with the effect off it is the deviance D_0 of "nothing missing".

Ranking uses the Bayesian information criterion, BIC = D + p ln N. Against "nothing missing"
a candidate adds one parameter, so ``dBIC = D_0 - D_c - ln N``; dBIC / 2 approximates the log
Bayes factor of the candidate over "nothing missing" (Schwarz 1978; Kass & Raftery 1995: above
6 strong, above 10 very strong evidence). BIC rather than AIC because its penalty grows with
the number of observations and it targets the question asked here (which model is true, not
which predicts best), so it is the more conservative of the two against naming an effect that
is not there. A candidate is named only when its dBIC reaches a threshold, it removes at least
a given share of D_0, and every applicable candidate could be scored (otherwise the best of the
scored ones need not be the right one).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from demcal.discrepancy.find import (
    BestFit,
    ParameterBox,
    SurrogateModel,
    format_stress,
    minimise_chi2,
)

__all__ = [
    "CandidateFit",
    "EffectResponse",
    "fit_candidate",
    "null_fit",
    "rank_candidates",
    "ranking_sigma",
    "response_signature",
]


@dataclass(frozen=True)
class EffectResponse:
    """DEM response of the K observations to one candidate effect around theta*.

    Attributes
    ----------
    candidate : str
        Name of the effect.
    magnitudes : ndarray, shape (L,)
        Effect magnitudes of the probe runs, ascending, including the reference (effect off).
    responses : ndarray, shape (L, K)
        DEM value at each magnitude minus the reference run's value (units of the observable);
        the reference row is zero.
    reference : int
        Row of the reference run.
    integer : bool
        The magnitude only takes whole values.
    """

    candidate: str
    magnitudes: np.ndarray
    responses: np.ndarray
    reference: int
    integer: bool = False

    def __post_init__(self) -> None:
        m = np.asarray(self.magnitudes, dtype=float)
        r = np.asarray(self.responses, dtype=float)
        if m.ndim != 1 or m.size < 2:
            raise ValueError(f"{self.candidate}: need the reference and at least one level")
        if np.any(np.diff(m) <= 0):
            raise ValueError(f"{self.candidate}: probe magnitudes must be strictly ascending")
        if r.shape[0] != m.size:
            raise ValueError(f"{self.candidate}: {r.shape[0]} response rows for {m.size} levels")
        if not 0 <= self.reference < m.size:
            raise ValueError(f"{self.candidate}: reference index out of range")
        if not np.all(np.isfinite(r)):
            raise ValueError(f"{self.candidate}: responses must be finite")

    @classmethod
    def from_runs(
        cls,
        candidate: str,
        magnitudes: Sequence[float],
        values: np.ndarray,
        reference: int,
        integer: bool = False,
    ) -> EffectResponse:
        """From DEM values per probe run (rows) and observation (columns), any order.

        Parameters
        ----------
        magnitudes : sequence of float, length L
            Effect magnitude of each run.
        values : ndarray, shape (L, K)
            DEM value of each observation in each run.
        reference : int
            Row of the run with the effect off.
        """
        mags = np.asarray(magnitudes, dtype=float)
        vals = np.asarray(values, dtype=float)
        # A level that coincides with the reference adds nothing but a duplicate abscissa.
        keep = [j for j in range(mags.size) if j == reference or mags[j] != mags[reference]]
        reference = keep.index(reference)
        mags, vals = mags[keep], vals[keep]
        order = np.argsort(mags, kind="stable")
        responses = vals - vals[reference]
        return cls(
            candidate,
            mags[order],
            responses[order],
            int(np.flatnonzero(order == reference)[0]),
            integer,
        )

    @property
    def off(self) -> float:
        """Magnitude at which the effect is absent."""
        return float(self.magnitudes[self.reference])

    def at(self, magnitude: float) -> np.ndarray:
        """Response of every observation at ``magnitude``, shape (K,).

        Piecewise linear between the probed magnitudes, held at the end values outside them.
        """
        m = self.magnitudes
        a = float(np.clip(magnitude, m[0], m[-1]))
        i = int(np.clip(np.searchsorted(m, a, side="right") - 1, 0, m.size - 2))
        t = (a - m[i]) / (m[i + 1] - m[i])
        return (1.0 - t) * self.responses[i] + t * self.responses[i + 1]

    def trial_magnitudes(self, points: int) -> np.ndarray:
        """Magnitudes tried in the fit: a regular grid over the probed span plus the levels."""
        lo, hi = float(self.magnitudes[0]), float(self.magnitudes[-1])
        if self.integer:
            return np.arange(math.ceil(lo), math.floor(hi) + 1, dtype=float)
        return np.unique(np.concatenate([np.linspace(lo, hi, max(points, 2)), self.magnitudes]))


@dataclass
class CandidateFit:
    """Best fit of the model extended by one candidate effect.

    Attributes
    ----------
    candidate : str
    magnitude : float
        Fitted effect magnitude (unit of the candidate's parameter).
    best : BestFit
        theta, the minimised deviance D_c and the extended model's predictions (K,).
    """

    candidate: str
    magnitude: float
    best: BestFit


def ranking_sigma(sigma: np.ndarray, noise_sd: np.ndarray) -> np.ndarray:
    """Weights of the ranking, ``sqrt(sigma^2 + 2 noise^2)``, shape (K,).

    Parameters
    ----------
    sigma : ndarray, shape (K,)
        Uncertainty of each observation in the Find step.
    noise_sd : ndarray, shape (K,)
        Noise of one DEM run per observation (the surrogate RMSE).
    """
    return np.sqrt(np.asarray(sigma, float) ** 2 + 2.0 * np.asarray(noise_sd, float) ** 2)


def null_fit(
    model: SurrogateModel,
    box: ParameterBox,
    grid: np.ndarray,
    grid_predictions: np.ndarray,
    weights: np.ndarray,
    refine: bool = True,
) -> BestFit:
    """Best fit of the current model ("nothing missing") with the ranking weights."""
    y = model.observations["measured"].to_numpy(float)

    def objective(theta: np.ndarray) -> np.ndarray:
        return np.sum(((model.predict(theta) - y) / weights) ** 2, axis=1)

    values = np.sum(((grid_predictions - y) / weights) ** 2, axis=1)
    theta, value = minimise_chi2(objective, box, grid, values, refine=refine)
    predictions = model.predict(theta[None, :])[0]
    return BestFit(dict(zip(box.names, map(float, theta), strict=True)), value, predictions)


def fit_candidate(
    model: SurrogateModel,
    box: ParameterBox,
    grid: np.ndarray,
    grid_predictions: np.ndarray,
    response: EffectResponse,
    weights: np.ndarray,
    magnitude_points: int = 41,
    refine: bool = True,
) -> CandidateFit:
    """Minimise the deviance of the extended model over the box and the effect magnitude.

    Parameters
    ----------
    model : SurrogateModel
        The current model (its ``observations`` hold the measured values).
    box : ParameterBox
        Bounds of theta.
    grid : ndarray, shape (n_grid, d)
        Grid of theta.
    grid_predictions : ndarray, shape (n_grid, K)
        ``model.predict(grid)``.
    response : EffectResponse
        DEM response of the observations to the effect.
    weights : ndarray, shape (K,)
        Standard deviation of each observation in the ranking (:func:`ranking_sigma`).
    magnitude_points : int
        Magnitudes tried across the probed span (continuous effects).
    refine : bool
        Refine theta at the best magnitude with L-BFGS-B.
    """
    y = model.observations["measured"].to_numpy(float)
    w = np.asarray(weights, dtype=float)
    if response.responses.shape[1] != y.size or w.shape != y.shape:
        raise ValueError(
            f"{response.candidate}: responses cover {response.responses.shape[1]} observations "
            f"and weights {w.size}, the model {y.size}"
        )
    best_value, best_a, best_values = math.inf, response.off, None
    for a in response.trial_magnitudes(magnitude_points):
        values = np.sum(((y - response.at(a) - grid_predictions) / w) ** 2, axis=1)
        j = int(np.argmin(values))
        if values[j] < best_value:
            best_value, best_a, best_values = float(values[j]), float(a), values
    assert best_values is not None
    offset = response.at(best_a)

    def objective(theta: np.ndarray) -> np.ndarray:
        return np.sum(((y - offset - model.predict(theta)) / w) ** 2, axis=1)

    theta, value = minimise_chi2(objective, box, grid, best_values, refine=refine)
    predictions = model.predict(theta[None, :])[0] + offset
    best = BestFit(dict(zip(box.names, map(float, theta), strict=True)), value, predictions)
    return CandidateFit(response.candidate, best_a, best)


def rank_candidates(
    null_deviance: float,
    fits: Mapping[str, CandidateFit],
    n_observations: int,
    min_delta_bic: float,
    min_explained: float = 0.0,
) -> tuple[pd.DataFrame, str | None]:
    """Rank candidate effects by their BIC advantage over "nothing missing".

    Parameters
    ----------
    null_deviance : float
        Deviance of the best fit of the current model (D_0).
    fits : mapping
        Candidate name -> its :class:`CandidateFit`.
    n_observations : int
        Number of observations N.
    min_delta_bic : float
        Smallest dBIC for the top candidate to be named.
    min_explained : float
        Smallest share of D_0 the top candidate must remove to be named.

    Returns
    -------
    table : DataFrame
        One row per candidate, best first: rank, candidate, magnitude, deviance,
        delta_deviance (D_0 - D_c), delta_bic, explained (fraction of D_0 removed), gap
        (sqrt(D_c / N)) and named (bool).
    winner : str or None
        The named candidate, or None when none beats "nothing missing" clearly.
    """
    if n_observations < 1:
        raise ValueError("need at least one observation")
    penalty = math.log(n_observations)
    rows = []
    for name, fit in fits.items():
        # "Nothing missing" is nested in every candidate (a = off), so D_c <= D_0 exactly.
        deviance = min(fit.best.deviance, null_deviance)
        drop = null_deviance - deviance
        rows.append(
            {
                "candidate": name,
                "magnitude": fit.magnitude,
                "deviance": deviance,
                "delta_deviance": drop,
                "delta_bic": drop - penalty,
                "explained": drop / null_deviance if null_deviance > 0 else 0.0,
                "gap": math.sqrt(max(deviance, 0.0) / n_observations),
            }
        )
    table = pd.DataFrame(
        rows,
        columns=[
            "candidate",
            "magnitude",
            "deviance",
            "delta_deviance",
            "delta_bic",
            "explained",
            "gap",
        ],
    )
    table = table.sort_values("delta_bic", ascending=False, kind="stable").reset_index(drop=True)
    table.insert(0, "rank", np.arange(1, len(table) + 1))
    winner = None
    if (
        len(table)
        and table["delta_bic"].iloc[0] >= min_delta_bic
        and table["explained"].iloc[0] >= min_explained
    ):
        winner = str(table["candidate"].iloc[0])
    table["named"] = table["candidate"] == winner
    return table, winner


_FRICTION = ("mu_psh", "mu_sh")


def _change(name: str, value: float, reference: float) -> str:
    if name in _FRICTION:
        return f"{value:+.2f}"
    if name == "aor":
        return f"{value:+.1f} deg"
    return f"{100.0 * value / reference:+.1f} %"


def response_signature(
    observations: pd.DataFrame,
    response: EffectResponse,
    reference_values: np.ndarray,
    noise_sd: np.ndarray,
) -> str:
    """How the observables respond to the effect at its largest probed magnitude, in words.

    Per observable the response is averaged over P at each normal stress; responses within the
    noise are reported as no clear change, and with two or more stresses the trend with normal
    stress is named (e.g. for cohesion: the added friction weakens with normal stress, that is
    the apparent friction falls with normal stress).

    Parameters
    ----------
    observations : DataFrame, shape (K, ...)
        Columns observable, normal_stress, P.
    response : EffectResponse
    reference_values : ndarray, shape (K,)
        DEM values of the reference run (for relative changes).
    noise_sd : ndarray, shape (K,)
        Noise of one DEM run per observation.
    """
    far = int(np.argmax(np.abs(response.magnitudes - response.off)))
    delta = response.responses[far]
    obs = observations.reset_index(drop=True).assign(
        delta=delta, ref=reference_values, noise=noise_sd
    )
    parts = []
    for name, rows in obs.groupby("observable", sort=False):
        if rows["normal_stress"].isna().all():
            level = rows["delta"].mean()
            noise = rows["noise"].mean() * math.sqrt(2.0)
            text = _change(name, level, rows["ref"].mean())
            parts.append(f"{name} {text}" if abs(level) > noise else f"{name} no clear change")
            continue
        per_stress = rows.groupby("normal_stress", sort=True).agg(
            delta=("delta", "mean"), ref=("ref", "mean"), noise=("noise", "mean"), n=("P", "size")
        )
        noise = float((per_stress["noise"] * np.sqrt(2.0 / per_stress["n"])).max())
        items = [
            f"{_change(name, r.delta, r.ref)} at {format_stress(s)}"
            for s, r in per_stress.iterrows()
        ]
        biggest = float(per_stress["delta"].abs().max())
        if biggest <= noise:
            parts.append(f"{name} no clear change")
            continue
        text = f"{name} " + ", ".join(items)
        if len(per_stress) > 1:
            low, high = per_stress["delta"].iloc[0], per_stress["delta"].iloc[-1]
            if abs(low - high) > max(noise, 0.3 * biggest):
                trend = "weakens" if abs(low) > abs(high) else "grows"
                text += f" (the change {trend} with normal stress"
                if name in _FRICTION and trend == "weakens" and low > 0:
                    text += ": apparent friction falls with normal stress"
                text += ")"
        parts.append(text)
    return "; ".join(parts)
