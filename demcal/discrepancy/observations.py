"""The observations of the discrepancy workflow and their surrogate predictions.

Every measured bulk value is one *observation* k: an observable (``mu_psh``, ``mu_sh``,
``rho_b``, ``aor``) at a load condition (normal stress, P), with its uncertainty

    sigma_k = sqrt(sd_k^2 + rmse_k^2),

sd_k the standard deviation of the measurement (``tolerance * |y_k|`` when none is given) and
rmse_k the held-out RMSE of the surrogate (:func:`demcal.discrepancy.extension.rmse_of`), so
that a surrogate's own error is never mistaken for missing physics.

Surrogates are duck-typed: ``predict(X: ndarray (n, d)) -> ndarray (n,)`` over an ordered list
of input names (the output of :func:`demcal.surrogates.training.load_surrogate`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pandas as pd

from demcal.core.experiments import SHEAR_OBSERVABLES, Experiment

__all__ = [
    "LOAD_INPUTS",
    "OBSERVABLES",
    "SurrogateModel",
    "format_stress",
    "observation_table",
]

#: Observables in report order: the shear-cell readings, then the angle of repose.
OBSERVABLES = (*SHEAR_OBSERVABLES, "aor")
#: Surrogate inputs that come from the load condition of an observation, not from theta.
LOAD_INPUTS = ("normal_stress", "P")


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


def format_stress(stress: float) -> str:
    """A normal stress as text with a space as thousands separator, e.g. ``"1 068 Pa"``."""
    return f"{round(stress):,} Pa".replace(",", " ")
