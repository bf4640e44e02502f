"""The parameter sets of the next round.

The rule (docs/sequential.md):

1. Draw ``candidates`` sets uniformly in the design box. A Gaussian process per bulk value,
   fitted on every DEM run so far, predicts each measured value at each candidate (mean and
   standard deviation, the latter including the run-to-run scatter it learned as noise).
2. ``misfit`` of a candidate: the largest ``|prediction / measured - 1| / tolerance`` over the
   measured values (at most 1 means it passes the screening's eqs. 3-4); ``uncertainty``: the
   ``std / (tolerance * |measured|)`` of the value that sets the misfit.
3. ``round(batch * (1 - explore_fraction))`` sets come from the valid sets of the latest
   screening (the identified group), chosen one by one as the valid set farthest from every
   earlier DEM run and every set already chosen (greedy maximin in the design box scaled to
   the unit cube): they sharpen the valid region.
4. The others come from the candidates near the valid region (misfit at most ``near_factor``),
   chosen one by one by the largest ``1.96 * uncertainty - |misfit - 1|`` (the "straddle" score
   of level-set estimation: large where the 95 % band of the prediction straddles the edge of
   the valid region), each choice damping the score of candidates within 0.1 (unit-cube
   distance) of it and of earlier runs: they teach the surrogates where they are least certain
   whether a set is valid.
5. Where one pool is empty its share goes to the other; when both are, the sets come from the
   5 % of candidates with the smallest misfit, by greedy maximin.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from demcal.bulk.dataset import training_rows
from demcal.core.experiments import Experiment
from demcal.surrogates.baselines import gaussian_process_regression
from demcal.surrogates.log_inputs import log_columns
from demcal.surrogates.training import INPUTS, TEST_OF, varying_features

#: Unit-cube distance within which a chosen uncertain set damps the others' uncertainty.
DAMPING_LENGTH = 0.1
#: Share of the candidates (smallest misfit) used when no candidate is valid or near.
FALLBACK_SHARE = 0.05


@dataclass(frozen=True)
class Observable:
    """One measured value: the bulk value, its load condition and the measurement.

    Attributes
    ----------
    output : str
        ``mu_psh``, ``mu_sh``, ``rho_b`` or ``aor``.
    load : dict of str to float
        ``normal_stress`` [Pa] and ``P`` [-] of a shear-cell value; empty for the angle.
    measured : float
        The measured value (units of the bulk value).
    """

    output: str
    load: dict[str, float]
    measured: float


def observables(experiment: Experiment) -> list[Observable]:
    """Every measured value of ``experiment``, shear-cell conditions first."""
    found = [
        Observable(name, dict(cond.load), float(value))
        for cond in experiment.shear_conditions
        for name, value in cond.values.items()
    ]
    if experiment.angle_of_repose is not None:
        found.append(Observable("aor", {}, float(experiment.angle_of_repose)))
    return found


def draw_candidates(ranges: Mapping[str, Sequence[float]], n: int, seed: int) -> pd.DataFrame:
    """``n`` parameter sets drawn uniformly in the box ``ranges`` (name -> [low, high])."""
    rng = np.random.default_rng(seed)
    return pd.DataFrame(
        {name: rng.uniform(float(lo), float(hi), n) for name, (lo, hi) in ranges.items()}
    )


def unit_cube(frame: pd.DataFrame, ranges: Mapping[str, Sequence[float]]) -> np.ndarray:
    """The parameter columns of ``frame`` scaled to [0, 1] by ``ranges``, shape (n, d)."""
    cols = [
        (frame[name].to_numpy(dtype=float) - float(lo)) / (float(hi) - float(lo))
        for name, (lo, hi) in ranges.items()
    ]
    return np.column_stack(cols) if cols else np.empty((len(frame), 0))


class BulkProcesses:
    """One Gaussian process per bulk value, fitted on the DEM runs so far.

    Parameters
    ----------
    data : DataFrame
        The tidy bulk dataset (failed runs are left out).
    outputs : sequence of str
        The bulk values to fit (those measured).
    constants : mapping
        Bulk value -> inputs held at a value (e.g. the test's dCylDp) when they vary in the data
        but are not parameters of the candidates.
    seed : int
        Seed of the optimiser restarts.
    """

    def __init__(
        self,
        data: pd.DataFrame,
        outputs: Sequence[str],
        constants: Mapping[str, Mapping[str, float]],
        seed: int,
    ) -> None:
        self.models: dict[str, tuple[object, list[str]]] = {}
        self.constants = {k: dict(v) for k, v in constants.items()}
        for output in dict.fromkeys(outputs):
            rows = training_rows(data, TEST_OF[output], output)
            if len(rows) < 3:
                raise ValueError(
                    f"{output}: {len(rows)} usable DEM results; at least 3 are needed to "
                    "place the next round"
                )
            features = varying_features(rows, INPUTS[output])
            model = gaussian_process_regression(
                seed, n_restarts_optimizer=1, log_inputs=log_columns(features)
            )
            model.fit(rows[features].to_numpy(dtype=float), rows[output].to_numpy(dtype=float))
            self.models[output] = (model, features)

    def predict(
        self, candidates: pd.DataFrame, observable: Observable
    ) -> tuple[np.ndarray, np.ndarray]:
        """Mean and standard deviation of ``observable`` at every candidate, shape (n,)."""
        model, features = self.models[observable.output]
        fixed = {**self.constants.get(observable.output, {}), **observable.load}
        columns = []
        for name in features:
            if name in fixed:
                columns.append(np.full(len(candidates), float(fixed[name])))
            elif name in candidates:
                columns.append(candidates[name].to_numpy(dtype=float))
            else:
                raise ValueError(
                    f"{observable.output}: input {name!r} varies in the DEM runs but is neither a "
                    "design range nor held constant"
                )
        X = np.column_stack(columns)
        mean, std = model.predict(X, return_std=True)
        return np.asarray(mean, dtype=float), np.asarray(std, dtype=float)


def misfit_and_uncertainty(
    candidates: pd.DataFrame,
    processes: BulkProcesses,
    measured: Sequence[Observable],
    tolerance: float,
) -> tuple[np.ndarray, np.ndarray]:
    """Relative misfit and its uncertainty per candidate, in tolerances.

    Returns
    -------
    misfit, uncertainty : numpy.ndarray, shape (n,)
        ``max_j |mean_j / measured_j - 1| / tolerance`` over the measured values j, and
        ``std_k / (tolerance * |measured_k|)`` of the value k that attains the maximum.
    """
    misfit = np.full(len(candidates), -np.inf)
    uncertainty = np.zeros(len(candidates))
    for obs in measured:
        mean, std = processes.predict(candidates, obs)
        this = np.abs(mean / obs.measured - 1.0) / tolerance
        binding = this > misfit
        misfit = np.where(binding, this, misfit)
        uncertainty = np.where(binding, std / (tolerance * abs(obs.measured)), uncertainty)
    return misfit, uncertainty


def straddle(misfit: np.ndarray, uncertainty: np.ndarray) -> np.ndarray:
    """``1.96 * uncertainty - |misfit - 1|``: large where the prediction's 95 % band straddles
    the edge of the valid region (misfit 1), shape as ``misfit``."""
    return 1.96 * np.asarray(uncertainty) - np.abs(np.asarray(misfit) - 1.0)


def greedy_maximin(pool: np.ndarray, existing: np.ndarray, n: int) -> list[int]:
    """Indices of ``n`` rows of ``pool`` (m, d), each the farthest from ``existing`` (k, d) and
    the rows already chosen; fewer when the pool is smaller."""
    chosen: list[int] = []
    if len(pool) == 0 or n <= 0:
        return chosen
    if len(existing):
        gap = np.min(np.linalg.norm(pool[:, None, :] - existing[None, :, :], axis=2), axis=1)
    else:
        gap = np.full(len(pool), np.inf)
    for _ in range(min(n, len(pool))):
        # Ties (no earlier run) go to the pool's first row, so the choice is reproducible.
        pick = int(np.argmax(gap))
        chosen.append(pick)
        gap = np.minimum(gap, np.linalg.norm(pool - pool[pick], axis=1))
        gap[pick] = -np.inf
    return chosen


def damping(pool: np.ndarray, point: np.ndarray) -> np.ndarray:
    """``1 - exp(-(distance / DAMPING_LENGTH)^2)`` of every row of ``pool`` (m, d) from
    ``point`` (d,): 0 at the point, near 1 beyond a few damping lengths."""
    distance = np.linalg.norm(pool - point, axis=1)
    return 1.0 - np.exp(-((distance / DAMPING_LENGTH) ** 2))


def greedy_uncertain(
    pool: np.ndarray, score: np.ndarray, existing: np.ndarray, n: int
) -> list[int]:
    """Indices of ``n`` rows of ``pool`` (m, d) by largest ``score`` (m,), shifted to be
    positive and damped near ``existing`` (k, d) and near every earlier choice
    (:func:`damping`)."""
    chosen: list[int] = []
    left = np.asarray(score, dtype=float)
    left = left - left.min() + 1e-12 if left.size else left
    for point in existing:
        left = left * damping(pool, point)
    for _ in range(min(n, len(pool))):
        pick = int(np.argmax(left))
        chosen.append(pick)
        left = left * damping(pool, pool[pick])
        left[pick] = -np.inf
    return chosen


def propose(
    candidates: pd.DataFrame,
    misfit: np.ndarray,
    uncertainty: np.ndarray,
    valid: pd.DataFrame,
    existing: pd.DataFrame,
    ranges: Mapping[str, Sequence[float]],
    n: int,
    explore_fraction: float,
    near_factor: float,
) -> pd.DataFrame:
    """The next round's ``n`` parameter sets (rule in the module docstring).

    Parameters
    ----------
    candidates : DataFrame, shape (m, d)
        Uniform draws in the design box, one column per parameter of ``ranges``.
    misfit, uncertainty : numpy.ndarray, shape (m,)
        From :func:`misfit_and_uncertainty`.
    valid : DataFrame
        The valid sets of the latest screening (may be empty); parameter columns as ``ranges``.
    existing : DataFrame
        Every parameter set run so far (parameter columns as ``ranges``).
    ranges : mapping
        Parameter -> [low, high] of the design box.
    n : int
        Sets to choose.
    explore_fraction : float
        Share chosen by uncertainty near the valid region.
    near_factor : float
        Misfit (in tolerances) up to which a candidate counts as near the valid region.

    Returns
    -------
    pandas.DataFrame
        ``n`` rows: the parameters and ``reason`` (``valid``, ``uncertain`` or ``nearest``).
    """
    names = list(ranges)
    missing = [p for p in names if len(valid) and p not in valid]
    if missing:
        raise ValueError(f"the valid sets have no column for design parameter(s) {missing}")
    before = unit_cube(existing, ranges)
    in_valid = unit_cube(valid, ranges) if len(valid) else np.empty((0, len(names)))
    near = np.flatnonzero(misfit <= near_factor)
    n_explore = round(n * explore_fraction) if len(near) else 0
    n_valid = min(n - n_explore, len(in_valid))
    n_explore = min(n - n_valid, len(near))
    rows: list[pd.DataFrame] = []
    picked = before
    if n_valid:
        idx = greedy_maximin(in_valid, before, n_valid)
        rows.append(valid.iloc[idx][names].assign(reason="valid"))
        picked = np.vstack([picked, in_valid[idx]])
    if n_explore:
        pool = unit_cube(candidates.iloc[near], ranges)
        score = straddle(misfit[near], uncertainty[near])
        idx = greedy_uncertain(pool, score, picked, n_explore)
        rows.append(candidates.iloc[near[idx]][names].assign(reason="uncertain"))
        picked = np.vstack([picked, pool[idx]])
    n_left = n - sum(len(r) for r in rows)
    if n_left > 0:
        share = max(n_left, int(np.ceil(FALLBACK_SHARE * len(candidates))))
        closest = np.argsort(misfit, kind="stable")[:share]
        idx = greedy_maximin(unit_cube(candidates.iloc[closest], ranges), picked, n_left)
        rows.append(candidates.iloc[closest[idx]][names].assign(reason="nearest"))
    return pd.concat(rows, ignore_index=True)
