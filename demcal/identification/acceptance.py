"""Acceptance of candidate parameter sets against measured bulk values (paper eqs. 3 and 4).

A candidate set is *marked* when its predicted shear-cell values (mu_psh, mu_sh, rho_b) all lie
within a relative tolerance of the measurements at a load condition (eq. 3); a marked set is
*valid* when its predicted angle of repose also lies within the tolerance (eq. 4). Only the
observables present in a measurement are matched, so partial data sets are allowed.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

DEFAULT_TOLERANCE = 0.05
"""Relative tolerance of the paper (5 %)."""


def _format_load(value: float | None) -> str:
    return "None" if value is None else f"{value:g}"


@dataclass(frozen=True)
class MeasuredCondition:
    """Measured bulk values of one experiment at one load condition.

    Parameters
    ----------
    values : Mapping[str, float]
        Measured bulk values by output name (``mu_psh``, ``mu_sh`` [-], ``rho_b`` [kg/m^3],
        ``aor`` [deg], ...). Must be non-empty, finite and non-zero (they are divisors).
    uncertainties : Mapping[str, float], optional
        Standard deviations of the measured values, same units; keys must be in ``values``.
    normal_stress : float or None
        Pre-shear normal stress [Pa] of a shear-cell condition; None for tests without load.
    P : float or None
        Shear load as a fraction of the pre-shear load [-]; given together with
        ``normal_stress``.
    name : str or None
        Label of the condition; generated from the load when omitted.
    """

    values: Mapping[str, float]
    uncertainties: Mapping[str, float] = field(default_factory=dict)
    normal_stress: float | None = None
    P: float | None = None
    name: str | None = None

    def __post_init__(self) -> None:
        if not self.values:
            raise ValueError(f"measured condition {self.label!r}: no measured values given")
        for key, value in self.values.items():
            if not math.isfinite(value) or value == 0.0:
                raise ValueError(
                    f"measured condition {self.label!r}: value of {key!r} must be finite and "
                    f"non-zero, got {value!r}"
                )
        for key, value in self.uncertainties.items():
            if key not in self.values:
                raise KeyError(
                    f"measured condition {self.label!r}: uncertainty given for {key!r} "
                    f"which has no measured value"
                )
            if not math.isfinite(value) or value < 0.0:
                raise ValueError(
                    f"measured condition {self.label!r}: uncertainty of {key!r} must be finite "
                    f"and >= 0, got {value!r}"
                )
        if (self.normal_stress is None) != (self.P is None):
            raise ValueError(
                f"measured condition {self.label!r}: normal_stress and P must be given together"
            )
        if self.normal_stress is not None and not self.normal_stress > 0.0:
            raise ValueError(
                f"measured condition {self.label!r}: normal_stress must be > 0 Pa, "
                f"got {self.normal_stress!r}"
            )

    @property
    def label(self) -> str:
        """Name of the condition, e.g. ``"normal_stress=10070,P=1"``."""
        if self.name is not None:
            return self.name
        if self.normal_stress is None and self.P is None:
            return "+".join(self.values)
        return f"normal_stress={_format_load(self.normal_stress)},P={_format_load(self.P)}"

    @property
    def load(self) -> dict[str, float]:
        """Load features of the condition (``normal_stress`` [Pa], ``P`` [-]); empty if none."""
        if self.normal_stress is None or self.P is None:
            return {}
        return {"normal_stress": float(self.normal_stress), "P": float(self.P)}


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


def within_tolerance(
    pred: Mapping[str, np.ndarray],
    measured: Mapping[str, float],
    tol: float = DEFAULT_TOLERANCE,
) -> np.ndarray:
    """Sets whose predictions match every measured value within ``tol`` (strict ``<``).

    Parameters
    ----------
    pred : Mapping[str, numpy.ndarray]
        Predictions by output name, each of shape (n,). Extra outputs are ignored.
    measured : Mapping[str, float]
        Measured values by output name; only these observables are matched.
    tol : float
        Relative tolerance, e.g. 0.05 for 5 %.

    Returns
    -------
    numpy.ndarray of bool, shape (n,)
        True where ``|1 - pred/measured| < tol`` for all measured observables. NaN
        predictions are never accepted.
    """
    if not measured:
        raise ValueError("within_tolerance: no measured values to match")
    if not tol > 0.0:
        raise ValueError(f"within_tolerance: tol must be > 0, got {tol!r}")
    mask: np.ndarray | None = None
    for key, exp in measured.items():
        if key not in pred:
            raise KeyError(f"within_tolerance: no prediction for measured output {key!r}")
        values = np.asarray(pred[key], dtype=np.float64)
        if values.ndim != 1:
            raise ValueError(
                f"within_tolerance: predictions of {key!r} must be 1-D, got shape {values.shape}"
            )
        ok = relative_deviation(values, exp) < tol
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


def within_all_conditions(
    predictions: Sequence[Mapping[str, np.ndarray]],
    conditions: Sequence[MeasuredCondition],
    tol: float = DEFAULT_TOLERANCE,
) -> np.ndarray:
    """Sets matching every given load condition (logical AND of eq. 3 over conditions).

    Parameters
    ----------
    predictions : Sequence[Mapping[str, numpy.ndarray]]
        One mapping per condition (same order as ``conditions``) of predictions, shape (n,),
        made with that condition's load.
    conditions : Sequence[MeasuredCondition]
        The measured conditions.
    tol : float
        Relative tolerance.

    Returns
    -------
    numpy.ndarray of bool, shape (n,)
    """
    if len(predictions) != len(conditions):
        raise ValueError(
            f"within_all_conditions: {len(predictions)} prediction sets for "
            f"{len(conditions)} conditions"
        )
    if not conditions:
        raise ValueError("within_all_conditions: no conditions given")
    mask: np.ndarray | None = None
    for pred, cond in zip(predictions, conditions, strict=True):
        ok = within_tolerance(pred, cond.values, tol)
        if mask is not None and ok.shape != mask.shape:
            raise ValueError(
                f"within_all_conditions: condition {cond.label!r} has {ok.size} rows, "
                f"expected {mask.size}"
            )
        mask = ok if mask is None else mask & ok
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


@dataclass(frozen=True)
class AcceptanceResult:
    """Outcome of eq. 3 followed by eq. 4.

    Attributes
    ----------
    marked : numpy.ndarray of bool, shape (n,)
        Sets within tolerance at all shear-cell conditions (eq. 3).
    valid : numpy.ndarray of bool, shape (n,)
        Marked sets also within tolerance for the repose angle (eq. 4).
    """

    marked: np.ndarray
    valid: np.ndarray


def marked_then_valid(
    shear_predictions: Sequence[Mapping[str, np.ndarray]],
    shear_conditions: Sequence[MeasuredCondition],
    predict_repose: Callable[[np.ndarray], Mapping[str, np.ndarray]],
    repose: MeasuredCondition,
    tol: float = DEFAULT_TOLERANCE,
) -> AcceptanceResult:
    """Paper eqs. 3 and 4: mark sets on the shear cell, then check only marked sets on AoR.

    Parameters
    ----------
    shear_predictions : Sequence[Mapping[str, numpy.ndarray]]
        Per shear condition, predictions of shape (n,) for all n candidate sets.
    shear_conditions : Sequence[MeasuredCondition]
        Measured shear-cell conditions (ANDed).
    predict_repose : Callable
        Receives the row indices of the marked sets, shape (m,), and returns the repose
        predictions for those rows only (e.g. ``{"aor": array of shape (m,)}``, degrees).
    repose : MeasuredCondition
        Measured angle of repose.
    tol : float
        Relative tolerance.

    Returns
    -------
    AcceptanceResult
    """
    marked = within_all_conditions(shear_predictions, shear_conditions, tol)

    def repose_test(rows: np.ndarray) -> np.ndarray:
        return within_tolerance(predict_repose(rows), repose.values, tol)

    rows = np.flatnonzero(marked)
    valid_rows = sequential_filter(rows, [repose_test])[0]
    valid = np.zeros_like(marked)
    valid[valid_rows] = True
    return AcceptanceResult(marked=marked, valid=valid)
