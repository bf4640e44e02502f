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
is not there. dBIC orders the candidates; whether the top one is named is decided by two
parametric-bootstrap tests whose error rates are known at the few values a shear test gives
(:func:`naming_test`):

* **Is there an effect?** Data sets drawn under "nothing missing" (the current model at its
  best grid point, with the ranking weights) are fitted by the current model and by every
  candidate; p_effect is the share whose largest deviance drop max_c (D_0 - D_c) reaches the
  observed one. The maximum over the candidates accounts for having picked the best of several.
* **Is it this effect, not the runner-up?** Data sets drawn from the runner-up's best fit are
  fitted by both; p_runner_up is the share in which the runner-up's deviance exceeds the top
  candidate's by at least the observed amount. When it is not below alpha the two cannot be told
  apart, and the measured value where their fits differ most (in units of its weight) is the one
  whose repetition or neighbourhood would separate them best.

A candidate is named only when both p-values are below alpha, it removes at least a given share
of D_0, and every applicable candidate could be scored (otherwise the best of the scored ones
need not be the right one).

Whether the measurements could name a candidate at all is a separate question, answered before
anyone reads a "nothing named" as "not there" (:func:`naming_power`): data sets drawn with the
candidate present at each of its probe levels go through the effect test, and the share in which
it is found and leads bounds its naming probability. A candidate whose response the current
parameters absorb (a denser packing that a higher particle density reproduces) or that stays
within the noise cannot be named from these data, however the decision rule is tuned.
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
)
from demcal.discrepancy.effect_response import EffectResponse
from demcal.discrepancy.observations import SurrogateModel

__all__ = [
    "UNNAMEABLE",
    "CandidateFit",
    "NamingTest",
    "fit_candidate",
    "naming_power",
    "naming_test",
    "null_fit",
    "power_with_fixed",
    "rank_candidates",
    "ranking_sigma",
]


#: Naming power below which a candidate counts as not nameable from the measurements
#: (:func:`naming_power`).
UNNAMEABLE = 0.5


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


def ranking_sigma(
    sigma: np.ndarray, noise_sd: np.ndarray, probe_runs: int = 1, reference_runs: int = 1
) -> np.ndarray:
    """Weights of the ranking, ``sqrt(sigma^2 + (1 / n_p + 1 / n_ref) noise^2)``, shape (K,).

    A candidate's response is the mean of ``n_p`` probe runs minus the mean of ``n_ref``
    reference runs, so its seed-to-seed scatter adds ``(1 / n_p + 1 / n_ref) noise^2`` to the
    variance of the observation (``2 noise^2`` for single runs).

    Parameters
    ----------
    sigma : ndarray, shape (K,)
        Uncertainty of each observation in the Find step.
    noise_sd : ndarray, shape (K,)
        Noise of one DEM run per observation (the surrogate RMSE).
    probe_runs, reference_runs : int
        Runs averaged per probe level and at the reference point (at least 1).
    """
    if probe_runs < 1 or reference_runs < 1:
        raise ValueError(f"run counts must be at least 1, got {probe_runs}, {reference_runs}")
    share = 1.0 / probe_runs + 1.0 / reference_runs
    return np.sqrt(np.asarray(sigma, float) ** 2 + share * np.asarray(noise_sd, float) ** 2)


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
    min_explained: float = 0.0,
) -> tuple[pd.DataFrame, str | None]:
    """Rank candidate effects by their BIC advantage over "nothing missing".

    dBIC only orders the candidates; whether the leader is named is decided by the bootstrap
    tests of :func:`naming_test`.

    Parameters
    ----------
    null_deviance : float
        Deviance of the best fit of the current model (D_0).
    fits : mapping
        Candidate name -> its :class:`CandidateFit`.
    n_observations : int
        Number of observations N.
    min_explained : float
        Smallest share of D_0 the top candidate must remove to lead.

    Returns
    -------
    table : DataFrame
        One row per candidate, best first: rank, candidate, magnitude, deviance,
        delta_deviance (D_0 - D_c), delta_bic, explained (fraction of D_0 removed), gap
        (sqrt(D_c / N)) and named (bool: the leader).
    winner : str or None
        The leader: the top candidate if it removes at least ``min_explained`` of D_0, else
        None.
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
    if len(table) and table["explained"].iloc[0] >= min_explained:
        winner = str(table["candidate"].iloc[0])
    table["named"] = table["candidate"] == winner
    return table, winner


@dataclass
class NamingTest:
    """The bootstrap tests behind naming the top candidate (see the module documentation).

    Attributes
    ----------
    top : str
        Candidate with the largest deviance drop on the grid.
    p_effect : float
        p-value of "nothing missing" against the best of the candidates.
    runner_up : str or None
        Second candidate (None with a single candidate).
    p_runner_up : float or None
        p-value of "the runner-up is the effect" against the top candidate.
    separating : int or None
        Index of the measured value where the two fits differ most in units of its weight.
    draws : int
        Bootstrap data sets per test.
    null_drops : ndarray, shape (draws,)
        The largest deviance drop of each data set drawn under "nothing missing" (the null
        distribution of the effect test; :func:`naming_power` reuses it).
    """

    top: str
    p_effect: float
    runner_up: str | None
    p_runner_up: float | None
    separating: int | None
    draws: int
    null_drops: np.ndarray = field(default_factory=lambda: np.empty(0), repr=False, compare=False)


def _offsets(response: EffectResponse, magnitude_points: int) -> list[np.ndarray]:
    """The candidate's response at each trial magnitude, shape (K,) each."""
    return [response.at(a) for a in response.trial_magnitudes(magnitude_points)]


# A candidate's predictions are the grid's plus one offset per magnitude; they are formed one
# magnitude at a time, as (G, K) blocks, rather than all at once.
def _best(
    grid: np.ndarray, offsets: list[np.ndarray], data: np.ndarray, weights: np.ndarray
) -> np.ndarray:
    out = np.full(np.atleast_2d(data).shape[0], np.inf)
    for offset in offsets:
        out = np.minimum(out, best_deviances(grid + offset, data, weights))
    return out


def _largest_drops(
    grid: np.ndarray, offsets: list[list[np.ndarray]], data: np.ndarray, weights: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Per data set (rows of ``data``, shape (B, K)), the largest deviance drop D_0 - D_c over
    the candidates (their offsets in order) and the index of the candidate giving it."""
    d0 = best_deviances(grid, data, weights)
    per_candidate = np.array([d0 - _best(grid, o, data, weights) for o in offsets])
    return per_candidate.max(axis=0), per_candidate.argmax(axis=0)


def _best_row(
    grid: np.ndarray, offsets: list[np.ndarray], y: np.ndarray, weights: np.ndarray
) -> np.ndarray:
    best_value, best_row = np.inf, grid[0]
    for offset in offsets:
        block = grid + offset
        values = np.sum(((block - y) / weights) ** 2, axis=1)
        j = int(np.argmin(values))
        if values[j] < best_value:
            best_value, best_row = float(values[j]), block[j]
    return best_row


def naming_test(
    grid_predictions: np.ndarray,
    y: np.ndarray,
    weights: np.ndarray,
    responses: Mapping[str, EffectResponse],
    magnitude_points: int = 41,
    draws: int = 1000,
    seed: int = 0,
) -> NamingTest:
    """Parametric-bootstrap tests for naming the candidate that explains most of the misfit.

    Parameters
    ----------
    grid_predictions : ndarray, shape (G, K)
        The current model's predictions over the parameter grid.
    y : ndarray, shape (K,)
        Measured values.
    weights : ndarray, shape (K,)
        Ranking weights (:func:`ranking_sigma`).
    responses : mapping
        Candidate name -> DEM response; at least one.
    magnitude_points : int
        Magnitudes tried per continuous candidate, as in :func:`fit_candidate`.
    draws : int
        Bootstrap data sets per test.
    seed : int
        Seed of the draws.
    """
    if not responses:
        raise ValueError("naming_test needs at least one candidate")
    rng = np.random.default_rng(seed)
    w = np.asarray(weights, float)
    y = np.asarray(y, float)
    offsets = {c: _offsets(r, magnitude_points) for c, r in responses.items()}
    d0 = float(best_deviances(grid_predictions, y, w)[0])
    dc = {c: float(_best(grid_predictions, o, y, w)[0]) for c, o in offsets.items()}
    order = sorted(dc, key=lambda c: dc[c])
    top = order[0]
    # Is there an effect: the largest drop over all candidates, under "nothing missing".
    null_point = _best_row(grid_predictions, [np.zeros_like(y)], y, w)
    data = null_point + w * rng.standard_normal((draws, y.size))
    drops, _ = _largest_drops(grid_predictions, list(offsets.values()), data, w)
    p_effect = float(exceedance_p(drops, d0 - dc[top]))
    if len(order) < 2:
        return NamingTest(top, p_effect, None, None, None, draws, drops)
    # Is it the top candidate rather than the runner-up: data drawn from the runner-up's fit.
    second = order[1]
    top_point = _best_row(grid_predictions, offsets[top], y, w)
    second_point = _best_row(grid_predictions, offsets[second], y, w)
    data = second_point + w * rng.standard_normal((draws, y.size))
    gaps = _best(grid_predictions, offsets[second], data, w) - _best(
        grid_predictions, offsets[top], data, w
    )
    p_second = float(exceedance_p(gaps, dc[second] - dc[top]))
    separating = int(np.argmax(np.abs(top_point - second_point) / w))
    return NamingTest(top, p_effect, second, p_second, separating, draws, drops)


def naming_power(
    grid_predictions: np.ndarray,
    y: np.ndarray,
    weights: np.ndarray,
    responses: Mapping[str, EffectResponse],
    alpha: float,
    magnitude_points: int = 41,
    draws: int = 200,
    null_draws: int = 1000,
    seed: int = 1,
    only: str | None = None,
    null_drops: np.ndarray | None = None,
) -> pd.DataFrame:
    """How often each candidate would be found and lead if it were present at a probe level.

    Data sets are drawn as the current model's best fit to ``y`` (as in :func:`naming_test`)
    plus the candidate's response at one of its probe levels plus noise with the ranking
    weights, and put through the effect test of :func:`naming_test` (``null_draws`` data sets
    under "nothing missing" give the critical drop). ``found`` is the share in which the test
    rejects "nothing missing" at ``alpha``; ``named`` the share in which it also leads the
    candidates. ``named`` bounds the naming probability from above (the runner-up test is not
    repeated per data set), so a low value means these measurements cannot name the candidate
    at that magnitude: what it changes, the current parameters absorb or the noise hides. The
    responses carry the probe runs' noise, which makes the shares, if anything, too high.

    Parameters
    ----------
    grid_predictions, y, weights, responses, magnitude_points
        As for :func:`naming_test` (shapes (G, K), (K,), (K,)).
    alpha : float
        Significance level of the effect test.
    draws : int
        Data sets per candidate and probe level.
    null_draws : int
        Data sets under "nothing missing" for the critical drop.
    seed : int
        Seed of the draws.
    only : str, optional
        Draw data sets for this candidate's levels only (all candidates still compete).
    null_drops : ndarray, optional
        The null distribution of the effect test on the same data, grid, weights and
        candidates (``NamingTest.null_drops``); drawn here (``null_draws``) when not given.

    Returns
    -------
    DataFrame
        One row per candidate and probe level (the effect-off reference excluded): candidate,
        magnitude, found, named (shares in [0, 1]).
    """
    if not responses:
        raise ValueError("naming_power needs at least one candidate")
    if only is not None and only not in responses:
        raise ValueError(f"naming_power: {only!r} is not a candidate")
    rng = np.random.default_rng(seed)
    w = np.asarray(weights, float)
    y = np.asarray(y, float)
    names = list(responses)
    offsets = [_offsets(responses[c], magnitude_points) for c in names]
    base = _best_row(grid_predictions, [np.zeros_like(y)], y, w)
    if null_drops is None:
        null = base + w * rng.standard_normal((null_draws, y.size))
        null_drops = _largest_drops(grid_predictions, offsets, null, w)[0]
    rows = []
    for i, name in enumerate(names):
        if only is not None and name != only:
            continue
        response = responses[name]
        for j, level in enumerate(response.magnitudes):
            if j == response.reference:
                continue
            data = base + response.responses[j] + w * rng.standard_normal((draws, y.size))
            drops, leader = _largest_drops(grid_predictions, offsets, data, w)
            found = exceedance_p(null_drops, drops) < alpha  # as p_effect
            rows.append(
                {
                    "candidate": name,
                    "magnitude": float(level),
                    "found": float(found.mean()),
                    "named": float((found & (leader == i)).mean()),
                }
            )
    return pd.DataFrame(rows, columns=["candidate", "magnitude", "found", "named"])


def power_with_fixed(
    grid: np.ndarray,
    grid_predictions: np.ndarray,
    names: list[str],
    y: np.ndarray,
    weights: np.ndarray,
    responses: Mapping[str, EffectResponse],
    candidate: str,
    alpha: float,
    magnitude_points: int = 41,
    draws: int = 200,
    null_draws: int = 1000,
) -> dict[str, float]:
    """A candidate's best naming power when one parameter is measured on its own.

    Each free parameter in turn is held at the current model's best grid value (as a separate
    measurement, e.g. a pycnometer particle density, would fix it) and :func:`naming_power` is
    repeated on that slice of the grid. A parameter whose fixing lifts the power says which
    extra measurement would let the data name the candidate. The held value is exact, as no
    measurement is, so the power found is an upper bound on what that measurement gives.

    Parameters
    ----------
    grid : ndarray, shape (G, d)
        The parameter grid.
    grid_predictions : ndarray, shape (G, K)
        The current model's predictions over it.
    names : list of str, length d
        Parameter of each grid column.
    y, weights, responses, alpha, magnitude_points, draws, null_draws
        As for :func:`naming_power`.
    candidate : str
        The candidate whose power is wanted.

    Returns
    -------
    dict
        Parameter -> the candidate's largest ``named`` share over its probe levels with that
        parameter fixed.
    """
    grid = np.asarray(grid, float)
    w = np.asarray(weights, float)
    best = int(np.argmin(np.sum(((grid_predictions - np.asarray(y, float)) / w) ** 2, axis=1)))
    out = {}
    for i, name in enumerate(names):
        rows = np.isclose(grid[:, i], grid[best, i])
        power = naming_power(
            grid_predictions[rows],
            y,
            w,
            responses,
            alpha,
            magnitude_points,
            draws,
            null_draws,
            only=candidate,
        )
        out[name] = float(power["named"].max())
    return out
