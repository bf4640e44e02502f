"""Acceptance stages of a screening run and their evaluation on one chunk of the grid.

A stage names the predictors it evaluates, the feature values it holds fixed (e.g. the load
condition) and its acceptance rule. Predictors are duck-typed: ``predict(X: ndarray (n, d)) ->
ndarray (n,)``, and optionally ``predict_torch(X: Tensor float32 (n, d)) -> Tensor (n,)`` which
is preferred for speed.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import partial
from typing import Protocol

import numpy as np
import torch

from demcal.core.experiments import MeasuredCondition
from demcal.identification.acceptance import (
    DEFAULT_TOLERANCE,
    within_tolerance,
)
from demcal.identification.candidate_grid import axis_positions, grid_shape


class Predictor(Protocol):
    """A fitted surrogate mapping input features (n, d) to one bulk value (n,)."""

    def predict(self, X: np.ndarray) -> np.ndarray: ...


PredictorEntry = tuple[Predictor, Sequence[str]]
"""A predictor together with its ordered list of input feature names."""


@dataclass(frozen=True)
class Stage:
    """One acceptance step of a screening run.

    Attributes
    ----------
    name : str
        Unique label of the stage (keys the predictions of the result).
    outputs : tuple[str, ...]
        Predictor names evaluated in this stage.
    accept : Callable[[Mapping[str, numpy.ndarray]], numpy.ndarray]
        Receives the stage's predictions (each of shape (m,)) and returns a bool mask (m,).
    fixed : Mapping[str, float]
        Feature values held fixed in this stage (e.g. the load condition); they override the
        run-wide fixed values.
    """

    name: str
    outputs: tuple[str, ...]
    accept: Callable[[Mapping[str, np.ndarray]], np.ndarray]
    fixed: Mapping[str, float] = field(default_factory=dict)


def stage_from_condition(
    condition: MeasuredCondition, tol: float = DEFAULT_TOLERANCE, coverage: float = 0.0
) -> Stage:
    """Stage that accepts sets within the band of every value measured at ``condition``.

    The band is ``tol`` widened by ``coverage`` standard deviations of each measured value that
    states one (:func:`demcal.identification.acceptance.acceptance_band`). The outputs evaluated
    are the measured observables (predictor names must equal the output names) and the
    condition's load (``normal_stress``, ``P``) is held fixed.
    """
    return Stage(
        name=condition.label,
        outputs=tuple(condition.values),
        accept=partial(
            within_tolerance,
            measured=dict(condition.values),
            tol=tol,
            uncertainties=dict(condition.uncertainties),
            coverage=coverage,
        ),
        fixed=condition.load,
    )


class GridAxes:
    """Axis values of the grid in float64 (numpy) and float32 (torch)."""

    def __init__(self, axes: Mapping[str, np.ndarray]) -> None:
        self.names = list(axes)
        self.shape = grid_shape(axes)
        self.values64 = {k: np.asarray(v, dtype=np.float64) for k, v in axes.items()}
        self.values32 = {
            k: torch.from_numpy(v.astype(np.float32)) for k, v in self.values64.items()
        }


class StageInputs:
    """Predictor input matrices for one set of flat indices and fixed values.

    Matrices are built once per distinct feature list (the shear-cell networks share theirs)
    and handed out as copies, so a predictor that modifies its input cannot affect another.
    """

    def __init__(self, grid: GridAxes, indices: np.ndarray, fixed: Mapping[str, float]) -> None:
        self.grid = grid
        self.n = int(indices.size)
        self.fixed = fixed
        pos = axis_positions(grid.shape, indices)
        self.positions = dict(zip(grid.names, pos, strict=True))
        self._numpy: dict[tuple[str, ...], np.ndarray] = {}
        self._torch: dict[tuple[str, ...], torch.Tensor] = {}

    def numpy(self, features: Sequence[str]) -> np.ndarray:
        """Float64 matrix of shape (n, len(features))."""
        key = tuple(features)
        if key not in self._numpy:
            X = np.empty((self.n, len(key)), dtype=np.float64)
            for j, name in enumerate(key):
                if name in self.positions:
                    X[:, j] = self.grid.values64[name][self.positions[name]]
                else:
                    X[:, j] = self.fixed[name]
            self._numpy[key] = X
        return self._numpy[key].copy()

    def torch(self, features: Sequence[str]) -> torch.Tensor:
        """Float32 tensor of shape (n, len(features))."""
        key = tuple(features)
        if key not in self._torch:
            X = torch.empty((self.n, len(key)), dtype=torch.float32)
            for j, name in enumerate(key):
                if name in self.positions:
                    X[:, j] = self.grid.values32[name][torch.from_numpy(self.positions[name])]
                else:
                    X[:, j] = float(self.fixed[name])
            self._torch[key] = X
        return self._torch[key].clone()


def check_setup(
    predictors: Mapping[str, PredictorEntry],
    axes: Mapping[str, np.ndarray],
    fixed: Mapping[str, float],
    stages: Sequence[Stage],
) -> None:
    clash = set(fixed) & set(axes)
    if clash:
        raise ValueError(f"screen: features {sorted(clash)} are both grid axes and fixed")
    names = [stage.name for stage in stages]
    if len(set(names)) != len(names):
        raise ValueError(f"screen: stage names must be unique, got {names}")
    if not stages:
        raise ValueError("screen: no acceptance stages given")
    for stage in stages:
        clash = set(stage.fixed) & set(axes)
        if clash:
            raise ValueError(
                f"screen: stage {stage.name!r} fixes {sorted(clash)} which are grid axes"
            )
        if not stage.outputs:
            raise ValueError(f"screen: stage {stage.name!r} evaluates no outputs")
        for output in stage.outputs:
            if output not in predictors:
                raise KeyError(f"screen: stage {stage.name!r} needs predictor {output!r}")
            model, features = predictors[output]
            if not hasattr(model, "predict"):
                raise TypeError(f"screen: predictor {output!r} has no predict method")
            for feature in features:
                if feature not in axes and feature not in stage.fixed and feature not in fixed:
                    raise KeyError(
                        f"screen: feature {feature!r} of predictor {output!r} is neither a "
                        f"grid axis nor fixed (stage {stage.name!r})"
                    )


def predict_output(
    model: Predictor, features: Sequence[str], inputs: StageInputs, name: str
) -> np.ndarray:
    if hasattr(model, "predict_torch"):
        with torch.inference_mode():
            y = model.predict_torch(inputs.torch(features))
        out = y.detach().cpu().numpy().astype(np.float64).reshape(-1)
    else:
        out = np.asarray(model.predict(inputs.numpy(features)), dtype=np.float64).reshape(-1)
    if out.shape != (inputs.n,):
        raise ValueError(
            f"screen: predictor {name!r} returned {out.size} values for {inputs.n} rows"
        )
    return out


def run_stage(
    rows: np.ndarray,
    stage: Stage,
    predictors: Mapping[str, PredictorEntry],
    grid: GridAxes,
    fixed: Mapping[str, float],
    store: dict[str, dict[str, np.ndarray]],
) -> np.ndarray:
    """Evaluate one stage on the sets ``rows`` (m,); return its bool mask (m,).

    ``store`` holds the predictions of earlier stages for the same rows; they are filtered
    with the mask so that all stored arrays stay aligned with the survivors.
    """
    inputs = StageInputs(grid, rows, {**fixed, **stage.fixed})
    pred = {
        out: predict_output(predictors[out][0], predictors[out][1], inputs, out)
        for out in stage.outputs
    }
    mask = np.asarray(stage.accept(pred))
    if mask.dtype != np.bool_ or mask.shape != rows.shape:
        raise ValueError(
            f"screen: stage {stage.name!r} accept returned dtype {mask.dtype} "
            f"shape {mask.shape}, expected bool of shape {rows.shape}"
        )
    for name, values in list(store.items()):
        store[name] = {o: v[mask] for o, v in values.items()}
    store[stage.name] = {o: v[mask] for o, v in pred.items()}
    return mask
