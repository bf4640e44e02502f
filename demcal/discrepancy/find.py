"""Find where a calibrated model and the measurements disagree (discrepancy workflow, step 1).

Every measured bulk value is one *observation* k: an observable (``mu_psh``, ``mu_sh``,
``rho_b``, ``aor``) at a load condition (normal stress, P). Its normalised misfit at a
parameter set theta is

    z_k(theta) = (f_k(theta) - y_k) / sigma_k,   sigma_k = sqrt(sd_k^2 + rmse_k^2),

with f_k the surrogate of the observable at the load of k, y_k the measurement, sd_k its
standard deviation (``tolerance * |y_k|`` when none is given) and rmse_k the held-out RMSE of
the surrogate (:func:`demcal.discrepancy.extension.rmse_of`), so that a surrogate's own error is
never mistaken for missing physics.

Over the parameter box (a regular grid, then a bounded local refinement of the best grid point)
this module finds

* per observation, the range of values the model reaches and the smallest achievable |z_k|;
* the joint best point theta* = argmin chi^2, chi^2 = sum_k z_k^2;
* the gap figure G = sqrt(chi^2(theta*) / N): about 1 or less when the model explains the data
  within its uncertainty, clearly above 1 when it cannot;
* the verdict: G <= threshold means the disagreement is within the noise and nothing is missing.

Surrogates are duck-typed: ``predict(X: ndarray (n, d)) -> ndarray (n,)`` over an ordered list
of input names (the output of :func:`demcal.surrogates.training.load_surrogate`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd
from scipy.optimize import minimize

from demcal.core.experiments import Experiment

__all__ = [
    "LOAD_INPUTS",
    "OBSERVABLES",
    "BestFit",
    "FindResult",
    "ParameterBox",
    "SurrogateModel",
    "describe_disagreement",
    "find",
    "format_stress",
    "minimise_chi2",
    "observation_table",
]

OBSERVABLES = ("mu_psh", "mu_sh", "rho_b", "aor")
#: Surrogate inputs that come from the load condition of an observation, not from theta.
LOAD_INPUTS = ("normal_stress", "P")
#: Observables measured in the shear cell (the others have no load condition).
SHEAR_OBSERVABLES = ("mu_psh", "mu_sh", "rho_b")


def observation_table(
    experiment: Experiment,
    rmse: Mapping[str, float],
    tolerance: float,
    observables: Sequence[str] = OBSERVABLES,
) -> pd.DataFrame:
    """One row per measured value with its uncertainty.

    Parameters
    ----------
    experiment : Experiment
        The measurements (shear-cell conditions and the angle of repose).
    rmse : mapping
        Test RMSE of the surrogate per observable, in the observable's unit.
    tolerance : float
        Relative standard deviation assumed for a measurement without one (e.g. 0.05).
    observables : sequence of str
        Observables to use; measured values of others are left out.

    Returns
    -------
    DataFrame, shape (K, 7)
        Columns observable, normal_stress (Pa, NaN for aor), P (-, NaN for aor), measured,
        measured_sd, surrogate_rmse, sigma (all in the observable's unit).

    Raises
    ------
    KeyError
        When a measured observable has no surrogate RMSE (no surrogate).
    ValueError
        When nothing is measured or the tolerance is not positive.
    """
    if not tolerance > 0:
        raise ValueError(f"tolerance must be > 0, got {tolerance!r}")
    rows: list[dict[str, Any]] = []

    def add(name: str, stress: float, p: float, value: float, sd: float | None) -> None:
        if name not in observables:
            return
        if name not in rmse:
            raise KeyError(f"observable {name!r} is measured but has no trained surrogate")
        sd_value = float(sd) if sd is not None else tolerance * abs(value)
        model_error = float(rmse[name])
        rows.append(
            {
                "observable": name,
                "normal_stress": stress,
                "P": p,
                "measured": float(value),
                "measured_sd": sd_value,
                "surrogate_rmse": model_error,
                "sigma": math.hypot(sd_value, model_error),
            }
        )

    for cond in experiment.shear_conditions:
        for name in SHEAR_OBSERVABLES:
            if name in cond.values:
                add(
                    name,
                    float(cond.normal_stress),
                    float(cond.P),
                    cond.values[name],
                    cond.uncertainties.get(name),
                )
    if experiment.angle_of_repose is not None:
        add("aor", math.nan, math.nan, experiment.angle_of_repose, experiment.angle_of_repose_sd)
    if not rows:
        raise ValueError(f"experiment {experiment.material!r}: no measured value to compare with")
    table = pd.DataFrame(rows)
    if not (table["sigma"] > 0).all():
        bad = table[~(table["sigma"] > 0)].iloc[0]
        raise ValueError(
            f"observation {bad['observable']} at normal_stress={bad['normal_stress']}: "
            "zero uncertainty (no sd, zero surrogate RMSE)"
        )
    return table


@dataclass(frozen=True)
class ParameterBox:
    """The parameter box searched for the best fit.

    Attributes
    ----------
    bounds : dict[str, tuple[float, float]]
        Per parameter (LIGGGHTS name, SI units) its closed range [low, high].
    integer : frozenset[str]
        Parameters that only take whole values.
    """

    bounds: dict[str, tuple[float, float]]
    integer: frozenset[str] = field(default_factory=frozenset)

    def __post_init__(self) -> None:
        if not self.bounds:
            raise ValueError("parameter box: no parameters")
        for name, (lo, hi) in self.bounds.items():
            if not (math.isfinite(lo) and math.isfinite(hi) and lo <= hi):
                raise ValueError(f"parameter box: {name!r} needs finite low <= high, got {lo, hi}")
        unknown = set(self.integer) - set(self.bounds)
        if unknown:
            raise KeyError(f"parameter box: integer parameters {sorted(unknown)} have no bounds")

    @property
    def names(self) -> list[str]:
        return list(self.bounds)

    def axes(self, points: int) -> dict[str, np.ndarray]:
        """Regular axes: ``points`` values per continuous parameter, every whole value otherwise."""
        if points < 2:
            raise ValueError(f"grid points per axis must be >= 2, got {points}")
        out: dict[str, np.ndarray] = {}
        for name, (lo, hi) in self.bounds.items():
            if name in self.integer:
                out[name] = np.arange(math.ceil(lo), math.floor(hi) + 1, dtype=float)
            elif lo == hi:
                out[name] = np.array([lo])
            else:
                out[name] = np.linspace(lo, hi, points)
        return out

    def grid(self, points: int) -> np.ndarray:
        """Cartesian product of :meth:`axes`, shape (n_grid, n_parameters)."""
        axes = self.axes(points)
        mesh = np.meshgrid(*axes.values(), indexing="ij")
        return np.stack([m.reshape(-1) for m in mesh], axis=1)


class SurrogateModel:
    """Surrogate predictions of every observation for parameter vectors.

    Parameters
    ----------
    surrogates : mapping
        Observable -> (model, ordered input names); ``model.predict(X (n, d)) -> (n,)``.
    observations : DataFrame
        Output of :func:`observation_table` (columns observable, normal_stress, P).
    parameters : sequence of str
        Names of the entries of a parameter vector theta.
    constants : mapping
        Observable -> inputs held constant (e.g. ``{"dCylDp": 10}``).

    Raises
    ------
    KeyError
        When an input of a surrogate is neither a parameter, a load input nor a constant.
    """

    def __init__(
        self,
        surrogates: Mapping[str, tuple[Any, Sequence[str]]],
        observations: pd.DataFrame,
        parameters: Sequence[str],
        constants: Mapping[str, Mapping[str, float]] | None = None,
    ) -> None:
        self.parameters = list(parameters)
        self.observations = observations.reset_index(drop=True)
        constants = constants or {}
        self._columns: list[tuple[Any, list[tuple[str, Any]]]] = []
        for _, row in self.observations.iterrows():
            name = row["observable"]
            if name not in surrogates:
                raise KeyError(f"no surrogate for observable {name!r}")
            model, features = surrogates[name]
            spec: list[tuple[str, Any]] = []
            for feature in features:
                if feature in self.parameters:
                    spec.append(("param", self.parameters.index(feature)))
                elif feature in LOAD_INPUTS and math.isfinite(float(row[feature])):
                    spec.append(("value", float(row[feature])))
                elif feature in constants.get(name, {}):
                    spec.append(("value", float(constants[name][feature])))
                else:
                    raise KeyError(
                        f"surrogate {name!r}: input {feature!r} is neither a parameter "
                        f"({', '.join(self.parameters)}), a load input nor a constant"
                    )
            self._columns.append((model, spec))

    @property
    def n_observations(self) -> int:
        return len(self._columns)

    def predict(self, theta: np.ndarray, chunk_size: int = 65536) -> np.ndarray:
        """Predictions for parameter vectors.

        Parameters
        ----------
        theta : ndarray, shape (n, n_parameters)
            Parameter vectors in the order of ``parameters`` (SI units).

        Returns
        -------
        ndarray, shape (n, K)
            Column k holds the prediction of observation k in its unit.
        """
        theta = np.atleast_2d(np.asarray(theta, dtype=float))
        if theta.shape[1] != len(self.parameters):
            raise ValueError(f"theta has {theta.shape[1]} columns, expected {len(self.parameters)}")
        out = np.empty((theta.shape[0], self.n_observations))
        for start in range(0, theta.shape[0], chunk_size):
            block = theta[start : start + chunk_size]
            for k, (model, spec) in enumerate(self._columns):
                X = np.empty((block.shape[0], len(spec)))
                for j, (kind, value) in enumerate(spec):
                    X[:, j] = block[:, value] if kind == "param" else value
                out[start : start + block.shape[0], k] = np.asarray(
                    model.predict(X), dtype=float
                ).reshape(-1)
        return out


@dataclass
class BestFit:
    """The smallest misfit found over a parameter box.

    Attributes
    ----------
    theta : dict[str, float]
        The best parameter set (SI units).
    deviance : float
        The minimised objective (chi^2 for a plain fit).
    predictions : ndarray, shape (K,)
        Model values of the observations at ``theta``.
    """

    theta: dict[str, float]
    deviance: float
    predictions: np.ndarray


def minimise_chi2(
    objective: Callable[[np.ndarray], np.ndarray],
    box: ParameterBox,
    grid: np.ndarray,
    grid_values: np.ndarray,
    refine: bool = True,
) -> tuple[np.ndarray, float]:
    """Best grid point of a vectorised objective, refined by bounded L-BFGS-B.

    Parameters
    ----------
    objective : callable
        ``objective(theta (n, d)) -> (n,)``, the quantity to minimise.
    box : ParameterBox
        Bounds; integer parameters stay at their grid value during the refinement.
    grid : ndarray, shape (n_grid, d)
        Candidate points.
    grid_values : ndarray, shape (n_grid,)
        ``objective(grid)``, computed by the caller (often from cached predictions).
    refine : bool
        Run the local refinement.

    Returns
    -------
    theta : ndarray, shape (d,)
    value : float
    """
    finite = np.isfinite(grid_values)
    if not finite.any():
        raise ValueError("the misfit is not finite anywhere on the parameter grid")
    best = int(np.argmin(np.where(finite, grid_values, np.inf)))
    theta0 = grid[best].astype(float)
    value0 = float(grid_values[best])
    free = [
        j
        for j, name in enumerate(box.names)
        if name not in box.integer and box.bounds[name][1] > box.bounds[name][0]
    ]
    if not refine or not free:
        return theta0, value0
    lo = np.array([box.bounds[box.names[j]][0] for j in free])
    span = np.array([box.bounds[box.names[j]][1] - box.bounds[box.names[j]][0] for j in free])

    def scalar(u: np.ndarray) -> float:
        theta = theta0.copy()
        theta[free] = lo + np.clip(u, 0.0, 1.0) * span
        return float(objective(theta[None, :])[0])

    u0 = (theta0[free] - lo) / span
    res = minimize(
        scalar,
        u0,
        method="L-BFGS-B",
        bounds=[(0.0, 1.0)] * len(free),
        options={"maxiter": 200, "eps": 1e-6},
    )
    if np.isfinite(res.fun) and res.fun < value0:
        theta = theta0.copy()
        theta[free] = lo + np.clip(res.x, 0.0, 1.0) * span
        return theta, float(res.fun)
    return theta0, value0


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
    threshold : float
        Gap at or below which the disagreement counts as noise.
    sentences : list[str]
        Where the disagreement sits, one sentence per observable, and one more when theta* sits
        on the boundary of the box.
    pinned : dict[str, str]
        Parameters of theta* on a bound of the box: name -> "lower" or "upper".
    """

    observations: pd.DataFrame
    best: BestFit
    gap: float
    threshold: float
    sentences: list[str]
    pinned: dict[str, str] = field(default_factory=dict)

    @property
    def missing(self) -> bool:
        """True when the gap exceeds the threshold (something is missing)."""
        return self.gap > self.threshold

    @property
    def verdict(self) -> str:
        if self.missing:
            return (
                f"gap {self.gap:.2f} > {self.threshold:g}: the model cannot reproduce the "
                "measurements within their uncertainty -> a physical effect is missing"
            )
        text = f"gap {self.gap:.2f} <= {self.threshold:g}: within noise -> nothing missing"
        if self.pinned:
            text += f", but theta* sits on the box boundary ({', '.join(self.pinned)})"
        return text


def pinned_parameters(
    theta: Mapping[str, float], box: ParameterBox, rel_tol: float = 1e-3
) -> dict[str, str]:
    """Parameters of a point that sit on a bound of the box.

    Parameters
    ----------
    theta : mapping of str to float
        The point, per parameter name (SI units).
    box : ParameterBox
        The box; parameters with a single value are never reported.
    rel_tol : float
        Distance from a bound, as a fraction of the parameter's range, that counts as on it.

    Returns
    -------
    dict[str, str]
        Name -> "lower" or "upper", in the box's order.
    """
    out: dict[str, str] = {}
    for name, (lo, hi) in box.bounds.items():
        span = hi - lo
        if span <= 0.0 or name not in theta:
            continue
        if theta[name] <= lo + rel_tol * span:
            out[name] = "lower"
        elif theta[name] >= hi - rel_tol * span:
            out[name] = "upper"
    return out


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


def find(
    model: SurrogateModel,
    box: ParameterBox,
    grid_points: int,
    gap_threshold: float,
    fit_z: float = 2.0,
    refine: bool = True,
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
    gap_threshold : float
        The verdict threshold on the gap figure.
    fit_z : float
        |z| at or below which an observation counts as fitted in the sentences.
    refine : bool
        Refine theta* with L-BFGS-B from the best grid point.
    """
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
    return FindResult(obs, best, gap, gap_threshold, sentences, pinned)


def format_stress(stress: float) -> str:
    """A normal stress as text with a space as thousands separator, e.g. ``"1 068 Pa"``."""
    return f"{round(stress):,} Pa".replace(",", " ")


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


def grid_size(box: ParameterBox, points: int) -> int:
    """Number of grid points of ``box`` at ``points`` per continuous axis."""
    return math.prod(len(v) for v in box.axes(points).values())
