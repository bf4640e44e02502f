"""Acceptance of candidate parameter sets against measured bulk values (paper eqs. 3 and 4).

A candidate set is *marked* when its predicted shear-cell values (mu_psh, mu_sh, rho_b) all lie
within a relative tolerance of the measurements at a load condition (eq. 3); a marked set is
*valid* when its predicted angle of repose also lies within the tolerance (eq. 4). Only the
observables present in a measurement are matched, so partial data sets are allowed.

A measured value is known only to within its standard deviation, so where the measurement
states one the band is widened by ``coverage`` standard deviations, added in quadrature:
``|num - exp| < sqrt((tol * exp)^2 + (coverage * sd)^2)`` (:func:`acceptance_band`). Without a
standard deviation, or with ``coverage`` 0, this is the paper's rule ``|1 - num/exp| < tol``.

:func:`within_tolerance` is the one implementation of the rule. The
screening (:func:`demcal.identification.screening.screen`) applies it stage by stage through
:func:`sequential_filter`: eq. 3 at every shear-cell load condition, then eq. 4 on the sets that
are left; the verification table applies it to the DEM values at the identified set.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

import numpy as np

DEFAULT_TOLERANCE = 0.05
"""Relative tolerance of the paper (5 %)."""


def relative_deviation(num: np.ndarray | float, exp: np.ndarray | float) -> np.ndarray:
    """Absolute relative deviation ``|1 - num / exp|`` of predictions from measurements.

    Parameters
    ----------
    num : array_like, shape (n,) or scalar
        Numerical (predicted) values.
    exp : array_like, shape (n,) or scalar
        Experimental values in the same units; must be non-zero.

    Returns
    -------
    numpy.ndarray, shape (n,) or ()
        Dimensionless deviation; NaN where ``num`` is NaN.
    """
    num_arr = np.asarray(num, dtype=np.float64)
    exp_arr = np.asarray(exp, dtype=np.float64)
    if np.any(exp_arr == 0.0):
        raise ValueError("relative_deviation: experimental value 0 is not allowed (divisor)")
    return np.abs(1.0 - num_arr / exp_arr)


def acceptance_band(
    exp: float, tol: float, sd: float | None = None, coverage: float = 0.0
) -> float:
    """Relative half-width of the acceptance band around one measured value.

    Parameters
    ----------
    exp : float
        Measured value (any unit); non-zero.
    tol : float
        Relative tolerance, e.g. 0.05 for 5 %.
    sd : float or None
        Standard deviation of the measured value, same unit; None when not stated.
    coverage : float
        Standard deviations of the measurement added to the band in quadrature (2: about 95 %
        of the values a repeated measurement would give); 0 keeps the tolerance alone.

    Returns
    -------
    float
        ``sqrt(tol^2 + (coverage * sd / exp)^2)``, dimensionless; ``tol`` when ``sd`` is None.
    """
    if sd is None or coverage == 0.0:
        return float(tol)
    return float(np.hypot(tol, coverage * sd / abs(exp)))


def within_tolerance(
    pred: Mapping[str, np.ndarray],
    measured: Mapping[str, float],
    tol: float = DEFAULT_TOLERANCE,
    uncertainties: Mapping[str, float] | None = None,
    coverage: float = 0.0,
) -> np.ndarray:
    """Sets whose predictions match every measured value within its band (strict ``<``).

    Parameters
    ----------
    pred : Mapping[str, numpy.ndarray]
        Predictions by output name, each of shape (n,). Extra outputs are ignored.
    measured : Mapping[str, float]
        Measured values by output name; only these observables are matched.
    tol : float
        Relative tolerance, e.g. 0.05 for 5 %.
    uncertainties : Mapping[str, float], optional
        Standard deviations of (some of) the measured values, same units.
    coverage : float
        Standard deviations added to the band in quadrature (:func:`acceptance_band`).

    Returns
    -------
    numpy.ndarray of bool, shape (n,)
        True where ``|1 - pred/measured|`` is below the band of every measured observable
        (``tol`` where no standard deviation is given). NaN predictions are never accepted.
    """
    if not measured:
        raise ValueError("within_tolerance: no measured values to match")
    if not tol > 0.0:
        raise ValueError(f"within_tolerance: tol must be > 0, got {tol!r}")
    if not coverage >= 0.0:
        raise ValueError(f"within_tolerance: coverage must be >= 0, got {coverage!r}")
    sds = uncertainties or {}
    mask: np.ndarray | None = None
    for key, exp in measured.items():
        if key not in pred:
            raise KeyError(f"within_tolerance: no prediction for measured output {key!r}")
        values = np.asarray(pred[key], dtype=np.float64)
        if values.ndim != 1:
            raise ValueError(
                f"within_tolerance: predictions of {key!r} must be 1-D, got shape {values.shape}"
            )
        band = acceptance_band(exp, tol, sds.get(key), coverage)
        ok = relative_deviation(values, exp) < band
        if mask is None:
            mask = ok
        elif ok.shape != mask.shape:
            raise ValueError(
                f"within_tolerance: predictions of {key!r} have {ok.size} rows, "
                f"expected {mask.size}"
            )
        else:
            mask &= ok
    assert mask is not None
    return mask


def sequential_filter(
    indices: np.ndarray,
    tests: Sequence[Callable[[np.ndarray], np.ndarray]],
) -> list[np.ndarray]:
    """Apply acceptance tests one after another, each only to the survivors of the previous.

    Parameters
    ----------
    indices : numpy.ndarray of int, shape (n,)
        Identifiers of the candidate sets (e.g. flat grid indices).
    tests : Sequence[Callable]
        Each test receives the identifiers of the current survivors, shape (m,), and returns
        a boolean mask of shape (m,).

    Returns
    -------
    list of numpy.ndarray
        Identifiers surviving after each test (cumulative), one array per test.
    """
    survivors = np.asarray(indices)
    passed: list[np.ndarray] = []
    for k, test in enumerate(tests):
        if survivors.size:
            mask = np.asarray(test(survivors))
            if mask.dtype != np.bool_ or mask.shape != survivors.shape:
                raise ValueError(
                    f"sequential_filter: test {k} returned dtype {mask.dtype} shape "
                    f"{mask.shape}, expected bool of shape {survivors.shape}"
                )
            survivors = survivors[mask]
        passed.append(survivors)
    return passed
