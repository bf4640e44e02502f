"""The parameter box and the smallest misfit in it.

A misfit over the box is minimised on a regular grid (integer parameters take every whole
value) and the best grid point is then refined by bounded L-BFGS-B, with the integer parameters
held at their grid value.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import minimize

__all__ = [
    "BestFit",
    "ParameterBox",
    "best_deviances",
    "exceedance_p",
    "grid_size",
    "minimise_chi2",
    "pinned_parameters",
]


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


def grid_size(box: ParameterBox, points: int) -> int:
    """Number of grid points of ``box`` at ``points`` per continuous axis."""
    return math.prod(len(v) for v in box.axes(points).values())


def best_deviances(rows: np.ndarray, data: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """For each data set, the smallest weighted squared misfit over candidate predictions.

    Parameters
    ----------
    rows : ndarray, shape (R, K)
        Predictions of the K values, one row per candidate point (e.g. a parameter grid).
    data : ndarray, shape (B, K)
        Data sets.
    weights : ndarray, shape (K,)
        Standard deviation of each value.

    Returns
    -------
    ndarray, shape (B,)
        min over the rows of sum_k ((data_bk - rows_rk) / weights_k)^2.
    """
    scaled = np.asarray(rows, float) / weights
    norms = np.sum(scaled**2, axis=1)
    u_all = np.atleast_2d(np.asarray(data, float)) / weights
    out = np.empty(u_all.shape[0])
    # |a - u|^2 = |a|^2 - 2 a.u + |u|^2; chunks of data sets keep the (R, chunk) product small.
    chunk = max(1, min(u_all.shape[0], 20_000_000 // max(1, scaled.shape[0])))
    for start in range(0, u_all.shape[0], chunk):
        u = u_all[start : start + chunk]
        best = np.min(norms[:, None] - 2.0 * scaled @ u.T, axis=0)
        out[start : start + len(u)] = np.maximum(best + np.sum(u**2, axis=1), 0.0)
    return out


def exceedance_p(null: np.ndarray, observed: float | np.ndarray) -> np.ndarray:
    """Parametric-bootstrap p-value of each observed statistic against the null draws,
    ``(1 + #{null >= observed}) / (n + 1)`` (never 0, so a p-value resolves 1 / (n + 1)).

    Parameters
    ----------
    null : ndarray, shape (n,)
        The statistic over the data sets drawn under the null hypothesis.
    observed : float or ndarray, shape (m,)
        Observed statistic(s).

    Returns
    -------
    ndarray, shape of ``observed``
    """
    ordered = np.sort(np.asarray(null, float))
    exceed = ordered.size - np.searchsorted(ordered, observed, side="left")
    return (1.0 + exceed) / (ordered.size + 1.0)
